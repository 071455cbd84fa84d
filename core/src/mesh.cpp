#include "hila/core/mesh.hpp"

#include <assimp/config.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <assimp/Exporter.hpp>
#include <assimp/Importer.hpp>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <memory>
#include <string_view>

#include "hila/core/error.hpp"
#include "mesh_checks.hpp"

namespace hila::core {

Eigen::Vector3d TriangleMesh::min_corner() const {
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  for (const auto& v : vertices) lo = lo.cwiseMin(v);
  return lo;
}

Eigen::Vector3d TriangleMesh::max_corner() const {
  Eigen::Vector3d hi = Eigen::Vector3d::Constant(-std::numeric_limits<double>::infinity());
  for (const auto& v : vertices) hi = hi.cwiseMax(v);
  return hi;
}

namespace {
void append_node(const aiScene* scene, const aiNode* node, const aiMatrix4x4& parent, double scale,
                 TriangleMesh& out) {
  const aiMatrix4x4 transform = parent * node->mTransformation;
  for (unsigned m = 0; m < node->mNumMeshes; ++m) {
    const aiMesh* mesh = scene->mMeshes[node->mMeshes[m]];
    const int base = static_cast<int>(out.vertices.size());
    for (unsigned i = 0; i < mesh->mNumVertices; ++i) {
      const aiVector3D v = transform * mesh->mVertices[i];
      out.vertices.emplace_back(v.x * scale, v.y * scale, v.z * scale);
    }
    for (unsigned f = 0; f < mesh->mNumFaces; ++f) {
      const aiFace& face = mesh->mFaces[f];
      if (face.mNumIndices != 3) continue;  // points and lines carry no surface
      out.triangles.push_back({base + static_cast<int>(face.mIndices[0]),
                               base + static_cast<int>(face.mIndices[1]),
                               base + static_cast<int>(face.mIndices[2])});
    }
  }
  for (unsigned c = 0; c < node->mNumChildren; ++c) {
    append_node(scene, node->mChildren[c], transform, scale, out);
  }
}

// Whether a line of `text` starts with `word` (after blanks) followed by a blank, a line end or
// the end of the text, as assimp's PLY header reader reads a keyword (not '\v', say).
bool has_line_starting_with(const std::string& text, const std::string& word) {
  for (std::size_t at = text.find(word); at != std::string::npos; at = text.find(word, at + 1)) {
    const std::size_t line = text.find_last_of('\n', at);
    const std::size_t first =
        text.find_first_not_of(" \t", line == std::string::npos ? 0 : line + 1);
    const std::size_t end = at + word.size();
    constexpr std::string_view kAfter(" \t\r\n\f\0", 6);  // what may follow the word
    if (first == at && (end == text.size() || kAfter.find(text[end]) != std::string_view::npos)) {
      return true;
    }
  }
  return false;
}

// assimp 5.2 (Debian 12) reads a PLY header without its closing `end_header` line forever (a
// file cut short in its header; found by fuzz/fuzz_mesh).
void check_ply_header(const std::string& path, const std::string& text) {
  if (!has_line_starting_with(text, "end_header")) {
    throw InputError(path, "(file)", "a PLY header that ends with an end_header line",
                     "no end_header line (a file cut short?)");
  }
}

// assimp 5.2's post-processing aborts the process (an ai_assert in the triangulation) on a mesh
// marked as holding polygons that has none, which its PLY importer writes for a face list with
// an empty face, and reads out of bounds (SIGSEGV) for a face with a corner past the vertices
// (found by fuzz/fuzz_mesh). Both faces are refused here, and each mesh's primitive types are set
// from its faces before the post-processing.
void check_faces(const std::string& path, const aiScene* read) {
  for (unsigned m = 0; m < read->mNumMeshes; ++m) {
    aiMesh* mesh = read->mMeshes[m];  // the importer's scene, not yet post-processed
    unsigned types = 0;
    for (unsigned f = 0; f < mesh->mNumFaces; ++f) {
      const unsigned n = mesh->mFaces[f].mNumIndices;
      const std::string field = "mesh " + std::to_string(m) + " face " + std::to_string(f);
      if (n == 0) throw InputError(path, field, "a face with corners", "an empty face");
      for (unsigned k = 0; k < n; ++k) {
        const unsigned corner = mesh->mFaces[f].mIndices[k];
        if (corner >= mesh->mNumVertices) {
          throw InputError(path, field,
                           "vertex indices below " + std::to_string(mesh->mNumVertices),
                           std::to_string(corner));
        }
      }
      types |= n == 1   ? aiPrimitiveType_POINT
               : n == 2 ? aiPrimitiveType_LINE
               : n == 3 ? aiPrimitiveType_TRIANGLE
                        : aiPrimitiveType_POLYGON;
    }
    if (types != 0) mesh->mPrimitiveTypes = types;  // a mesh without faces keeps its own
  }
}

}  // namespace

TriangleMesh load_mesh(const std::string& path, double unit_scale) {
  if (!(unit_scale > 0.0) || !std::isfinite(unit_scale)) {
    throw InputError(path, "unit scale", "a positive metres-per-unit factor",
                     format_number(unit_scale));
  }
  if (!std::filesystem::exists(path)) {
    throw InputError(path, "(file)", "an existing mesh file", "no such file");
  }
  if (std::filesystem::is_directory(path)) {
    throw InputError(path, "(file)", "a mesh file", "a directory");
  }
  // assimp picks its importer by the extension: only the three formats hila documents, each
  // checked for what assimp 5.2 mishandles (mesh_checks.hpp) before assimp reads it.
  const std::string extension = mesh_checks::checked_extension(path);
  if (extension != ".stl") {
    std::ifstream in(path, std::ios::binary);
    const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    if (extension == ".ply") {
      check_ply_header(path, text);
      mesh_checks::check_ply(path, text);
    } else {
      mesh_checks::check_obj(path, text);
    }
  }
  Assimp::Importer importer;
  // Drop normals, colours and texture coordinates first so that vertices weld by position alone
  // (an STL repeats every corner once per face).
  importer.SetPropertyInteger(AI_CONFIG_PP_RVC_FLAGS,
                              aiComponent_NORMALS | aiComponent_TANGENTS_AND_BITANGENTS |
                                  aiComponent_COLORS | aiComponent_TEXCOORDS);
  const auto refuse_unless = [&](const aiScene* read) {
    if (read == nullptr || read->mRootNode == nullptr) {
      throw InputError(path, "(file)", "a mesh readable by assimp",
                       std::string("'") + importer.GetErrorString() + "'");
    }
  };
  refuse_unless(importer.ReadFile(path, 0));
  check_faces(path, importer.GetScene());
  const aiScene* scene =
      importer.ApplyPostProcessing(aiProcess_RemoveComponent | aiProcess_Triangulate |
                                   aiProcess_JoinIdenticalVertices | aiProcess_SortByPType);
  refuse_unless(scene);
  TriangleMesh mesh;
  append_node(scene, scene->mRootNode, aiMatrix4x4(), unit_scale, mesh);
  if (mesh.triangles.empty()) {
    throw InputError(path, "(mesh)", "at least one triangle", "an empty mesh");
  }
  for (std::size_t i = 0; i < mesh.vertices.size(); ++i) {
    if (!mesh.vertices[i].allFinite()) {
      throw InputError(path, "vertex " + std::to_string(i), "finite coordinates",
                       "NaN or infinite values");
    }
  }
  return mesh;
}

TriangleMesh make_box_mesh(const Eigen::Vector3d& size) {
  TriangleMesh mesh;
  const Eigen::Vector3d h = size / 2.0;
  for (int i = 0; i < 8; ++i) {
    mesh.vertices.emplace_back((i & 1) ? h.x() : -h.x(), (i & 2) ? h.y() : -h.y(),
                               (i & 4) ? h.z() : -h.z());
  }
  // Counter-clockwise seen from outside.
  mesh.triangles = {{0, 2, 1}, {1, 2, 3}, {4, 5, 6}, {5, 7, 6}, {0, 1, 4}, {1, 5, 4},
                    {2, 6, 3}, {3, 6, 7}, {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}};
  return mesh;
}

void write_mesh(const TriangleMesh& mesh, const std::string& path, const std::string& format_id) {
  auto scene = std::make_unique<aiScene>();
  scene->mRootNode = new aiNode();
  scene->mMaterials = new aiMaterial*[1];
  scene->mMaterials[0] = new aiMaterial();
  scene->mNumMaterials = 1;
  scene->mMeshes = new aiMesh*[1];
  scene->mNumMeshes = 1;
  auto* out = new aiMesh();
  scene->mMeshes[0] = out;
  out->mMaterialIndex = 0;
  out->mPrimitiveTypes = aiPrimitiveType_TRIANGLE;
  scene->mRootNode->mMeshes = new unsigned[1]{0};
  scene->mRootNode->mNumMeshes = 1;
  // One vertex triple per face with the face normal, so formats with per-face normals (STL)
  // carry the true outward normal.
  out->mNumFaces = static_cast<unsigned>(mesh.triangles.size());
  out->mNumVertices = 3 * out->mNumFaces;
  out->mVertices = new aiVector3D[out->mNumVertices];
  out->mNormals = new aiVector3D[out->mNumVertices];
  out->mFaces = new aiFace[out->mNumFaces];
  for (unsigned f = 0; f < out->mNumFaces; ++f) {
    const auto& t = mesh.triangles[f];
    const Eigen::Vector3d n = (mesh.vertices[t[1]] - mesh.vertices[t[0]])
                                  .cross(mesh.vertices[t[2]] - mesh.vertices[t[0]])
                                  .normalized();
    out->mFaces[f].mNumIndices = 3;
    out->mFaces[f].mIndices = new unsigned[3];
    for (int k = 0; k < 3; ++k) {
      const auto& v = mesh.vertices[t[k]];
      const unsigned index = 3 * f + static_cast<unsigned>(k);
      out->mVertices[index] = aiVector3D(static_cast<ai_real>(v.x()), static_cast<ai_real>(v.y()),
                                         static_cast<ai_real>(v.z()));
      out->mNormals[index] = aiVector3D(static_cast<ai_real>(n.x()), static_cast<ai_real>(n.y()),
                                        static_cast<ai_real>(n.z()));
      out->mFaces[f].mIndices[k] = index;
    }
  }
  Assimp::Exporter exporter;
  if (exporter.Export(scene.get(), format_id, path) != AI_SUCCESS) {
    throw InputError(path, "(export)", "a writable mesh file of format " + format_id,
                     exporter.GetErrorString());
  }
}

}  // namespace hila::core
