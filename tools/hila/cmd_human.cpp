#include <fstream>
#include <iostream>

#include "commands.hpp"
#include "hila/core/error.hpp"
#include "hila/core/human_model.hpp"

namespace hila::tools {

namespace {
struct HumanOptions {
  double stature = 1.722;
  std::string sex = "male";
  std::string output;
};

int run_human(const HumanOptions& opt) {
  core::HumanBodySpec spec;
  spec.stature = opt.stature;
  if (opt.sex == "male") {
    spec.sex = core::Sex::Male;
  } else if (opt.sex == "female") {
    spec.sex = core::Sex::Female;
  } else {
    throw core::InputError("command line", "--sex", "male or female", "'" + opt.sex + "'");
  }
  const std::string urdf = core::generate_human_urdf(spec);
  if (opt.output.empty() || opt.output == "-") {
    std::cout << urdf;
    return 0;
  }
  // Write beside, then rename: a failed write never leaves a truncated URDF.
  const std::string tmp = opt.output + ".tmp";
  {
    std::ofstream out(tmp);
    if (!out) throw core::InputError(opt.output, "(file)", "a writable path", "cannot open");
    out << urdf;
    if (!out) throw core::InputError(opt.output, "(file)", "a writable path", "write failed");
  }
  if (std::rename(tmp.c_str(), opt.output.c_str()) != 0) {
    std::remove(tmp.c_str());
    throw core::InputError(opt.output, "(file)", "a writable path", "rename failed");
  }
  std::cerr << "wrote " << opt.output << "\n";
  return 0;
}
}  // namespace

void add_human_command(CLI::App& app, Action& action) {
  auto opt = std::make_shared<HumanOptions>();
  auto* human = app.add_subcommand("human", "Generate the URDF of a standing human co-worker");
  human->add_option("--stature", opt->stature, "stature in metres")->capture_default_str();
  human->add_option("--sex", opt->sex, "male or female (shoulder width)")->capture_default_str();
  human->add_option("-o,--output", opt->output, "output URDF ('-' or none: stdout)");
  human->callback([opt, &action] { action = [opt] { return run_human(*opt); }; });
}

}  // namespace hila::tools
