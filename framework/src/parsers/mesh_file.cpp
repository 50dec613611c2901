// Mesh files (STL, OBJ, COLLADA, ... through Assimp): found by the URI a robot description names, read for their
// vertices (MeshData) or their triangles (DrawMesh).

#include "redres/parsers/mesh_file.hpp"

#include "common/input_file.hpp"

#include <cstdlib>
#include <sstream>
#include <stdexcept>

#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <assimp/Importer.hpp>

namespace redres {

std::vector<std::filesystem::path> PackagePaths::from_environment() {
  std::vector<std::filesystem::path> dirs;
  for (const char* var : {"REDRES_PACKAGE_PATH", "ROS_PACKAGE_PATH"}) {
    const char* value = std::getenv(var);
    if (value == nullptr) continue;
    std::stringstream in(value);
    std::string item;
    while (std::getline(in, item, ':')) {
      if (!item.empty()) dirs.emplace_back(item);
    }
  }
  return dirs;
}

std::filesystem::path resolve_mesh(const std::string& uri, const std::filesystem::path& base_dir,
                                   const PackagePaths& packages) {
  namespace fs = std::filesystem;
  const std::string package = "package://", file = "file://";
  std::vector<fs::path> tried;
  const auto found = [&tried](const fs::path& p) {
    tried.push_back(p);
    std::error_code ec;
    return fs::is_regular_file(p, ec);
  };
  if (uri.rfind(package, 0) == 0) {
    const std::string rest = uri.substr(package.size());
    const auto slash = rest.find('/');
    if (slash == std::string::npos || slash == 0) {
      throw std::runtime_error("mesh '" + uri + "': expected package://NAME/path");
    }
    const std::string name = rest.substr(0, slash), inside = rest.substr(slash + 1);
    if (const auto it = packages.named.find(name); it != packages.named.end()) {
      if (found(it->second / inside)) return tried.back();
    }
    for (const fs::path& dir : PackagePaths::from_environment()) {
      if (found(dir / name / inside)) return tried.back();
    }
    if (found(base_dir / name / inside)) return tried.back();
  } else if (uri.rfind(file, 0) == 0) {
    if (found(fs::path(uri.substr(file.size())))) return tried.back();
  } else {
    const fs::path p(uri);
    if (found(p.is_absolute() ? p : base_dir / p)) return tried.back();
  }
  std::string where;
  for (const fs::path& p : tried) where += (where.empty() ? "" : ", ") + p.string();
  throw std::runtime_error("mesh '" + uri + "' not found (looked at " + where +
                           "; a package's directory can be given in the robot file's `packages` table or "
                           "REDRES_PACKAGE_PATH)");
}

namespace {

void collect(const aiScene& scene, const aiNode& node, const aiMatrix4x4& parent, const Eigen::Vector3d& scale,
             MeshData& out, int depth) {
  if (depth > 64) throw std::runtime_error("mesh '" + out.file.string() + "': its scene is nested too deeply");
  const aiMatrix4x4 at = parent * node.mTransformation;
  // One piece per node (an OBJ's object or group): its meshes, which Assimp splits by material, together.
  std::vector<Eigen::Vector3d> piece;
  for (unsigned k = 0; k < node.mNumMeshes; ++k) {
    const aiMesh& mesh = *scene.mMeshes[node.mMeshes[k]];
    piece.reserve(piece.size() + mesh.mNumVertices);
    for (unsigned v = 0; v < mesh.mNumVertices; ++v) {
      const aiVector3D p = at * mesh.mVertices[v];
      const Eigen::Vector3d q(scale.x() * static_cast<double>(p.x), scale.y() * static_cast<double>(p.y),
                              scale.z() * static_cast<double>(p.z));
      if (!q.allFinite()) throw std::runtime_error("mesh '" + out.file.string() + "': a vertex is not finite");
      piece.push_back(q);
    }
  }
  if (!piece.empty()) out.pieces.push_back(std::move(piece));
  for (unsigned c = 0; c < node.mNumChildren; ++c) collect(scene, *node.mChildren[c], at, scale, out, depth + 1);
}

// The scene of a mesh file, read by `importer` with Assimp's post-processing `flags`: the file is read within the
// input bounds (a regular file of at most 16 MiB, common/input_file.hpp), then parsed from memory with the
// extension as the format's hint, so that a device or a huge file named by a URDF is refused before Assimp sees it.
const aiScene& import_scene(const std::filesystem::path& file, const Eigen::Vector3d& scale, unsigned flags,
                            Assimp::Importer& importer) {
  if (!scale.allFinite() || (scale.array() <= 0.0).any()) {
    throw std::runtime_error("mesh '" + file.string() + "': expected a scale > 0 on every axis");
  }
  const std::string data = read_input_file(file, "mesh file");
  std::string hint = file.extension().string();
  if (!hint.empty()) hint.erase(0, 1);
  const aiScene* scene = importer.ReadFileFromMemory(data.data(), data.size(), flags, hint.c_str());
  if (scene == nullptr || scene->mRootNode == nullptr) {
    throw std::runtime_error("mesh '" + file.string() + "': Assimp could not read it: " + importer.GetErrorString());
  }
  return *scene;
}

}  // namespace

MeshData read_mesh(const std::filesystem::path& file, const Eigen::Vector3d& scale) {
  Assimp::Importer importer;
  const aiScene& scene = import_scene(file, scale, aiProcess_JoinIdenticalVertices, importer);
  MeshData out;
  out.file = file;
  collect(scene, *scene.mRootNode, aiMatrix4x4(), scale, out, 0);
  if (out.pieces.empty()) throw std::runtime_error("mesh '" + file.string() + "' holds no vertex");
  return out;
}

DrawMesh read_draw_mesh(const std::filesystem::path& file, const Eigen::Vector3d& scale) {
  Assimp::Importer importer;
  // The node transforms baked into the vertices, the meshes of one material merged: one part per colour.
  const aiScene& read = import_scene(
      file, scale,
      aiProcess_Triangulate | aiProcess_JoinIdenticalVertices | aiProcess_PreTransformVertices | aiProcess_SortByPType,
      importer);
  const aiScene* scene = &read;
  DrawMesh out;
  std::vector<int> part_of_material(scene->mNumMaterials + 1, -1);
  for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
    const aiMesh& mesh = *scene->mMeshes[m];
    if ((mesh.mPrimitiveTypes & aiPrimitiveType_TRIANGLE) == 0 || mesh.mNumVertices == 0) continue;
    const unsigned material = std::min(mesh.mMaterialIndex, scene->mNumMaterials);
    if (part_of_material[material] < 0) {
      part_of_material[material] = static_cast<int>(out.parts.size());
      DrawMesh::Part part;
      aiColor4D diffuse;
      if (material < scene->mNumMaterials &&
          scene->mMaterials[material]->Get(AI_MATKEY_COLOR_DIFFUSE, diffuse) == aiReturn_SUCCESS) {
        part.colour = {std::clamp(diffuse.r, 0.0F, 1.0F), std::clamp(diffuse.g, 0.0F, 1.0F),
                       std::clamp(diffuse.b, 0.0F, 1.0F)};
        part.coloured = true;
      }
      out.parts.push_back(std::move(part));
    }
    DrawMesh::Part& part = out.parts[static_cast<std::size_t>(part_of_material[material])];
    const auto first = static_cast<std::uint32_t>(part.positions.size() / 3);
    for (unsigned v = 0; v < mesh.mNumVertices; ++v) {
      const aiVector3D& p = mesh.mVertices[v];
      part.positions.push_back(static_cast<float>(static_cast<double>(p.x) * scale.x()));
      part.positions.push_back(static_cast<float>(static_cast<double>(p.y) * scale.y()));
      part.positions.push_back(static_cast<float>(static_cast<double>(p.z) * scale.z()));
    }
    for (unsigned f = 0; f < mesh.mNumFaces; ++f) {
      const aiFace& face = mesh.mFaces[f];
      if (face.mNumIndices != 3) continue;
      for (unsigned k = 0; k < 3; ++k) part.indices.push_back(first + face.mIndices[k]);
    }
  }
  std::erase_if(out.parts, [](const DrawMesh::Part& p) { return p.indices.empty(); });
  if (out.parts.empty()) throw std::runtime_error("mesh '" + file.string() + "' holds no triangle");
  return out;
}

}  // namespace redres
