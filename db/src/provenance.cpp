#include "hila/db/provenance.hpp"

#include <fstream>
#include <sstream>

#include "hila/core/error.hpp"
#include "hila/db/database.hpp"

namespace hila::db {

namespace {

std::string file_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw core::InputError(path, "(file)", "a readable file", "cannot open");
  std::stringstream buffer;
  buffer << in.rdbuf();
  return buffer.str();
}

}  // namespace

std::string hash_files(const std::vector<std::string>& paths) {
  std::string all;
  for (const auto& p : paths) {
    const std::string bytes = file_bytes(p);
    all += p.substr(p.find_last_of('/') + 1) + '\0' + std::to_string(bytes.size()) + '\0' + bytes;
  }
  return sha256_hex(all);
}

std::string cell_hash(const core::CellSpec& cell) {
  return hash_files({cell.file, cell.robot_urdf, cell.suction.tool_urdf, cell.human_urdf});
}

std::string product_hash(const core::ProductSpec& product) {
  std::vector<std::string> files{product.file};
  for (const auto& p : product.parts) files.push_back(p.mesh_file);
  return hash_files(files);
}

}  // namespace hila::db
