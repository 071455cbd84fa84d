#pragma once

#include <string>
#include <vector>

#include "hila/core/cell.hpp"
#include "hila/core/product.hpp"

namespace hila::db {

// Hashes that tie a database to its inputs (meta.cell_hash, meta.product_hash): the build writes
// them and the online planner refuses a database whose inputs changed since.

// SHA-256 of the files' names, sizes and bytes (moving bytes between files changes it). Throws
// core::InputError naming an unreadable file.
std::string hash_files(const std::vector<std::string>& paths);
// The cell file and every URDF it references.
std::string cell_hash(const core::CellSpec& cell);
// The product file and every mesh it references.
std::string product_hash(const core::ProductSpec& product);

}  // namespace hila::db
