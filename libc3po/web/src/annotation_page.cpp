// The self-contained annotation page: data (object + mesh as base64 typed
// arrays) and three.js are inlined into the page template (annotation_page_html.cpp).
#include "c3po/web/annotation_page.hpp"

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <vector>

#include "annotation_page_html.hpp"
#include "c3po/base/atomic_file.hpp"
#include "c3po/base/error.hpp"
#include "embedded_resources.hpp"

namespace c3po {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

std::string Base64(const unsigned char* bytes, std::size_t size) {
  static const char kAlphabet[] =
      "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((size + 2) / 3 * 4);
  for (std::size_t i = 0; i < size; i += 3) {
    const std::uint32_t b0 = bytes[i];
    const std::uint32_t b1 = i + 1 < size ? bytes[i + 1] : 0;
    const std::uint32_t b2 = i + 2 < size ? bytes[i + 2] : 0;
    const std::uint32_t triple = (b0 << 16) | (b1 << 8) | b2;
    out += kAlphabet[(triple >> 18) & 63];
    out += kAlphabet[(triple >> 12) & 63];
    out += i + 1 < size ? kAlphabet[(triple >> 6) & 63] : '=';
    out += i + 2 < size ? kAlphabet[triple & 63] : '=';
  }
  return out;
}

// Little-endian float32 xyz per vertex (the page decodes with a DataView).
std::string VerticesBase64(const Mesh& mesh) {
  std::vector<unsigned char> bytes;
  bytes.reserve(static_cast<std::size_t>(mesh.vertices.size()) * 4);
  for (Eigen::Index i = 0; i < mesh.vertices.size(); ++i) {
    const float value = static_cast<float>(mesh.vertices.data()[i]);
    std::uint32_t bits;
    std::memcpy(&bits, &value, 4);
    for (int b = 0; b < 4; ++b) bytes.push_back(static_cast<unsigned char>(bits >> (8 * b)));
  }
  return Base64(bytes.data(), bytes.size());
}

// Little-endian uint32 vertex indices, three per triangle.
std::string TrianglesBase64(const Mesh& mesh) {
  std::vector<unsigned char> bytes;
  bytes.reserve(static_cast<std::size_t>(mesh.triangles.size()) * 4);
  for (Eigen::Index i = 0; i < mesh.triangles.size(); ++i) {
    const auto index = static_cast<std::uint32_t>(mesh.triangles.data()[i]);
    for (int b = 0; b < 4; ++b) bytes.push_back(static_cast<unsigned char>(index >> (8 * b)));
  }
  return Base64(bytes.data(), bytes.size());
}

// The mesh path as the object JSON names it (relative to the JSON's folder).
std::string MeshReference(const ObjectSpec& spec, const std::string& object_json_path) {
  const fs::path json_dir = fs::absolute(object_json_path).parent_path();
  const fs::path mesh(spec.mesh_path);
  return (mesh.is_absolute() ? fs::relative(mesh, json_dir) : mesh).generic_string();
}

json ObjectJson(const ObjectSpec& spec, const std::string& mesh_reference) {
  json object;
  object["schema_version"] = spec.schema_version;
  object["name"] = spec.name;
  object["mesh"] = mesh_reference;
  object["units"] = spec.units;
  json keypoints = json::array();
  for (Eigen::Index i = 0; i < spec.keypoints.cols(); ++i) {
    keypoints.push_back({spec.keypoints(0, i), spec.keypoints(1, i), spec.keypoints(2, i)});
  }
  object["keypoints"] = keypoints;
  json names = json::array();
  for (int i = 0; i < spec.num_keypoints(); ++i) {
    names.push_back(spec.keypoint_names.empty() ? std::string() : spec.keypoint_names[i]);
  }
  object["keypoint_names"] = names;
  object["indicator_sets"] = spec.indicator_sets;
  object["eps_oc"] = spec.eps_oc;
  object["delta_nd"] = spec.delta_nd;
  if (!spec.extra_json.empty()) object["extra"] = json::parse(spec.extra_json);
  return object;
}

// JSON safe inside <script>: "</" cannot close the element once written "<\/".
std::string ScriptSafe(std::string text) {
  for (std::size_t at = text.find("</"); at != std::string::npos; at = text.find("</", at + 3)) {
    text.replace(at, 2, "<\\/");
  }
  return text;
}

std::string HtmlEscape(const std::string& text) {
  std::string out;
  for (char c : text) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      default: out += c;
    }
  }
  return out;
}

}  // namespace

std::string AnnotationPageHtml(const ObjectSpec& spec, const Mesh& mesh,
                               const std::string& object_json_path) {
  if (mesh.empty()) throw std::invalid_argument("AnnotationPageHtml: mesh has no triangles");
  mesh.Validate();
  json data;
  data["object"] = ObjectJson(spec, MeshReference(spec, object_json_path));
  data["diameter"] = mesh.Diameter();
  data["vertex_count"] = mesh.vertices.cols();
  data["triangle_count"] = mesh.triangles.cols();
  data["vertices_f32"] = VerticesBase64(mesh);
  data["triangles_u32"] = TrianglesBase64(mesh);

  const std::string three = resources::ThreeJsModule();
  if (three.find("</script") != std::string::npos) {
    throw std::logic_error("embedded three.js contains </script");
  }
  std::string page;
  page += page::Head(HtmlEscape(spec.name));
  page += "<script type=\"text/plain\" id=\"c3po-three\">" + three + "</script>\n";
  page += "<script type=\"application/json\" id=\"c3po-data\">" + ScriptSafe(data.dump()) +
          "</script>\n";
  page += page::AppScript();
  page += "</body>\n</html>\n";
  return page;
}

void WriteAnnotationPage(const ObjectSpec& spec, const Mesh& mesh,
                         const std::string& object_json_path, const std::string& html_path) {
  WriteFileAtomically(html_path, AnnotationPageHtml(spec, mesh, object_json_path));
}

}  // namespace c3po
