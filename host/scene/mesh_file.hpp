#pragma once
// A mesh file's triangles, read with assimp and checked before anything (Embree, the layouts)
// uses them.
#include <string>

#include "scene_geometry.hpp"

namespace sf::scene {

// Every triangle of every mesh of the file (OBJ, PLY, OFF, STL: anything assimp reads) in one
// TriMesh named after the file's stem, vertices as stored. InputError("mesh '<path>': ...", one
// line) when the path is not a regular file (io::require_regular_file), assimp cannot read it,
// it holds no triangles, a vertex is NaN or infinite, a face names a vertex that is not there,
// or the file asks for more memory than there is.
TriMesh read_mesh_file(const std::string& path);

}  // namespace sf::scene
