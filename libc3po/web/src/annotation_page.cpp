// The self-contained annotation page: its static parts
// (libc3po/web/resources/annotation_page.*), three.js and the data (object +
// mesh as base64 typed arrays) inlined into one HTML file.
#include "c3po/web/annotation_page.hpp"

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <vector>

#include "c3po/base/atomic_file.hpp"
#include "c3po/base/error.hpp"
#include "c3po/base/json.hpp"
#include "embedded_resources.hpp"
#include "three_js.hpp"
#include "web_text.hpp"

namespace c3po {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

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
  return web::Base64(bytes.data(), bytes.size());
}

// Little-endian uint32 vertex indices, three per triangle.
std::string TrianglesBase64(const Mesh& mesh) {
  std::vector<unsigned char> bytes;
  bytes.reserve(static_cast<std::size_t>(mesh.triangles.size()) * 4);
  for (Eigen::Index i = 0; i < mesh.triangles.size(); ++i) {
    const auto index = static_cast<std::uint32_t>(mesh.triangles.data()[i]);
    for (int b = 0; b < 4; ++b) bytes.push_back(static_cast<unsigned char>(index >> (8 * b)));
  }
  return web::Base64(bytes.data(), bytes.size());
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
  object["keypoints"] = PointsToJson(spec.keypoints);
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

  const std::string three = web::ThreeJsForPage();
  std::string page;
  page += R"page(<!doctype html>
<html lang="en">
<head>
<meta charset="utf-8">
<meta name="viewport" content="width=device-width, initial-scale=1">
<link rel="icon" href="data:,">
<title>c3po annotate: )page" + web::HtmlEscape(spec.name) + "</title>\n";
  page += "<style>\n" + resources::AnnotationPageCss() + "</style>\n</head>\n<body>\n";
  page += resources::AnnotationPageBody();
  page += "<script type=\"text/plain\" id=\"c3po-three\">" + three + "</script>\n";
  page += "<script type=\"application/json\" id=\"c3po-data\">" + web::ScriptSafe(data.dump()) +
          "</script>\n";
  page += "<script type=\"module\">\n" + resources::AnnotationPageJs() + "</script>\n";
  page += "</body>\n</html>\n";
  return page;
}

void WriteAnnotationPage(const ObjectSpec& spec, const Mesh& mesh,
                         const std::string& object_json_path, const std::string& html_path) {
  WriteFileAtomically(html_path, AnnotationPageHtml(spec, mesh, object_json_path));
}

}  // namespace c3po
