#include "mesh_file.hpp"

#include <assimp/Importer.hpp>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <cstring>
#include <sstream>
#include <stdexcept>

#include "input_file.hpp"
#include "isolated_read.hpp"
#include "io_detail.hpp"
#include "ply_header.hpp"

namespace sf::scene {
namespace {

const char* const kMeshRole = "mesh";
// The longest assimp may take over one file (a mesh of millions of triangles takes seconds): past
// it the file is taken to have sent assimp into a loop.
constexpr int kMeshReadSeconds = 300;

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

TriMesh read_triangles(const std::string& path) {
  Assimp::Importer importer;
  const aiScene* ai = importer.ReadFile(path, 0);
  if (!ai) fail(kMeshRole, path, "not a mesh assimp can read" + io::detail::details_suffix(importer.GetErrorString()));
  check_imported(*const_cast<aiScene*>(ai), path);  // the importer's own scene, before post-processing
  ai = importer.ApplyPostProcessing(aiProcess_Triangulate | aiProcess_JoinIdenticalVertices |
                                    aiProcess_PreTransformVertices | aiProcess_SortByPType);
  if (!ai) fail(kMeshRole, path, "not a mesh assimp can use" + io::detail::details_suffix(importer.GetErrorString()));
  TriMesh mesh;
  for (unsigned m = 0; m < ai->mNumMeshes; ++m)
    if (ai->mMeshes[m]) append_triangles(*ai->mMeshes[m], m, path, mesh);
  if (mesh.triangles.empty()) fail(kMeshRole, path, "it holds no triangles");
  return mesh;
}

// The child's answer: 'M', the vertex and triangle counts (8 bytes each), the vertices (3
// doubles each) and the triangles (3 uint32 each); or 'E' and an InputError's message, or 'X' and
// another exception's.
template <class T>
void append_raw(std::string& out, const T* values, size_t count) {
  out.append(reinterpret_cast<const char*>(values), count * sizeof(T));
}

std::string encode_triangles(const std::string& path) {
  try {
    const TriMesh mesh = read_triangles(path);
    std::string out = "M";
    const uint64_t counts[2] = {mesh.vertices.size(), mesh.triangles.size()};
    append_raw(out, counts, 2);
    for (const Vec3& v : mesh.vertices) {
      const double xyz[3] = {v.x, v.y, v.z};
      append_raw(out, xyz, 3);
    }
    for (const auto& t : mesh.triangles) append_raw(out, t.data(), 3);
    return out;
  } catch (const InputError& e) {
    return std::string("E") + e.what();
  } catch (const std::bad_alloc&) {
    return "E" + std::string(kMeshRole) + " '" + path + "': out of memory while reading it";
  } catch (const std::exception& e) {
    return std::string("X") + e.what();
  }
}

TriMesh decode_triangles(const std::string& answer, const std::string& path) {
  if (!answer.empty() && answer[0] == 'E') throw InputError(answer.substr(1));
  if (!answer.empty() && answer[0] == 'X') throw std::runtime_error(answer.substr(1));
  uint64_t counts[2] = {0, 0};
  if (answer.size() < 17 || answer[0] != 'M') throw std::runtime_error("mesh '" + path + "': a garbled answer");
  std::memcpy(counts, answer.data() + 1, 16);
  if (counts[0] > (answer.size() - 17) / 24 || counts[1] > (answer.size() - 17) / 12 ||
      answer.size() != 17 + counts[0] * 24 + counts[1] * 12)
    throw std::runtime_error("mesh '" + path + "': a garbled answer");
  TriMesh mesh;
  mesh.vertices.resize(counts[0]);
  mesh.triangles.resize(counts[1]);
  const char* at = answer.data() + 17;
  for (Vec3& v : mesh.vertices) {
    double xyz[3];
    std::memcpy(xyz, at, 24);
    at += 24;
    v = {xyz[0], xyz[1], xyz[2]};
  }
  for (auto& t : mesh.triangles) {
    std::memcpy(t.data(), at, 12);
    at += 12;
  }
  return mesh;
}

}  // namespace

TriMesh read_mesh_file(const std::string& path) {
  io::require_regular_file(path, kMeshRole);
  if (looks_like_ply(path)) check_ply_header(path, kMeshRole);
  const IsolatedResult r = run_isolated([&] { return encode_triangles(path); }, kMeshReadSeconds);
  switch (r.kind) {
    case IsolatedResult::Kind::Signalled:
      fail(kMeshRole, path, std::string("assimp crashed reading it (") + ::strsignal(r.signal) + ")");
    case IsolatedResult::Kind::TimedOut:
      fail(kMeshRole, path, "assimp did not finish reading it within " + std::to_string(kMeshReadSeconds) + " s");
    case IsolatedResult::Kind::Failed:
      throw std::runtime_error("mesh '" + path + "': " + r.failure);
    case IsolatedResult::Kind::Done:
      break;
  }
  return io::with_out_of_memory_named(path, kMeshRole, [&] {
    TriMesh mesh = decode_triangles(r.bytes, path);
    mesh.name = std::filesystem::path(path).stem().string();
    return mesh;
  });
}

}  // namespace sf::scene
