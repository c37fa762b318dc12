// Camera JSON and depth images (camera_io.hpp).
#include "c3po/io/camera_io.hpp"

#include <cmath>
#include <cstring>
#include <nlohmann/json.hpp>
#include <sstream>

#include "c3po/base/atomic_file.hpp"
#include "c3po/base/error.hpp"

#include "json_input_internal.hpp"

namespace c3po {
namespace {

using nlohmann::json;

using io_detail::ParseJson;
using io_detail::FiniteNumber;

CameraInfo CameraFromEntry(const json& entry, const std::string& name, const std::string& prefix,
                           std::optional<double> depth_scale) {
  if (!entry.is_object()) throw InputError(name, prefix + "expected a JSON object");
  CameraInfo camera;
  if (entry.contains("cam_K")) {
    const json& k = entry["cam_K"];
    if (!k.is_array() || k.size() != 9) throw InputError(name, prefix + "cam_K: expected 9 numbers (row-major 3x3)");
    double m[9];
    for (std::size_t i = 0; i < 9; ++i) m[i] = FiniteNumber(k[i], name, prefix + "cam_K");
    if (m[1] != 0.0 || m[3] != 0.0 || m[6] != 0.0 || m[7] != 0.0 || m[8] != 1.0) {
      throw InputError(name, prefix + "cam_K: expected [fx, 0, cx, 0, fy, cy, 0, 0, 1] (no skew)");
    }
    camera.K = {m[0], m[4], m[2], m[5]};
  } else if (entry.contains("fx") || entry.contains("fy") || entry.contains("cx") || entry.contains("cy")) {
    for (const char* key : {"fx", "fy", "cx", "cy"}) {
      if (!entry.contains(key)) throw InputError(name, prefix + key + ": missing");
    }
    camera.K = {FiniteNumber(entry["fx"], name, prefix + "fx"), FiniteNumber(entry["fy"], name, prefix + "fy"),
                FiniteNumber(entry["cx"], name, prefix + "cx"), FiniteNumber(entry["cy"], name, prefix + "cy")};
  } else {
    throw InputError(name, prefix + "cam_K: missing (nor fx, fy, cx, cy)");
  }
  if (depth_scale) {
    camera.depth_scale = *depth_scale;
  } else if (entry.contains("depth_scale")) {
    camera.depth_scale = FiniteNumber(entry["depth_scale"], name, prefix + "depth_scale");
  } else {
    throw InputError(name, prefix + "depth_scale: missing (give --depth-scale S)");
  }
  CheckCamera(camera, name + (prefix.empty() ? "" : ": " + prefix.substr(0, prefix.size() - 2)));
  return camera;
}

bool AllKeysNumbered(const json& doc) {
  if (!doc.is_object() || doc.empty()) return false;
  for (const auto& item : doc.items()) {
    const std::string& key = item.key();
    if (key.empty() || key.size() > 9 || key.find_first_not_of("0123456789") != std::string::npos) return false;
  }
  return true;
}

}  // namespace

void CheckCamera(const CameraInfo& camera, const std::string& where) {
  if (!std::isfinite(camera.depth_scale) || camera.depth_scale <= 0.0) {
    throw InputError(where, "depth_scale must be a positive number, not " + std::to_string(camera.depth_scale));
  }
  camera.K.Check(where);
}

CameraInfo ParseCameraJson(const std::string& text, const std::string& name, std::optional<double> depth_scale,
                           std::optional<int> im_id) {
  const json doc = ParseJson(text, name);
  if (AllKeysNumbered(doc)) {
    if (im_id) {
      const std::string key = std::to_string(*im_id);
      // BOP writes keys without leading zeros; accept "000007" as well.
      for (const auto& item : doc.items()) {
        if (std::stol(item.key()) == *im_id) return CameraFromEntry(item.value(), name, item.key() + ": ", depth_scale);
      }
      throw InputError(name, "--im-id " + key + ": no such image among its " + std::to_string(doc.size()) +
                                 " entries (first id " + doc.items().begin().key() + ")");
    }
    if (doc.size() != 1) {
      throw InputError(name, "a scene_camera.json of " + std::to_string(doc.size()) +
                                 " images; give --im-id ID (or a single entry, or use --bop)");
    }
    const auto item = doc.items().begin();
    return CameraFromEntry(item.value(), name, item.key() + ": ", depth_scale);
  }
  // One camera (a scene_camera.json entry or BOP camera.json): it serves every
  // image, so --im-id has nothing to pick.
  return CameraFromEntry(doc, name, "", depth_scale);
}

CameraInfo ReadCameraJson(const std::string& path, std::optional<double> depth_scale, std::optional<int> im_id) {
  return ParseCameraJson(ReadFileToString(path), path, depth_scale, im_id);
}

std::map<int, CameraInfo> ParseSceneCamera(const std::string& text, const std::string& name) {
  const json doc = ParseJson(text, name);
  if (!doc.is_object()) throw InputError(name, "expected an object keyed by image id");
  std::map<int, CameraInfo> cameras;
  for (const auto& item : doc.items()) {
    const std::string& key = item.key();
    if (key.empty() || key.size() > 9 || key.find_first_not_of("0123456789") != std::string::npos) {
      throw InputError(name, "key '" + key.substr(0, 40) + "' is not an image id");
    }
    cameras[std::stoi(key)] = CameraFromEntry(item.value(), name, key + ": ", std::nullopt);
  }
  return cameras;
}

CameraInfo CameraFromIntrinsics(const std::string& fx_fy_cx_cy, double depth_scale) {
  std::vector<double> values;
  std::stringstream stream(fx_fy_cx_cy);
  std::string item;
  while (std::getline(stream, item, ',')) {
    char* end = nullptr;
    const double value = std::strtod(item.c_str(), &end);
    if (item.empty() || end != item.c_str() + item.size()) {
      throw InputError("--intrinsics", "'" + item + "' is not a number (expected fx,fy,cx,cy)");
    }
    values.push_back(value);
  }
  if (values.size() != 4) throw InputError("--intrinsics", "expected 4 numbers fx,fy,cx,cy");
  CameraInfo camera{{values[0], values[1], values[2], values[3]}, depth_scale};
  CheckCamera(camera, "--intrinsics/--depth-scale");
  return camera;
}

DepthImage DepthFromPng(const Image& image, double depth_scale) {
  DepthImage depth{image.width, image.height, std::vector<float>(image.pixels.size())};
  const double metres_per_unit = depth_scale * kMetresPerMillimetre;
  for (std::size_t i = 0; i < image.pixels.size(); ++i) {
    depth.z[i] = static_cast<float>(image.pixels[i] * metres_per_unit);
  }
  return depth;
}

namespace {

// What a .npy header says of a depth image (format 1.0-3.0: magic, version, header length, a Python dict).
struct NpyLayout {
  int item_size = 0;           // 4 ('<f4') or 8 ('<f8')
  bool column_major = false;   // fortran_order
  std::size_t height = 0, width = 0;
  std::size_t data_offset = 0;
};

// The header's dict text; `offset` receives where it starts.
std::string NpyHeaderText(const std::string& bytes, const std::string& name, std::size_t* offset) {
  static const char kMagic[] = "\x93NUMPY";
  if (bytes.size() < 10 || bytes.compare(0, 6, kMagic, 6) != 0) throw InputError(name, "not a .npy file (bad magic)");
  const int major = static_cast<unsigned char>(bytes[6]);
  const auto byte = [&bytes](std::size_t i) { return static_cast<std::size_t>(static_cast<unsigned char>(bytes[i])); };
  std::size_t header_len = 0;
  if (major == 1) {
    header_len = byte(8) | (byte(9) << 8);
    *offset = 10;
  } else if (major == 2 || major == 3) {
    if (bytes.size() < 12) throw InputError(name, "truncated .npy header");
    for (int i = 0; i < 4; ++i) header_len |= byte(8 + i) << (8 * i);
    *offset = 12;
  } else {
    throw InputError(name, ".npy version " + std::to_string(major) + " is not supported");
  }
  if (header_len > 65536 || *offset + header_len > bytes.size()) throw InputError(name, "truncated .npy header");
  return bytes.substr(*offset, header_len);
}

// The value of 'key' in the header's dict, as written (a tuple with its parentheses).
std::string NpyHeaderValue(const std::string& header, const std::string& key, const std::string& name) {
  const std::size_t at = header.find("'" + key + "'");
  if (at == std::string::npos) throw InputError(name, ".npy header: '" + key + "' missing");
  const std::size_t colon = header.find(':', at);
  if (colon == std::string::npos) throw InputError(name, ".npy header: malformed '" + key + "'");
  const std::size_t start = header.find_first_not_of(' ', colon + 1);
  if (start == std::string::npos) throw InputError(name, ".npy header: malformed '" + key + "'");
  const bool tuple = header[start] == '(';
  const std::size_t end = tuple ? header.find(')', start) : header.find_first_of(",}", start);
  if (end == std::string::npos) throw InputError(name, ".npy header: malformed '" + key + "'");
  return header.substr(start, end - start + (tuple ? 1 : 0));
}

// "(H, W)" -> {H, W}: non-negative integers of at most 9 digits, a trailing comma allowed.
std::vector<long long> NpyShape(const std::string& shape, const std::string& name) {
  if (shape.size() < 2 || shape.front() != '(' || shape.back() != ')') {
    throw InputError(name, ".npy header: shape must be a tuple (H, W)");
  }
  std::vector<long long> dims;
  std::stringstream stream(shape.substr(1, shape.size() - 2));
  std::string item;
  while (std::getline(stream, item, ',')) {
    const std::size_t first = item.find_first_not_of(' ');
    if (first == std::string::npos) continue;   // trailing comma
    item = item.substr(first, item.find_last_not_of(' ') - first + 1);
    if (item.empty() || item.size() > 9 || item.find_first_not_of("0123456789") != std::string::npos) {
      throw InputError(name, ".npy header: bad shape " + shape.substr(0, 40));
    }
    dims.push_back(std::stoll(item));
  }
  return dims;
}

NpyLayout ParseNpyLayout(const std::string& bytes, const std::string& name) {
  NpyLayout layout;
  std::size_t offset = 0;
  const std::string header = NpyHeaderText(bytes, name, &offset);
  const std::string descr = NpyHeaderValue(header, "descr", name);
  if (descr == "'<f4'") layout.item_size = 4;
  else if (descr == "'<f8'") layout.item_size = 8;
  else throw InputError(name, ".npy dtype " + descr.substr(0, 20) +
                              " is not float32/float64 little-endian ('<f4', '<f8')");
  const std::string fortran = NpyHeaderValue(header, "fortran_order", name);
  if (fortran != "False" && fortran != "True") {
    throw InputError(name, ".npy header: fortran_order must be True or False");
  }
  layout.column_major = fortran == "True";
  const std::string shape = NpyHeaderValue(header, "shape", name);
  const std::vector<long long> dims = NpyShape(shape, name);
  if (dims.size() != 2) throw InputError(name, ".npy depth must have shape (H, W), not " + shape.substr(0, 40));
  if (dims[0] <= 0 || dims[1] <= 0) throw InputError(name, ".npy depth of zero size");
  layout.height = static_cast<std::size_t>(dims[0]);
  layout.width = static_cast<std::size_t>(dims[1]);
  if (layout.width * layout.height > kMaxImagePixels) throw InputError(name, ".npy depth larger than the image limit");
  layout.data_offset = offset + header.size();
  return layout;
}

}  // namespace

DepthImage ParseNpyDepth(const std::string& bytes, const std::string& name) {
  const NpyLayout layout = ParseNpyLayout(bytes, name);
  const std::size_t count = layout.width * layout.height;
  const std::size_t expected = count * static_cast<std::size_t>(layout.item_size);
  if (bytes.size() - layout.data_offset != expected) {
    throw InputError(name, ".npy data holds " + std::to_string(bytes.size() - layout.data_offset) +
                               " bytes, shape needs " + std::to_string(expected));
  }
  DepthImage depth{static_cast<int>(layout.width), static_cast<int>(layout.height), std::vector<float>(count)};
  const char* data = bytes.data() + layout.data_offset;
  for (std::size_t i = 0; i < count; ++i) {
    double value;
    if (layout.item_size == 4) {
      float f;
      std::memcpy(&f, data + 4 * i, 4);
      value = f;
    } else {
      std::memcpy(&value, data + 8 * i, 8);
    }
    if (std::isinf(value) || value < 0.0) throw InputError(name, "negative or infinite depth in .npy");
    if (std::isnan(value)) value = 0.0;
    const std::size_t target = layout.column_major ? (i % layout.height) * layout.width + i / layout.height : i;
    depth.z[target] = static_cast<float>(value);
  }
  return depth;
}

DepthImage ReadDepth(const std::string& path, double depth_scale) {
  const std::size_t dot = path.rfind('.');
  const std::string ext = dot == std::string::npos ? "" : path.substr(dot);
  if (ext == ".npy" || ext == ".NPY") return ParseNpyDepth(ReadFileToString(path), path);
  return DepthFromPng(ReadDepthPng(path), depth_scale);
}

std::string EncodeNpyDepth(const DepthImage& depth) {
  std::string header = "{'descr': '<f4', 'fortran_order': False, 'shape': (" + std::to_string(depth.height) + ", " +
                       std::to_string(depth.width) + "), }";
  while ((10 + header.size() + 1) % 64 != 0) header += ' ';
  header += '\n';
  std::string out("\x93NUMPY\x01\x00", 8);
  out += static_cast<char>(header.size() & 0xff);
  out += static_cast<char>(header.size() >> 8);
  out += header;
  const std::size_t start = out.size();
  out.resize(start + 4 * depth.z.size());
  std::memcpy(&out[start], depth.z.data(), 4 * depth.z.size());
  return out;
}

}  // namespace c3po
