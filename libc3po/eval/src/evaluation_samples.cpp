// Per-sample rows of an evaluation and their merge (evaluation_samples.hpp).
#include "c3po/eval/evaluation_samples.hpp"

#include <cmath>
#include <limits>
#include <nlohmann/json.hpp>

#include "c3po/base/lines.hpp"
#include "c3po/base/error.hpp"
#include "c3po/base/json.hpp"
#include "c3po/io/shard.hpp"

namespace c3po {
namespace {

using nlohmann::json;

constexpr const char* kMagic = "c3po_eval_samples";
constexpr int kVersion = 1;

// A double that reads back bit for bit: nlohmann writes the shortest
// round-trip form; non-finite values become strings.
json Exact(double value) {
  if (std::isnan(value)) return "nan";
  if (std::isinf(value)) return value > 0 ? "inf" : "-inf";
  return value;
}

double ReadExact(const json& value, const std::string& where, const char* key) {
  if (value.is_number()) return value.get<double>();
  if (value.is_string()) {
    const std::string text = value.get<std::string>();
    if (text == "inf") return std::numeric_limits<double>::infinity();
    if (text == "-inf") return -std::numeric_limits<double>::infinity();
    if (text == "nan") return std::numeric_limits<double>::quiet_NaN();
  }
  throw InputError(where, std::string(key) + ": expected a number (or \"inf\", \"-inf\", \"nan\")");
}

const json& Field(const json& object, const char* key, const std::string& where) {
  const auto it = object.find(key);
  if (it == object.end()) throw InputError(where, std::string(key) + ": missing");
  return *it;
}

double Number(const json& object, const char* key, const std::string& where) {
  return ReadExact(Field(object, key, where), where, key);
}

bool Bool(const json& object, const char* key, const std::string& where) {
  const json& value = Field(object, key, where);
  if (!value.is_boolean()) throw InputError(where, std::string(key) + ": expected true or false");
  return value.get<bool>();
}

std::string String(const json& object, const char* key, const std::string& where) {
  const json& value = Field(object, key, where);
  if (!value.is_string()) throw InputError(where, std::string(key) + ": expected a string");
  return value.get<std::string>();
}

long long Integer(const json& object, const char* key, const std::string& where, long long lo, long long hi) {
  const json& value = Field(object, key, where);
  if (!value.is_number_integer()) throw InputError(where, std::string(key) + ": expected an integer");
  const long long n = value.get<long long>();
  if (n < lo || n > hi) throw InputError(where, std::string(key) + ": " + std::to_string(n) + " out of range");
  return n;
}

json SettingsJson(const EvaluationOptions& o) {
  const CertificateOptions& c = o.pipeline.certificate;
  const CorrectorOptions& k = o.pipeline.corrector;
  json s;
  s["adds_variant"] = ToString(o.adds_variant);
  s["adds_threshold"] = Exact(o.adds_threshold);
  s["auc_max"] = Exact(o.auc_max);
  s["eps_oc"] = Exact(c.eps_oc);
  s["delta_nd"] = Exact(c.delta_nd);
  s["max_outliers_count"] = c.max_outliers.count;
  s["max_outliers_fraction"] = Exact(c.max_outliers.fraction);
  s["local_nondegeneracy"] = c.local_nondegeneracy;
  s["local_min_eigenvalue"] = Exact(c.local.min_eigenvalue);
  s["reestimate"] = c.global.reestimate;
  s["solver"] = ToString(k.solver);
  s["loss"] = ToString(k.loss);
  s["robust_loss"] = ToString(k.robust_loss);
  s["kappa"] = Exact(k.kappa);
  s["theta"] = Exact(k.theta);
  s["run_icp"] = o.run_icp;
  s["run_ransac"] = o.run_ransac;
  s["icp_max_iterations"] = o.icp.max_iterations;
  s["icp_max_correspondence_distance"] = Exact(o.icp.max_correspondence_distance);
  s["icp_trim_fraction"] = Exact(o.icp.trim_fraction);
  s["ransac_inlier_threshold"] = Exact(o.ransac.inlier_threshold);
  s["ransac_max_iterations"] = o.ransac.max_iterations;
  s["ransac_seed"] = o.ransac.seed;
  s["worst_listed"] = o.worst_listed;
  json symmetries = json::array();
  for (const Pose& symmetry : o.symmetries) {
    json pose = json::array();
    for (int i = 0; i < 9; ++i) pose.push_back(Exact(symmetry.R(i / 3, i % 3)));
    for (int i = 0; i < 3; ++i) pose.push_back(Exact(symmetry.t(i)));
    symmetries.push_back(pose);
  }
  s["symmetries"] = symmetries;
  return s;
}

// "symmetries": [[R row-major (9), t (3)], ...]; absent in files written
// before it existed (= none). At most 64.
std::vector<Pose> SymmetriesFromSettings(const json& s, const std::string& where) {
  std::vector<Pose> symmetries;
  const auto it = s.find("symmetries");
  if (it == s.end()) return symmetries;
  if (!it->is_array() || it->size() > 64) throw InputError(where, "symmetries: expected an array of at most 64 poses");
  for (const json& pose : *it) {
    if (!pose.is_array() || pose.size() != 12) throw InputError(where, "symmetries: each pose is 12 numbers (R, t)");
    Pose symmetry;
    for (int i = 0; i < 9; ++i) symmetry.R(i / 3, i % 3) = ReadExact(pose[static_cast<std::size_t>(i)], where, "symmetries");
    for (int i = 0; i < 3; ++i) symmetry.t(i) = ReadExact(pose[static_cast<std::size_t>(9 + i)], where, "symmetries");
    symmetries.push_back(symmetry);
  }
  return symmetries;
}

// The options the table and JSON show, back from SettingsJson (the rest keep
// their defaults: they are not part of any output).
EvaluationOptions OptionsFromSettings(const json& s, const std::string& where) {
  if (!s.is_object()) throw InputError(where, "settings: expected an object");
  EvaluationOptions o;
  try {
    o.adds_variant = ParseAddSVariant(String(s, "adds_variant", where));
    o.pipeline.corrector.solver = ParseCorrectorSolver(String(s, "solver", where));
    o.pipeline.corrector.loss = ParsePointCloudLoss(String(s, "loss", where));
    o.pipeline.corrector.robust_loss = ParseRobustLoss(String(s, "robust_loss", where));
  } catch (const InputError& e) {
    throw InputError(where, std::string("settings: ") + e.what());
  }
  o.adds_threshold = Number(s, "adds_threshold", where);
  o.auc_max = Number(s, "auc_max", where);
  CertificateOptions& c = o.pipeline.certificate;
  c.eps_oc = Number(s, "eps_oc", where);
  c.delta_nd = Number(s, "delta_nd", where);
  c.max_outliers.count = static_cast<int>(Integer(s, "max_outliers_count", where, 0, 1 << 30));
  c.max_outliers.fraction = Number(s, "max_outliers_fraction", where);
  c.local_nondegeneracy = Bool(s, "local_nondegeneracy", where);
  c.local.min_eigenvalue = Number(s, "local_min_eigenvalue", where);
  // Absent in files written before re-estimation was named (= off, as it was by default then).
  c.global.reestimate = s.contains("reestimate") && Bool(s, "reestimate", where);
  o.pipeline.corrector.kappa = Number(s, "kappa", where);
  o.pipeline.corrector.theta = Number(s, "theta", where);
  o.run_icp = Bool(s, "run_icp", where);
  o.run_ransac = Bool(s, "run_ransac", where);
  o.icp.max_iterations = static_cast<int>(Integer(s, "icp_max_iterations", where, 0, 1 << 30));
  o.icp.max_correspondence_distance = Number(s, "icp_max_correspondence_distance", where);
  o.icp.trim_fraction = Number(s, "icp_trim_fraction", where);
  o.ransac.inlier_threshold = Number(s, "ransac_inlier_threshold", where);
  o.ransac.max_iterations = static_cast<int>(Integer(s, "ransac_max_iterations", where, 0, 1 << 30));
  o.ransac.seed = Field(s, "ransac_seed", where).is_number_unsigned()
                      ? Field(s, "ransac_seed", where).get<std::uint64_t>()
                      : throw InputError(where, "ransac_seed: expected an unsigned integer");
  o.worst_listed = static_cast<int>(Integer(s, "worst_listed", where, 0, 1 << 30));
  o.symmetries = SymmetriesFromSettings(s, where);
  try {
    o.Check();
  } catch (const std::invalid_argument& e) {
    throw InputError(where, std::string("settings: ") + e.what());
  } catch (const InputError& e) {
    throw InputError(where, std::string("settings: ") + e.what());
  }
  return o;
}

EvalMethod ParseMethod(const std::string& text, const std::string& where) {
  for (EvalMethod m : {EvalMethod::kKeyPo, EvalMethod::kKeyPoIcp, EvalMethod::kKeyPoCorrector, EvalMethod::kC3po,
                       EvalMethod::kKeyPoRansacIcp}) {
    if (text == ToString(m)) return m;
  }
  throw InputError(where, "rows: unknown method '" + text.substr(0, 40) + "'");
}

json SampleLine(int row, const SampleResult& s) {
  json j;
  j["row"] = row;
  j["index"] = s.index;
  j["cloud"] = s.cloud;
  if (!s.ok()) j["error"] = s.error;
  j["adds"] = Exact(s.adds);
  j["rotation_error"] = Exact(s.rotation_error);
  j["translation_error"] = Exact(s.translation_error);
  j["oc"] = s.oc;
  j["nd"] = s.nd;
  j["free_space"] = s.free_space;
  j["oc_distance"] = Exact(s.oc_distance);
  j["hausdorff"] = Exact(s.hausdorff);   // NaN unless certified (eval's Hausdorff check)
  j["ms"] = Exact(s.milliseconds);
  if (s.ok()) SetPoseJson(s.scene_from_model, &j);
  return j;
}

Pose ReadPose(const json& line, const std::string& where) {
  const json& R = Field(line, "R", where);
  const json& t = Field(line, "t", where);
  if (!R.is_array() || R.size() != 3 || !t.is_array() || t.size() != 3) {
    throw InputError(where, "R, t: expected 3 rows of 3 and 3 numbers");
  }
  Pose pose;
  for (int r = 0; r < 3; ++r) {
    if (!R[r].is_array() || R[r].size() != 3) throw InputError(where, "R: expected 3 rows of 3 numbers");
    for (int c = 0; c < 3; ++c) pose.R(r, c) = ReadExact(R[r][c], where, "R");
    pose.t(r) = ReadExact(t[r], where, "t");
  }
  return pose;
}

SampleResult ReadSample(const json& line, const std::string& where) {
  SampleResult s;
  s.index = static_cast<std::size_t>(Integer(line, "index", where, 0, 1LL << 40));
  s.cloud = String(line, "cloud", where);
  if (line.contains("error")) {
    s.error = String(line, "error", where);
    if (s.error.empty()) throw InputError(where, "error: empty");
  }
  s.adds = Number(line, "adds", where);
  s.rotation_error = Number(line, "rotation_error", where);
  s.translation_error = Number(line, "translation_error", where);
  s.oc = Bool(line, "oc", where);
  s.nd = Bool(line, "nd", where);
  // Sample files written before frames were evaluated have no "free_space": no frame.
  s.free_space = line.contains("free_space") ? Bool(line, "free_space", where) : true;
  s.oc_distance = Number(line, "oc_distance", where);
  s.hausdorff = Number(line, "hausdorff", where);
  s.milliseconds = Number(line, "ms", where);
  if (s.ok()) s.scene_from_model = ReadPose(line, where);
  return s;
}

struct Part {
  json header;                                   // without "shard" and "clouds"
  Shard shard;
  std::size_t clouds = 0;
  std::vector<std::vector<SampleResult>> rows;   // per header row
};

Part ReadPart(const std::string& name, const std::string& text) {
  Part part;
  std::size_t line_number = 0;
  for (const std::string_view view : SplitLines(text)) {
    const std::string line(view);
    ++line_number;
    const std::string where = name + ": line " + std::to_string(line_number);
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    const json parsed = json::parse(line, nullptr, false);
    if (!parsed.is_object()) throw InputError(where, "not a JSON object");
    if (part.header.is_null()) {
      if (!parsed.contains(kMagic)) throw InputError(where, "not an eval samples file (no \"c3po_eval_samples\" header; write it with eval --samples)");
      if (Integer(parsed, kMagic, where, 0, 1000) != kVersion) throw InputError(where, "unsupported samples version");
      try {
        part.shard = ParseShard(String(parsed, "shard", where));
      } catch (const InputError& e) {
        throw InputError(where, std::string("shard: ") + e.what());
      }
      part.clouds = static_cast<std::size_t>(Integer(parsed, "clouds", where, 0, 1LL << 40));
      String(parsed, "object", where);
      String(parsed, "dataset", where);
      const double diameter = Number(parsed, "diameter", where);
      if (!(diameter > 0) || !std::isfinite(diameter)) throw InputError(where, "diameter: must be positive");
      OptionsFromSettings(Field(parsed, "settings", where), where);
      const json& rows = Field(parsed, "rows", where);
      if (!rows.is_array() || rows.empty() || rows.size() > 1000) throw InputError(where, "rows: expected a list of rows");
      for (const json& row : rows) {
        if (!row.is_object()) throw InputError(where, "rows: expected objects");
        String(row, "label", where);
        String(row, "detector", where);
        ParseMethod(String(row, "method", where), where);
      }
      part.rows.resize(rows.size());
      part.header = parsed;
      part.header.erase("shard");
      part.header.erase("clouds");
      continue;
    }
    const std::size_t row = static_cast<std::size_t>(Integer(parsed, "row", where, 0, 1 << 30));
    if (row >= part.rows.size()) throw InputError(where, "row " + std::to_string(row) + ": not in the header's rows");
    SampleResult sample = ReadSample(parsed, where);
    std::vector<SampleResult>& samples = part.rows[row];
    if (sample.index != samples.size() || sample.index >= part.clouds) {
      throw InputError(where, "index " + std::to_string(sample.index) + ": expected " + std::to_string(samples.size()) +
                                  " (samples in dataset order, fewer than \"clouds\")");
    }
    samples.push_back(std::move(sample));
  }
  if (part.header.is_null()) throw InputError(name, "empty (an eval samples file starts with its header line)");
  for (std::size_t r = 0; r < part.rows.size(); ++r) {
    if (part.rows[r].size() != part.clouds) {
      throw InputError(name, "row " + std::to_string(r) + " has " + std::to_string(part.rows[r].size()) + " samples, not " +
                                 std::to_string(part.clouds) + " (truncated?)");
    }
  }
  return part;
}

}  // namespace

std::string EvaluationSamplesJsonl(const Evaluation& evaluation, const std::string& shard) {
  ParseShard(shard);
  json header;
  header[kMagic] = kVersion;
  header["shard"] = shard;
  header["object"] = evaluation.object_name;
  header["dataset"] = evaluation.dataset_dir;
  header["clouds"] = evaluation.clouds;
  header["diameter"] = Exact(evaluation.diameter);
  header["settings"] = SettingsJson(evaluation.options);
  json rows = json::array();
  std::vector<const EvaluationRow*> all;
  for (const EvaluationRow& row : evaluation.rows) {
    if (row.subset != EvalSubset::kAll) continue;
    rows.push_back({{"label", row.label}, {"detector", row.detector}, {"method", ToString(row.method)}});
    all.push_back(&row);
  }
  header["rows"] = rows;
  std::string out = header.dump() + "\n";
  for (std::size_t r = 0; r < all.size(); ++r) {
    for (const SampleResult& s : all[r]->samples) out += SampleLine(static_cast<int>(r), s).dump() + "\n";
  }
  return out;
}

bool IsEvaluationSamples(const std::string& text) {
  const std::string first = text.substr(0, text.find('\n'));
  const json parsed = json::parse(first, nullptr, false);
  return parsed.is_object() && parsed.contains(kMagic);
}

Evaluation MergeEvaluationSamples(const std::vector<std::pair<std::string, std::string>>& parts) {
  if (parts.empty()) throw InputError("c3po merge", "no parts");
  std::vector<Part> read;
  for (const auto& [name, text] : parts) read.push_back(ReadPart(name, text));
  const int count = read.front().shard.count;
  for (std::size_t k = 0; k < read.size(); ++k) {
    const std::string& name = parts[k].first;
    const Shard& shard = read[k].shard;
    if (shard.count != count || shard.index != static_cast<int>(k) + 1 || read.size() != static_cast<std::size_t>(count)) {
      throw InputError(name, "shard " + std::to_string(shard.index) + "/" + std::to_string(shard.count) + " given as part " +
                                 std::to_string(k + 1) + " of " + std::to_string(read.size()) +
                                 " (give every shard 1/N .. N/N once, in order)");
    }
    if (read[k].header != read.front().header) {
      throw InputError(name, "object, dataset or settings differ from " + parts.front().first + "'s (another run?)");
    }
  }
  const json& header = read.front().header;
  const std::string where = parts.front().first + ": line 1";
  Evaluation e;
  e.object_name = header["object"].get<std::string>();
  e.dataset_dir = header["dataset"].get<std::string>();
  e.diameter = Number(header, "diameter", where);
  e.options = OptionsFromSettings(header["settings"], where);
  const json& rows = header["rows"];
  std::vector<std::vector<SampleResult>> samples(rows.size());
  std::size_t offset = 0;
  for (const Part& part : read) {
    for (std::size_t r = 0; r < rows.size(); ++r) {
      for (SampleResult s : part.rows[r]) {
        s.index += offset;
        samples[r].push_back(std::move(s));
      }
    }
    offset += part.clouds;
  }
  e.clouds = offset;
  for (std::size_t r = 0; r < rows.size(); ++r) {
    const EvalMethod method = ParseMethod(rows[r]["method"].get<std::string>(), where);
    const std::string detector = rows[r]["detector"].get<std::string>();
    // A self-trained detector's C-3PO rows: all clouds, oc = 1, oc = nd = 1 (AppendRows).
    const std::vector<EvalSubset> subsets =
        method == EvalMethod::kC3po
            ? std::vector<EvalSubset>{EvalSubset::kAll, EvalSubset::kObservablyCorrect, EvalSubset::kCertified}
            : std::vector<EvalSubset>{EvalSubset::kAll};
    for (EvalSubset subset : subsets) {
      EvaluationRow row = MakeEvaluationRow(method, subset, detector, samples[r], e.options, e.diameter);
      if (subset == EvalSubset::kAll && row.label != rows[r]["label"].get<std::string>()) {
        throw InputError(where, "rows: label '" + rows[r]["label"].get<std::string>().substr(0, 60) +
                                    "' does not match its detector and method");
      }
      e.rows.push_back(std::move(row));
    }
  }
  return e;
}

}  // namespace c3po
