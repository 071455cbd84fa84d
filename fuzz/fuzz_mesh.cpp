// libFuzzer target: the mesh reader (core::load_mesh: its checks, then assimp). assimp picks its
// importer by the file's extension, so the input's first byte chooses it (byte % 3: .stl, .obj,
// .ply, the three load_mesh reads) and the rest is the file; fuzz/run prefixes the seed meshes
// accordingly.
#include <array>

#include "fuzz_input.hpp"
#include "hila/core/mesh.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static constexpr std::array<const char*, 3> kExtensions = {"stl", "obj", "ply"};
  static const std::string dir = hila::fuzz::work_dir("cabinet", {});
  if (size == 0) return 0;
  const std::string name = std::string("mesh.") + kExtensions[data[0] % kExtensions.size()];
  const std::string path = hila::fuzz::write_input(dir, name, data + 1, size - 1);
  hila::fuzz::expect_input_errors_only([&] { hila::core::load_mesh(path, 0.001); });
  return 0;
}
