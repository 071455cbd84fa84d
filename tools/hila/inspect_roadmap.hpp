#pragma once

#include <string>

#include "hila/db/database.hpp"

namespace hila::tools {

// `hila inspect DB roadmap [--arm A] [--part P] [--json]`: the roadmaps, each board's filters,
// its regrasp graph and whether its goals connect. Returns the exit status.
int inspect_roadmap(const db::Database& database, const std::string& arm, const std::string& part,
                    bool json);

}  // namespace hila::tools
