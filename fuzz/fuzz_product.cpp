// libFuzzer target: the product file (core::load_product). The input is product.yaml in a folder
// beside the cabinet's meshes (shelf.stl, lateral.stl, back_panel.stl), so that the fuzzer's
// products can load real parts.
#include "fuzz_input.hpp"
#include "hila/core/product.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const std::string dir = hila::fuzz::work_dir("cabinet", {".stl"});
  const std::string path = hila::fuzz::write_input(dir, "product.yaml", data, size);
  hila::fuzz::expect_input_errors_only([&] { hila::core::load_product(path); });
  return 0;
}
