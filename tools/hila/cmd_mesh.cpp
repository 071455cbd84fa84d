#include <iostream>

#include "commands.hpp"
#include "hila/core/error.hpp"
#include "hila/core/mesh.hpp"
#include "hila/core/product.hpp"

namespace hila::tools {

namespace {
struct MeshBoxOptions {
  std::vector<double> size;
  std::string unit = "m";
  std::string output;
};

int run_mesh_box(const MeshBoxOptions& opt) {
  for (double s : opt.size) {
    if (!(s > 0) || !std::isfinite(s)) {
      throw core::InputError("command line", "--size", "three positive lengths",
                             core::format_number(s));
    }
  }
  // Sizes are given in `unit`; the file is written in the same unit.
  core::unit_scale_from_name(opt.unit, "command line", "--unit");
  const auto mesh = core::make_box_mesh({opt.size[0], opt.size[1], opt.size[2]});
  const std::string ext = opt.output.substr(opt.output.find_last_of('.') + 1);
  core::write_mesh(mesh, opt.output, ext == "stl" ? "stl" : ext);
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
  box->add_option("--size", opt->size, "x y z side lengths")->expected(3)->required();
  box->add_option("--unit", opt->unit, "unit of the sizes and the file (m, cm, mm, in)")
      ->capture_default_str();
  box->add_option("-o,--output", opt->output, "output file (.stl, .obj, .ply)")->required();
  box->callback([opt, &action] { action = [opt] { return run_mesh_box(*opt); }; });
}

}  // namespace hila::tools
