// LoadMesh: PLY, OBJ, OFF and STL with c3po's own readers (mesh_io_internal.hpp),
// any other format assimp knows (glTF, FBX, COLLADA, 3DS, ...) with assimp;
// WriteObj.
#include "c3po/io/mesh_io.hpp"

#include <assimp/BaseImporter.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <algorithm>
#include <assimp/Importer.hpp>
#include <cctype>
#include <filesystem>
#include <fstream>

#include "c3po/base/atomic_file.hpp"
#include "c3po/base/error.hpp"
#include "cloud_io_internal.hpp"
#include "mesh_io_internal.hpp"

namespace c3po {
namespace mesh_detail {

Eigen::Matrix3Xi TriangleCollector::Take() const {
  Eigen::Matrix3Xi triangles(3, static_cast<Eigen::Index>(triangles_.size()));
  for (std::size_t t = 0; t < triangles_.size(); ++t) {
    for (int k = 0; k < 3; ++k) triangles(k, static_cast<Eigen::Index>(t)) = triangles_[t][k];
  }
  return triangles;
}

}  // namespace mesh_detail

namespace {

using mesh_detail::MeshData;
using Parser = MeshData (*)(std::string_view, const std::string&);

// The formats c3po reads itself; assimp must never see them.
struct OwnFormat {
  const char* extension;
  Parser parse;
};
constexpr OwnFormat kOwnFormats[] = {{"ply", mesh_detail::ParsePlyMesh},
                                     {"obj", mesh_detail::ParseObjMesh},
                                     {"off", mesh_detail::ParseOffMesh},
                                     {"stl", mesh_detail::ParseStlMesh}};

std::string LowerExtension(const std::string& path) {
  std::string extension = std::filesystem::path(path).extension().string();
  if (!extension.empty()) extension.erase(0, 1);
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return extension;
}

// A file whose first line is "ply", whatever its name says.
bool StartsLikePly(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  char magic[4] = {};
  in.read(magic, 4);
  return in.gcount() == 4 && std::string_view(magic, 3) == "ply" && (magic[3] == '\n' || magic[3] == '\r');
}

Parser OwnParserFor(const std::string& path) {
  const std::string extension = LowerExtension(path);
  for (const OwnFormat& format : kOwnFormats) {
    if (extension == format.extension) return format.parse;
  }
  return StartsLikePly(path) ? mesh_detail::ParsePlyMesh : nullptr;
}

// The final checks every loader shares; `vertices` are already scaled.
Mesh CheckedMesh(const std::string& path, PointSet vertices, Eigen::Matrix3Xi triangles) {
  if (triangles.cols() == 0) throw InputError(path, "mesh has no triangles");
  Mesh mesh;
  mesh.vertices = std::move(vertices);
  mesh.triangles = std::move(triangles);
  if (!mesh.vertices.allFinite()) throw InputError(path, "mesh has non-finite vertex coordinates");
  if (!(mesh.SurfaceArea() > 0.0)) throw InputError(path, "mesh has zero surface area");
  return mesh;
}

// Keeps the vertices some triangle uses (a stray vertex must not enlarge the
// bounding box, hence the diameter d), renumbered in order of first use.
Mesh LoadOwnFormat(const std::string& path, double scale, Parser parse) {
  MeshData data = parse(ReadFileToString(path), path);
  std::vector<int> new_index(static_cast<std::size_t>(data.vertices.cols()), -1);
  int used = 0;
  for (Eigen::Index t = 0; t < data.triangles.cols(); ++t) {
    for (int k = 0; k < 3; ++k) {
      int& index = new_index[static_cast<std::size_t>(data.triangles(k, t))];
      if (index < 0) index = used++;
      data.triangles(k, t) = index;
    }
  }
  PointSet vertices(3, used);
  for (std::size_t i = 0; i < new_index.size(); ++i) {
    if (new_index[i] >= 0) vertices.col(new_index[i]) = scale * data.vertices.col(static_cast<Eigen::Index>(i));
  }
  return CheckedMesh(path, std::move(vertices), std::move(data.triangles));
}

// Appends one assimp mesh (triangles only; points and lines are skipped).
void AppendAssimpMesh(const aiMesh& source, const aiMatrix4x4& to_root, double scale,
                      std::vector<Eigen::Vector3d>* vertices, std::vector<Eigen::Vector3i>* triangles) {
  // Point and line meshes (split off by aiProcess_SortByPType) must not add
  // their vertices: they would enlarge the bounding box and the diameter.
  if ((source.mPrimitiveTypes & aiPrimitiveType_TRIANGLE) == 0) return;
  const int offset = static_cast<int>(vertices->size());
  for (unsigned i = 0; i < source.mNumVertices; ++i) {
    const aiVector3D v = to_root * source.mVertices[i];
    vertices->emplace_back(scale * v.x, scale * v.y, scale * v.z);
  }
  for (unsigned f = 0; f < source.mNumFaces; ++f) {
    const aiFace& face = source.mFaces[f];
    if (face.mNumIndices != 3) continue;
    triangles->emplace_back(offset + static_cast<int>(face.mIndices[0]),
                            offset + static_cast<int>(face.mIndices[1]),
                            offset + static_cast<int>(face.mIndices[2]));
  }
}

void CollectNode(const aiScene& scene, const aiNode& node, const aiMatrix4x4& parent, double scale,
                 std::vector<Eigen::Vector3d>* vertices, std::vector<Eigen::Vector3i>* triangles, int depth) {
  if (depth > 64) return;  // pathological node nesting
  const aiMatrix4x4 to_root = parent * node.mTransformation;
  for (unsigned m = 0; m < node.mNumMeshes; ++m) {
    if (node.mMeshes[m] < scene.mNumMeshes) {
      AppendAssimpMesh(*scene.mMeshes[node.mMeshes[m]], to_root, scale, vertices, triangles);
    }
  }
  for (unsigned c = 0; c < node.mNumChildren; ++c) {
    CollectNode(scene, *node.mChildren[c], to_root, scale, vertices, triangles, depth + 1);
  }
}

// Only files whose extension assimp claims get to assimp, and its importers
// for c3po's own formats are removed (UnregisterLoader hands the object back),
// so signature detection cannot route any file to them.
void PrepareImporter(const std::string& path, Assimp::Importer* importer) {
  const std::string extension = LowerExtension(path);
  if (extension.empty() || !importer->IsExtensionSupported(extension.c_str())) {
    throw InputError(path, "unknown mesh format '" + extension +
                               "' (expected .ply, .obj, .off, .stl, or a format assimp reads such as .gltf, .glb, .fbx, .dae)");
  }
  for (const OwnFormat& format : kOwnFormats) {
    if (Assimp::BaseImporter* own = importer->GetImporter(format.extension)) {
      if (importer->UnregisterLoader(own) == AI_SUCCESS) delete own;
    }
  }
}

Mesh LoadWithAssimp(const std::string& path, double scale) {
  Assimp::Importer importer;
  PrepareImporter(path, &importer);
  // No normals, no materials: only triangulated geometry with merged vertices.
  const aiScene* scene = importer.ReadFile(
      path, aiProcess_Triangulate | aiProcess_JoinIdenticalVertices | aiProcess_SortByPType |
                aiProcess_ValidateDataStructure);
  if (scene == nullptr || scene->mRootNode == nullptr) {
    std::string reason = importer.GetErrorString();
    std::replace(reason.begin(), reason.end(), '\n', ' ');
    throw InputError(path, "cannot read mesh: " + (reason.empty() ? "unknown format" : reason));
  }
  std::vector<Eigen::Vector3d> vertices;
  std::vector<Eigen::Vector3i> triangles;
  CollectNode(*scene, *scene->mRootNode, aiMatrix4x4(), scale, &vertices, &triangles, 0);
  PointSet vertex_matrix(3, static_cast<Eigen::Index>(vertices.size()));
  for (std::size_t i = 0; i < vertices.size(); ++i) vertex_matrix.col(static_cast<Eigen::Index>(i)) = vertices[i];
  Eigen::Matrix3Xi triangle_matrix(3, static_cast<Eigen::Index>(triangles.size()));
  for (std::size_t i = 0; i < triangles.size(); ++i) triangle_matrix.col(static_cast<Eigen::Index>(i)) = triangles[i];
  return CheckedMesh(path, std::move(vertex_matrix), std::move(triangle_matrix));
}

}  // namespace

Mesh LoadMesh(const std::string& path, double scale) {
  if (!std::filesystem::is_regular_file(path)) throw InputError(path, "mesh file not found");
  if (const Parser parse = OwnParserFor(path)) return LoadOwnFormat(path, scale, parse);
  return LoadWithAssimp(path, scale);
}

void WriteObj(const Mesh& mesh, const std::string& path) {
  WriteFileAtomically(path, [&](std::ostream& out) {
    // Shortest text that reads back to the same double: LoadMesh returns
    // exactly the mesh that was written.
    out << "# written by c3po\n";
    for (int i = 0; i < mesh.vertices.cols(); ++i) {
      out << "v " << cloud_detail::FormatDouble(mesh.vertices(0, i)) << ' '
          << cloud_detail::FormatDouble(mesh.vertices(1, i)) << ' '
          << cloud_detail::FormatDouble(mesh.vertices(2, i)) << '\n';
    }
    for (int t = 0; t < mesh.triangles.cols(); ++t) {
      out << "f " << mesh.triangles(0, t) + 1 << ' ' << mesh.triangles(1, t) + 1 << ' '
          << mesh.triangles(2, t) + 1 << '\n';
    }
  });
}

}  // namespace c3po
