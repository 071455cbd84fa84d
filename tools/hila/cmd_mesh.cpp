#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <iostream>

#include "commands.hpp"
#include "hila/core/error.hpp"
#include "hila/core/mesh.hpp"
#include "hila/core/product.hpp"
#include "io_checks.hpp"
#include "option_checks.hpp"

namespace hila::tools {

namespace {
struct MeshBoxOptions {
  std::vector<double> size;
  std::string unit = "m";
  std::string output;
};

// Sizes a box may have, in its unit: the file stores single-precision floats, and a box smaller
// or larger than this is a typo.
constexpr double kMinBoxSize = 1e-6;
constexpr double kMaxBoxSize = 1e6;

// assimp's export format for the output's extension (the OBJ without a material file).
std::string mesh_format(const std::string& output) {
  std::string ext = std::filesystem::path(output).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (ext == ".stl") return "stl";
  if (ext == ".obj") return "objnomtl";
  if (ext == ".ply") return "ply";
  throw core::InputError("-o: expected a file name whose extension names a mesh format (.stl, "
                         ".obj, .ply), got '" +
                         output + "'");
}

int run_mesh_box(const MeshBoxOptions& opt) {
  check_output_path("-o", opt.output, {});
  const std::string format = mesh_format(opt.output);
  // Sizes are given in `unit`; the file is written in the same unit.
  core::unit_scale_from_name(opt.unit, "command line", "--unit");
  const auto mesh = core::make_box_mesh({opt.size[0], opt.size[1], opt.size[2]});
  write_atomically(opt.output,
                   [&](const std::string& temporary) { core::write_mesh(mesh, temporary, format); });
  std::cerr << "wrote " << opt.output << "\n";
  return 0;
}
}  // namespace

void add_mesh_command(CLI::App& app, Action& action) {
  auto* mesh = app.add_subcommand("mesh", "Write simple part meshes");
  mesh->require_subcommand(1);
  auto opt = std::make_shared<MeshBoxOptions>();
  auto* box =
      mesh->add_subcommand("box", "A box centred at the origin (x length, y width, z thickness)");
  box->add_option("--size", opt->size, "x y z side lengths")
      ->expected(3)
      ->required()
      ->check(number_in(kMinBoxSize, kMaxBoxSize, false, "a length"));
  box->add_option("--unit", opt->unit, "unit of the sizes and the file (m, cm, mm, in)")
      ->capture_default_str();
  box->add_option("-o,--output", opt->output, "output file (.stl, .obj, .ply)")->required();
  box->callback([opt, &action] { action = [opt] { return run_mesh_box(*opt); }; });
}

}  // namespace hila::tools
