#pragma once
// Mesh files: LoadMesh (c3po's own PLY/OBJ/OFF/STL readers, assimp for the
// rest) and WriteObj.
#include <string>

#include "c3po/geometry/mesh.hpp"

namespace c3po {

// Loads a triangle mesh (PLY, OBJ, OFF and STL with c3po's own readers, every
// other format -- glTF, FBX, COLLADA, 3DS, ... -- with assimp), merges all its meshes, drops
// vertices no triangle uses and scales coordinates by `scale` (e.g. 0.001 for
// a mesh in millimetres). Throws InputError("path: ...") when the file is
// missing, unreadable or has no triangles.
Mesh LoadMesh(const std::string& path, double scale = 1.0);

// Writes a Wavefront OBJ atomically.
void WriteObj(const Mesh& mesh, const std::string& path);

}  // namespace c3po
