// libFuzzer target: c3po::PointNetDetector::Load on arbitrary bytes, for a
// fixed identity: tests/fixtures/objects/cube.json, for which the seed model
// corpus/model/cube.model was trained (c3po train --epochs 1 --point-mlp 8 8
// --head 8 --points 32 on 8 sim clouds) and corpus/model/cube.ckpt, its
// training checkpoint.
#include "c3po/base/error.hpp"
#include "c3po/plugins/pointnet.hpp"
#include "fuzz_common.hpp"

namespace {
c3po::PointNetIdentity SeedIdentity() {
  c3po::PointNetIdentity identity;
  identity.object_name = "cube";
  identity.keypoint_hash = "4015274a702b0b0a";
  identity.num_keypoints = 8;
  identity.scale = 1.7320508075688772;
  return identity;
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const c3po::PointNetIdentity identity = SeedIdentity();
  const std::string path = c3po_fuzz::WriteScratch("model.c3pomodel", c3po_fuzz::Bytes(data, size));
  try {
    // A file that loads as a model is also read as a checkpoint of itself
    // (same identity and architecture): the optimiser state and progress.
    const auto detector = c3po::PointNetDetector::Load(path, identity);
    detector->LoadCheckpoint(path);
  } catch (const c3po::InputError&) {
    // expected for bad input
  }
  return 0;
}
