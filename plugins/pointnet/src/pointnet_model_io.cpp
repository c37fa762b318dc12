// PointNetDetector's model and checkpoint files (format in pointnet.hpp).
#include <cmath>
#include <cstdint>
#include <limits>
#include <sstream>

#include <nlohmann/json.hpp>

#include "c3po/base/atomic_file.hpp"
#include "c3po/base/error.hpp"
#include "c3po/base/json.hpp"
#include "detector_impl.hpp"
#include "model_file.hpp"

namespace c3po {
namespace {

using nlohmann::json;

json EpochToJson(const EpochLog& log) {
  auto number = [](double v) { return std::isfinite(v) ? json(v) : json(nullptr); };
  return {{"epoch", log.epoch}, {"train_loss", number(log.train_loss)},
          {"val_loss", number(log.val_loss)}, {"val_keypoint_error", number(log.val_keypoint_error)},
          {"seconds", log.seconds}, {"labellings_switched", log.labellings_switched}, {"best", log.best}};
}

double NumberOrNaN(const json& value) {
  return value.is_number() ? value.get<double>() : std::nan("");
}

int IntField(const json& j, const char* key, const std::string& path) {
  return static_cast<int>(IntegerInRange(j.at(key), 0, std::numeric_limits<int>::max(), path, key));
}

std::size_t SizeField(const json& j, const char* key, const std::string& path) {
  return static_cast<std::size_t>(IntegerInRange(j.at(key), 0, std::numeric_limits<std::int64_t>::max(), path, key));
}

EpochLog EpochFromJson(const json& j, const std::string& path) {
  EpochLog log;
  log.epoch = IntField(j, "epoch", path);
  log.train_loss = NumberOrNaN(j.at("train_loss"));
  log.val_loss = NumberOrNaN(j.at("val_loss"));
  log.val_keypoint_error = NumberOrNaN(j.at("val_keypoint_error"));
  log.seconds = j.at("seconds").get<double>();
  if (j.contains("labellings_switched")) log.labellings_switched = IntField(j, "labellings_switched", path);
  log.best = j.at("best").get<bool>();
  return log;
}

// A required header field of the expected JSON type, else InputError.
const json& Field(const json& header, const char* key, json::value_t type, const std::string& path) {
  const auto it = header.find(key);
  const bool ok = it != header.end() &&
                  (it->type() == type ||
                   (type == json::value_t::number_float && it->is_number()) ||
                   (type == json::value_t::number_integer && it->is_number_integer()));
  if (!ok) throw InputError(path, std::string("model header: missing or invalid \"") + key + "\"");
  return *it;
}

std::vector<int> Widths(const json& header, const char* key, const std::string& path) {
  const json& array = Field(header, key, json::value_t::array, path);
  std::vector<int> widths;
  for (const auto& w : array) {
    if (!w.is_number_integer()) throw InputError(path, std::string("model header: invalid \"") + key + "\"");
    widths.push_back(w.get<int>());
  }
  return widths;
}

// Weights + biases of the point MLP (from 3 channels) and the head (to 3N).
std::size_t ParameterCount(const PointNetArchitecture& architecture, int num_keypoints) {
  std::vector<std::size_t> widths = {3};
  for (int w : architecture.point_mlp) widths.push_back(static_cast<std::size_t>(w));
  for (int w : architecture.head) widths.push_back(static_cast<std::size_t>(w));
  widths.push_back(3 * static_cast<std::size_t>(num_keypoints));
  std::size_t count = 0;
  for (std::size_t l = 0; l + 1 < widths.size(); ++l) count += widths[l + 1] * (widths[l] + 1);
  return count;
}

void CheckFinite(const std::vector<float>& values, const std::string& path, const char* what) {
  for (float v : values) {
    if (!std::isfinite(v)) throw InputError(path, std::string("corrupt model: non-finite ") + what);
  }
}

std::string Compose(const PointNetDetector::Impl& impl, bool checkpoint, const std::string& extra_json,
                    const std::string& state_json) {
  const std::vector<float> weights = impl.network->Weights();
  json header = {{"detector", "pointnet"},
                 {"kind", checkpoint ? "checkpoint" : "model"},
                 {"object", impl.identity.object_name},
                 {"keypoint_hash", impl.identity.keypoint_hash},
                 {"num_keypoints", impl.identity.num_keypoints},
                 {"num_points", impl.architecture.num_points},
                 {"scale", impl.identity.scale},
                 {"point_mlp", impl.architecture.point_mlp},
                 {"head", impl.architecture.head},
                 {"weights", {{"count", weights.size()}, {"dtype", "float32-le"}}},
                 {"training", json::parse(impl.training_info)}};
  pointnet::BinaryWriter binary;
  binary.Floats(weights);
  if (checkpoint) {
    std::ostringstream state;
    if (impl.optimizer) impl.optimizer->SaveState(state);
    header["optimizer"] = {{"kind", impl.optimizer ? impl.optimizer->kind() : ""},
                           {"lr", impl.optimizer_lr},
                           {"momentum", impl.optimizer_momentum},
                           {"state_bytes", state.str().size()}};
    binary.Raw(state.str());
    const PointNetProgress& p = impl.progress;
    json history = json::array();
    for (const auto& log : p.history) history.push_back(EpochToJson(log));
    header["progress"] = {{"epochs_done", p.epochs_done},
                          {"best_epoch", p.best_epoch},
                          {"best_val_loss", std::isfinite(p.best_val_loss) ? json(p.best_val_loss) : json(nullptr)},
                          {"best_weights", p.best_weights.size()},
                          {"history", history}};
    binary.Floats(p.best_weights);
    header["state"] = state_json;
  }
  if (!extra_json.empty()) {
    json extra;
    try {
      extra = json::parse(extra_json);
    } catch (const json::exception& e) {
      throw std::invalid_argument(std::string("header extra is not JSON: ") + e.what());
    }
    if (!extra.is_object()) throw std::invalid_argument("header extra must be a JSON object");
    for (auto it = extra.begin(); it != extra.end(); ++it) {
      if (header.contains(it.key()) || it.key() == "magic" || it.key() == "format_version" ||
          it.key() == "binary") {
        throw std::invalid_argument("header extra may not redefine \"" + it.key() + "\"");
      }
      header[it.key()] = it.value();
    }
  }
  return pointnet::ComposeModelFile(header, binary.bytes());
}

void RestoreCheckpoint(const json& header, pointnet::BinaryReader* reader, const std::string& path,
                       PointNetDetector::Impl* impl) {
  const json& optimizer = Field(header, "optimizer", json::value_t::object, path);
  const json& progress = Field(header, "progress", json::value_t::object, path);
  try {
    const std::string kind = optimizer.at("kind").get<std::string>();
    const std::string state = reader->Raw(SizeField(optimizer, "state_bytes", path), "optimizer state");
    if (!kind.empty()) {
      PointNetTrainOptions options;
      options.optimizer = kind;
      options.lr = optimizer.at("lr").get<double>();
      options.momentum = optimizer.at("momentum").get<double>();
      impl->EnsureOptimizer(options);
      std::istringstream in(state);
      if (!impl->optimizer->LoadState(in)) throw InputError(path, "corrupt checkpoint: optimizer state");
    }
    PointNetProgress& p = impl->progress;
    p.epochs_done = IntField(progress, "epochs_done", path);
    p.best_epoch = IntField(progress, "best_epoch", path);
    p.best_val_loss = progress.at("best_val_loss").is_number()
                          ? progress.at("best_val_loss").get<double>()
                          : std::numeric_limits<double>::infinity();
    for (const auto& log : progress.at("history")) p.history.push_back(EpochFromJson(log, path));
    p.best_weights = reader->Floats(SizeField(progress, "best_weights", path), "best weights");
    if (header.contains("state") && header["state"].is_string()) {
      impl->checkpoint_state = header["state"].get<std::string>();
    }
    CheckFinite(p.best_weights, path, "best weights");
  } catch (const json::exception& e) {
    throw InputError(path, std::string("corrupt checkpoint header: ") + e.what());
  } catch (const std::invalid_argument& e) {
    throw InputError(path, std::string("corrupt checkpoint: ") + e.what());
  }
}

}  // namespace

void PointNetDetector::Save(const std::string& path, const std::string& header_extra_json) const {
  WriteFileAtomically(path, Compose(*impl_, /*checkpoint=*/false, header_extra_json, ""));
}

void PointNetDetector::SaveCheckpoint(const std::string& path, const std::string& state_json) const {
  WriteFileAtomically(path, Compose(*impl_, /*checkpoint=*/true, "", state_json));
}

std::unique_ptr<PointNetDetector> PointNetDetector::Load(const std::string& path,
                                                         const ObjectModel& object) {
  return Load(path, PointNetIdentity::ForObject(object));
}

namespace {

std::unique_ptr<PointNetDetector::Impl> LoadImpl(const std::string& path,
                                                 const PointNetIdentity& expected, bool checkpoint) {
  const pointnet::ModelFile file = pointnet::ReadModelFile(path);
  const json& h = file.header;
  const std::string detector = Field(h, "detector", json::value_t::string, path).get<std::string>();
  if (detector != "pointnet") {
    throw InputError(path, "model is for detector '" + detector + "', not 'pointnet'");
  }
  PointNetIdentity identity;
  identity.object_name = Field(h, "object", json::value_t::string, path).get<std::string>();
  identity.keypoint_hash = Field(h, "keypoint_hash", json::value_t::string, path).get<std::string>();
  identity.num_keypoints = Field(h, "num_keypoints", json::value_t::number_integer, path).get<int>();
  identity.scale = Field(h, "scale", json::value_t::number_float, path).get<double>();
  if (identity.object_name != expected.object_name || identity.keypoint_hash != expected.keypoint_hash) {
    throw InputError(path, "trained for object '" + identity.object_name + "' (keypoint hash " +
                               identity.keypoint_hash + "), not '" + expected.object_name +
                               "' (keypoint hash " + expected.keypoint_hash + ")");
  }
  if (identity.num_keypoints != expected.num_keypoints) {
    throw InputError(path, "model has " + std::to_string(identity.num_keypoints) +
                               " keypoints, the object has " + std::to_string(expected.num_keypoints));
  }
  PointNetArchitecture architecture;
  architecture.num_points = Field(h, "num_points", json::value_t::number_integer, path).get<int>();
  architecture.point_mlp = Widths(h, "point_mlp", path);
  architecture.head = Widths(h, "head", path);
  const std::string kind = Field(h, "kind", json::value_t::string, path).get<std::string>();
  if (checkpoint && kind != "checkpoint") throw InputError(path, "is a model, not a training checkpoint");
  try {
    identity.Check();
    architecture.Check();
  } catch (const std::invalid_argument& e) {
    throw InputError(path, std::string("invalid model header: ") + e.what());
  }
  // Sizes are checked against the file before any network is allocated.
  const json& weights = Field(h, "weights", json::value_t::object, path);
  const std::size_t expected_count = ParameterCount(architecture, identity.num_keypoints);
  if (!weights.contains("count") || !weights["count"].is_number_unsigned() ||
      weights["count"].get<std::size_t>() != expected_count ||
      expected_count > file.binary.size() / sizeof(float)) {
    throw InputError(path, "corrupt model: weight count does not match the architecture (" +
                               std::to_string(expected_count) + ")");
  }
  auto impl = std::make_unique<PointNetDetector::Impl>(identity, architecture, 0);
  if (impl->network->Weights().size() != expected_count) {
    throw std::logic_error("pointnet: parameter count formula disagrees with the network");
  }
  pointnet::BinaryReader reader(file.binary, path);
  const std::vector<float> values = reader.Floats(expected_count, "weights");
  CheckFinite(values, path, "weights");
  impl->network->SetWeights(values);
  if (h.contains("training") && h["training"].is_object()) impl->training_info = h["training"].dump();
  if (checkpoint) {
    RestoreCheckpoint(h, &reader, path, impl.get());
    if (!impl->progress.best_weights.empty() && impl->progress.best_weights.size() != expected_count) {
      throw InputError(path, "corrupt checkpoint: best weights have the wrong size");
    }
  }
  return impl;
}

}  // namespace

std::unique_ptr<PointNetDetector> PointNetDetector::Load(const std::string& path,
                                                         const PointNetIdentity& expected) {
  return std::unique_ptr<PointNetDetector>(new PointNetDetector(LoadImpl(path, expected, false)));
}

std::string PointNetDetector::LoadCheckpoint(const std::string& path) {
  std::unique_ptr<Impl> loaded = LoadImpl(path, impl_->identity, true);
  const PointNetArchitecture& a = loaded->architecture;
  const PointNetArchitecture& b = impl_->architecture;
  if (a.num_points != b.num_points || a.point_mlp != b.point_mlp || a.head != b.head) {
    throw InputError(path, "checkpoint has another network architecture than this detector");
  }
  loaded->threads = impl_->threads;
  loaded->step_options = impl_->step_options;
  impl_ = std::move(loaded);
  return impl_->checkpoint_state;
}

}  // namespace c3po
