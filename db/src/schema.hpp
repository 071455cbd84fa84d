#pragma once

#include <array>
#include <string>

namespace hila::db::detail {

// CREATE statements of the current schema (tables and indexes; meta rows are the writer's job).
const std::string& schema_sql();

// Every table in a fixed order: the content digest hashes them in this order.
inline constexpr std::array<const char*, 6> kTables = {
    "meta", "parts", "placements", "robot_grasps", "suction_grasps", "human_grasps"};

// The meta keys every database carries.
inline constexpr std::array<const char*, 10> kMetaKeys = {
    "schema_version", "hila_version", "product_name", "cell_hash", "product_hash",
    "settings_hash",  "seed",         "created_at",   "cell_file", "product_file"};

// Column lists of a pose ("p_x, p_y, p_z, p_qw, p_qx, p_qy, p_qz") and a vector ("v_x, v_y, v_z").
std::string pose_columns(const std::string& prefix);
std::string vector_columns(const std::string& prefix);

}  // namespace hila::db::detail
