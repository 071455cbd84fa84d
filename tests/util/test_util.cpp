#include "util/test_util.hpp"

#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "hila/core/error.hpp"
#include "hila/core/stage_scene.hpp"
#include "hila/core/ur_ik.hpp"

namespace hila::test {

std::string data_path(const std::string& relative) {
  return std::string(HILA_DATA_DIR) + "/" + relative;
}
std::string cell_path() {
  return data_path("cell/cell.yaml");
}
std::string product_path() {
  return data_path("cabinet/product.yaml");
}

std::shared_ptr<const core::Cell> reference_cell() {
  static const std::shared_ptr<const core::Cell> cell = core::Cell::load(cell_path());
  return cell;
}

Eigen::VectorXd arm_pointing_down_at(const core::Cell& cell, const core::Arm& arm,
                                     const Eigen::Vector3d& p) {
  core::Pose tcp = core::Pose::Identity();
  tcp.linear() = Eigen::AngleAxisd(core::kPi, Eigen::Vector3d::UnitX()).toRotationMatrix();
  tcp.translation() = p;
  core::UrIkSolutions ik;
  const int n =
      arm.ur_ik->solve(core::arm_base_in_world(cell, arm).inverse() * tcp, arm.spec.home, ik);
  EXPECT_GT(n, 0) << "no IK at " << p.transpose();
  return n > 0 ? Eigen::VectorXd(ik.q[0]) : arm.spec.home;
}

std::string temp_dir(const std::string& name) {
  // Per process: ctest -j runs a suite's tests as separate processes at once, and one removing
  // the directory another is building in made the latter's suite set-up fail.
  const auto dir =
      std::filesystem::path(HILA_TEST_TMP_DIR) / (name + "-" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir.string();
}

std::string write_file(const std::string& dir, const std::string& name, const std::string& text) {
  const std::string path = (std::filesystem::path(dir) / name).string();
  std::ofstream out(path);
  out << text;
  return path;
}

std::string cell_variant(const std::string& dir, const std::string& from, const std::string& to) {
  std::string cell = read_file(cell_path());
  const auto at = cell.find(from);
  EXPECT_NE(at, std::string::npos) << "cell.yaml no longer contains '" << from << "'";
  if (at != std::string::npos) cell.replace(at, from.size(), to);
  for (const char* f : {"dual_ur3.urdf", "suction_tool.urdf", "human.urdf"}) {
    write_file(dir, f, read_file(data_path(std::string("cell/") + f)));
  }
  return write_file(dir, "cell.yaml", cell);
}

std::string read_file(const std::string& path) {
  std::ifstream in(path);
  std::stringstream buffer;
  buffer << in.rdbuf();
  return buffer.str();
}

Eigen::VectorXd random_within(const core::KinematicChain& chain, std::mt19937_64& rng) {
  Eigen::VectorXd q(chain.dof());
  for (int i = 0; i < chain.dof(); ++i) {
    q[i] = std::uniform_real_distribution<double>(chain.lower_limits()[i],
                                                  chain.upper_limits()[i])(rng);
  }
  return q;
}

core::Pose random_pose(std::mt19937_64& rng, double position_range) {
  std::uniform_real_distribution<double> u(-position_range, position_range);
  std::normal_distribution<double> n(0.0, 1.0);
  Eigen::Quaterniond q(n(rng), n(rng), n(rng), n(rng));
  q.normalize();
  core::Pose pose = core::Pose::Identity();
  pose.linear() = q.toRotationMatrix();
  pose.translation() = Eigen::Vector3d(u(rng), u(rng), u(rng));
  return pose;
}

void expect_input_error(const std::function<void()>& fn,
                        std::initializer_list<std::string> fragments) {
  try {
    fn();
    ADD_FAILURE() << "expected hila::core::InputError, nothing was thrown";
  } catch (const core::InputError& e) {
    const std::string message = e.what();
    for (const auto& fragment : fragments) {
      EXPECT_NE(message.find(fragment), std::string::npos)
          << "message '" << message << "' lacks '" << fragment << "'";
    }
  }
}

// A 49 x 68 x 25 mm L bracket of 2.4 mm steel (tools/dev/gen_products --seed 1, product 16),
// lying on its L face on the left of the table; its target in a corner of a crate in front of
// the human.
std::string bracket_product(const std::string& dir) {
  test::write_file(dir, "bracket.obj", R"(o bracket
v -24.408 -34.080 -12.493
v 24.408 -34.080 -12.493
v 24.408 -31.649 -12.493
v -21.977 -31.649 -12.493
v -21.977 34.080 -12.493
v -24.408 34.080 -12.493
v -24.408 -34.080 12.493
v 24.408 -34.080 12.493
v 24.408 -31.649 12.493
v -21.977 -31.649 12.493
v -21.977 34.080 12.493
v -24.408 34.080 12.493
f 7 8 9
f 3 2 1
f 7 9 10
f 4 3 1
f 12 7 10
f 4 1 6
f 10 11 12
f 6 5 4
f 1 2 8
f 1 8 7
f 2 3 9
f 2 9 8
f 3 4 10
f 3 10 9
f 4 5 11
f 4 11 10
f 5 6 12
f 5 12 11
f 6 1 7
f 6 7 12
)");
  return test::write_file(dir, "product.yaml", R"(name: bracket
assembly_frame: {xyz: [0.658883, -0.031896, 1.094], rpy_deg: [0, 0, 1.849]}
suction_tool_pose: {xyz: [0.30, -0.72, 1.229], rpy_deg: [0, 0, 0]}
parts:
  - name: bracket
    order: 1
    mesh: bracket.obj
    mesh_unit: mm
    mass: 0.0546
    target: {xyz: [-0.052145, -0.133773, 0.05528], rotation: [[0, 0, 1], [1, 0, 0], [0, 1, 0]]}
    initial: {xyz: [0.43, 0.201716, 1.107993], rotation: [[0.052221916, -0.998635505, 0], [0.998635505, 0.052221916, 0], [0, 0, 1]]}
)");
}

CommandRun run_command(const std::string& command) {
  CommandRun r;
  FILE* pipe = popen((command + " 2>&1").c_str(), "r");
  if (pipe == nullptr) return r;
  std::array<char, 4096> buffer{};
  std::size_t n = 0;
  while ((n = fread(buffer.data(), 1, buffer.size(), pipe)) > 0) r.out.append(buffer.data(), n);
  const int raw = pclose(pipe);
  r.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
  return r;
}

}  // namespace hila::test
