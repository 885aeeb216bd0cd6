#pragma once
// A mesh file's triangles, read with assimp and checked before anything (Embree, the layouts)
// uses them.
#include <string>

#include "scene_geometry.hpp"

namespace sf::scene {

// Every triangle of every mesh of the file (OBJ, PLY, OFF, STL: anything assimp reads) in one
// TriMesh named after the file's stem, vertices as stored. InputError("mesh '<path>': ...", one
// line) when the path is not a regular file (io::require_regular_file), a PLY header is not
// well formed (ply_header.hpp), assimp cannot read it, it holds no triangles, a vertex is NaN or
// infinite, a face has no vertices or names one that is not there, or the file asks for more
// memory than there is. assimp 5.2 crashes, aborts or loops on some damaged files, so it runs in
// a child process (isolated_read.hpp): a crash is an InputError naming the signal, and so is a
// read that takes more than 300 s.
TriMesh read_mesh_file(const std::string& path);

}  // namespace sf::scene
