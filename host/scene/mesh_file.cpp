#include "mesh_file.hpp"

#include <assimp/Importer.hpp>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <cmath>
#include <cstdint>
#include <cctype>
#include <filesystem>
#include <fstream>
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

// The meshes as the importer left them, checked (and their primitive types recounted) before
// assimp's post-processing runs: every vertex finite (post-processing would merge a NaN vertex
// into another one and hide it), every face with vertices that are there. assimp 5.2's
// importers can leave faces without indices and a primitive-type mask that disagrees with the
// faces (a damaged PLY), on which its triangulation aborts the process (an ai_assert).
void check_imported(aiScene& ai, const std::string& path) {
  for (unsigned m = 0; m < ai.mNumMeshes; ++m) {
    aiMesh* src = ai.mMeshes[m];
    if (!src) continue;
    const std::string mesh = " of mesh " + std::to_string(m);
    if (src->mNumVertices > 0 && !src->mVertices) fail(kMeshRole, path, "vertices" + mesh + " missing");
    for (unsigned v = 0; v < src->mNumVertices; ++v) {
      const aiVector3D& p = src->mVertices[v];
      if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
        fail(kMeshRole, path, "vertex " + std::to_string(v) + mesh + " is not finite " + vertex_text(p));
    }
    if (src->mNumFaces > 0 && !src->mFaces) fail(kMeshRole, path, "faces" + mesh + " missing");
    unsigned types = 0;
    for (unsigned f = 0; f < src->mNumFaces; ++f) {
      const aiFace& face = src->mFaces[f];
      if (face.mNumIndices == 0 || !face.mIndices)
        fail(kMeshRole, path, "face " + std::to_string(f) + mesh + " has no vertices");
      for (unsigned k = 0; k < face.mNumIndices; ++k)
        if (face.mIndices[k] >= src->mNumVertices)
          fail(kMeshRole, path,
               "face " + std::to_string(f) + mesh + " names vertex " + std::to_string(face.mIndices[k]) + " of " +
                   std::to_string(src->mNumVertices));
      types |= face.mNumIndices == 1   ? aiPrimitiveType_POINT
               : face.mNumIndices == 2 ? aiPrimitiveType_LINE
               : face.mNumIndices == 3 ? aiPrimitiveType_TRIANGLE
                                       : aiPrimitiveType_POLYGON;
    }
    src->mPrimitiveTypes = types;
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

// assimp 5.2's PLY reader never returns from a header that ends without end_header (a
// truncated or cut file), so such a header is refused before assimp sees it. A file is read as
// PLY when its name ends in .ply or it starts with "ply" (assimp's signature check, any case).
void require_ply_header_end(const std::string& path) {
  constexpr size_t kMaxPlyHeader = size_t(1) << 20;
  std::ifstream in(path, std::ios::binary);
  std::string head(kMaxPlyHeader, '\0');
  in.read(head.data(), std::streamsize(head.size()));
  head.resize(size_t(in.gcount()));
  std::string lower = head.substr(0, 3);
  for (char& c : lower) c = char(std::tolower(static_cast<unsigned char>(c)));
  std::string extension = std::filesystem::path(path).extension().string();
  for (char& c : extension) c = char(std::tolower(static_cast<unsigned char>(c)));
  if (lower != "ply" && extension != ".ply") return;
  if (head.find("end_header") == std::string::npos)
    fail(kMeshRole, path, "a PLY header without end_header in its first " + std::to_string(kMaxPlyHeader) + " bytes");
}

TriMesh read_triangles(const std::string& path) {
  require_ply_header_end(path);
  Assimp::Importer importer;
  const aiScene* ai = importer.ReadFile(path, 0);
  if (!ai) fail(kMeshRole, path, "not a mesh assimp can read" + io::detail::details_suffix(importer.GetErrorString()));
  check_imported(*const_cast<aiScene*>(ai), path);  // the importer's own scene, before post-processing
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
