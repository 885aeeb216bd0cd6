#include "mesh_file.hpp"

#include <assimp/Importer.hpp>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <sstream>

#include "input_file.hpp"
#include "io_detail.hpp"

namespace sf::scene {
namespace {

const char* const kMeshRole = "mesh";

using io::detail::fail;

std::string vertex_text(const aiVector3D& v) {
  std::ostringstream text;
  text << "(" << v.x << ", " << v.y << ", " << v.z << ")";
  return text.str();
}

// Every vertex as the file holds it must be finite: checked before post-processing, which would
// merge a NaN vertex into another one (aiProcess_JoinIdenticalVertices) and hide it.
void require_finite_vertices(const aiScene& ai, const std::string& path) {
  for (unsigned m = 0; m < ai.mNumMeshes; ++m) {
    const aiMesh* src = ai.mMeshes[m];
    if (!src) continue;
    for (unsigned v = 0; v < src->mNumVertices; ++v) {
      const aiVector3D& p = src->mVertices[v];
      if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
        fail(kMeshRole, path,
             "vertex " + std::to_string(v) + " of mesh " + std::to_string(m) + " is not finite " + vertex_text(p));
    }
  }
}

// Appends one assimp mesh's triangles; faces of other sizes (points, lines) are skipped.
void append_triangles(const aiMesh& src, unsigned index, const std::string& path, TriMesh& mesh) {
  if (uint64_t(mesh.vertices.size()) + src.mNumVertices > UINT32_MAX)
    fail(kMeshRole, path, "more than 2^32 - 1 vertices");
  const auto base = uint32_t(mesh.vertices.size());
  for (unsigned v = 0; v < src.mNumVertices; ++v)
    mesh.vertices.push_back({src.mVertices[v].x, src.mVertices[v].y, src.mVertices[v].z});
  for (unsigned f = 0; f < src.mNumFaces; ++f) {
    const aiFace& face = src.mFaces[f];
    if (face.mNumIndices != 3) continue;
    for (unsigned k = 0; k < 3; ++k)
      if (face.mIndices[k] >= src.mNumVertices)
        fail(kMeshRole, path,
             "face " + std::to_string(f) + " of mesh " + std::to_string(index) + " names vertex " +
                 std::to_string(face.mIndices[k]) + " of " + std::to_string(src.mNumVertices));
    mesh.triangles.push_back({base + face.mIndices[0], base + face.mIndices[1], base + face.mIndices[2]});
  }
}

TriMesh read_triangles(const std::string& path) {
  Assimp::Importer importer;
  const aiScene* ai = importer.ReadFile(path, 0);
  if (!ai) fail(kMeshRole, path, "not a mesh assimp can read" + io::detail::details_suffix(importer.GetErrorString()));
  require_finite_vertices(*ai, path);
  ai = importer.ApplyPostProcessing(aiProcess_Triangulate | aiProcess_JoinIdenticalVertices |
                                    aiProcess_PreTransformVertices | aiProcess_SortByPType);
  if (!ai) fail(kMeshRole, path, "not a mesh assimp can use" + io::detail::details_suffix(importer.GetErrorString()));
  TriMesh mesh;
  mesh.name = std::filesystem::path(path).stem().string();
  for (unsigned m = 0; m < ai->mNumMeshes; ++m)
    if (ai->mMeshes[m]) append_triangles(*ai->mMeshes[m], m, path, mesh);
  if (mesh.triangles.empty()) fail(kMeshRole, path, "it holds no triangles");
  return mesh;
}

}  // namespace

TriMesh read_mesh_file(const std::string& path) {
  io::require_regular_file(path, kMeshRole);
  return io::with_out_of_memory_named(path, kMeshRole, [&] { return read_triangles(path); });
}

}  // namespace sf::scene
