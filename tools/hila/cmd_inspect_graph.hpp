#pragma once

#include <string>

#include "hila/db/database.hpp"

namespace hila::tools {

// `hila inspect DB graph --part P [--goals N] [--json]`: the part's manipulation graph as the
// database holds it, the ways the part can reach the human (direct pick by one arm, or exchange
// from the suction arm to the other), with the regrasp graph's stored edges where it has them.
// Text lists the first `goals` goals; JSON always holds the whole graph. Returns the exit status.
int inspect_graph(const db::Database& database, const std::string& part, int goals, bool json);

}  // namespace hila::tools
