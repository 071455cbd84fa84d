// libFuzzer target: the cell file (core::Cell::load: the YAML, then the URDFs it names, the
// kinematic chains and the analytic IK). The input is cell.yaml in a folder beside the reference
// cell's URDFs (dual_ur3.urdf, suction_tool.urdf, human.urdf).
#include "fuzz_input.hpp"
#include "hila/core/cell.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const std::string dir = hila::fuzz::work_dir("cell", {".urdf"});
  const std::string path = hila::fuzz::write_input(dir, "cell.yaml", data, size);
  hila::fuzz::expect_input_errors_only([&] { hila::core::Cell::load(path); });
  return 0;
}
