#pragma once

#include <string>
#include <string_view>

// Checks load_mesh makes on a mesh file's bytes before assimp 5.2 (Debian 12) reads it: inputs
// that make assimp hang, abort, allocate without bound or write past its own arrays are refused
// with an InputError. These check the file's structure against what assimp will do with it; they
// are not a reader (assimp still reads every mesh). Found by fuzz/fuzz_mesh (docs/fuzzing.md).
namespace hila::core::mesh_checks {

// The file's extension in lower case (".stl"); throws InputError unless it is .stl, .obj or
// .ply, the formats hila documents and checks (assimp would pick any of its ~40 importers).
std::string checked_extension(const std::string& path);

// A PLY file: a header of known lines ending with an end_header line, each element's records
// within the file (ASCII: one line each, its values matching the property types, each list as
// long as its count; binary: each record and list inside the file's bytes).
void check_ply(const std::string& path, std::string_view text);

// An OBJ file: every line statement ('l') names at least two corners (assimp writes past its
// vertex array after two one-corner lines).
void check_obj(const std::string& path, std::string_view text);

}  // namespace hila::core::mesh_checks
