#include <iostream>

#include "commands.hpp"
#include "hila/core/error.hpp"
#include "hila/core/human_model.hpp"
#include "io_checks.hpp"

namespace hila::tools {

namespace {
struct HumanOptions {
  double stature = 1.722;
  std::string sex = "male";
  std::string output;
  bool output_given = false;  // -o was on the command line (perhaps as '')
};

int run_human(const HumanOptions& opt) {
  const bool to_file = opt.output_given && opt.output != "-";
  if (to_file) check_output_path("-o", opt.output, {});
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
  if (!to_file) {
    std::cout << urdf;
    return 0;
  }
  write_file_atomically(opt.output, urdf);
  std::cerr << "wrote " << opt.output << "\n";
  return 0;
}
}  // namespace

void add_human_command(CLI::App& app, Action& action) {
  auto opt = std::make_shared<HumanOptions>();
  auto* human = app.add_subcommand("human", "Generate the URDF of a standing human co-worker");
  human->add_option("--stature", opt->stature, "stature in metres")->capture_default_str();
  human->add_option("--sex", opt->sex, "male or female (shoulder width)")->capture_default_str();
  CLI::Option* output =
      human->add_option("-o,--output", opt->output, "output URDF ('-' or none: stdout)");
  human->callback([opt, output, &action] {
    opt->output_given = output->count() > 0;
    action = [opt] { return run_human(*opt); };
  });
}

}  // namespace hila::tools
