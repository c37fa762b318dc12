#pragma once
// The parts of tiny-dnn the pointnet plugin uses: layer graph, fully connected
// layers, activations, optimiser interface and the sequential network.
// Included only by plugins/pointnet sources (never by a public header).
//
// Debian's tiny-dnn 1.0.0a3 headers include cereal (Debian's libcereal-dev)
// and stb (declaration-only stand-ins in plugins/pointnet/tiny_dnn_deps), and
// CNN_NO_SERIALIZATION is defined by the CMake target
// (tiny-dnn's own serialisation is not used: see model_file.cpp). tiny_dnn.h
// itself is not included: it pulls in the quantized layers (gemmlowp) and the
// image/caffe I/O.
// The order follows tiny_dnn.h (its headers depend on it).
#include <tiny_dnn/config.h>
#include <tiny_dnn/network.h>
#include <tiny_dnn/nodes.h>
#include <tiny_dnn/core/framework/tensor.h>
#include <tiny_dnn/core/framework/device.h>
#include <tiny_dnn/core/framework/program_manager.h>
#include <tiny_dnn/layers/input_layer.h>
#include <tiny_dnn/layers/feedforward_layer.h>
#include <tiny_dnn/core/params/fully_params.h>
// tiny-dnn's kernels name core::fully_params unqualified; upstream this works
// because convolutional_layer.h (included first by tiny_dnn.h) opens the namespace.
namespace tiny_dnn {
using namespace tiny_dnn::core;  // NOLINT
}  // namespace tiny_dnn
#include <tiny_dnn/layers/fully_connected_layer.h>
#include <tiny_dnn/activations/activation_function.h>
#include <tiny_dnn/optimizers/optimizer.h>
#include <tiny_dnn/util/weight_init.h>
