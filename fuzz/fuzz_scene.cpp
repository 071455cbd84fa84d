// libFuzzer target: the scene file (online::read_scene_files, then online::load_scene against the
// reference cell and the cabinet, loaded once). The input is scene.yaml in a folder beside the
// cabinet's meshes, which its obstacles may name.
#include "fuzz_input.hpp"
#include "hila/online/scene.hpp"

namespace {

const std::string kData = HILA_DATA_DIR;

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  namespace core = hila::core;
  static const auto cell = core::Cell::load(kData + "/cell/cell.yaml");
  static const core::ProductSpec product = core::load_product(kData + "/cabinet/product.yaml");
  static const std::string dir = hila::fuzz::work_dir("cabinet", {".stl"});
  const std::string path = hila::fuzz::write_input(dir, "scene.yaml", data, size);
  hila::fuzz::expect_input_errors_only([&] { hila::online::read_scene_files(path); });
  hila::fuzz::expect_input_errors_only([&] { hila::online::load_scene(path, *cell, product); });
  return 0;
}
