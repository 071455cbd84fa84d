#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

namespace hila::core {

// Something an arm carries at its flange besides the part: an F/T sensor, a coupling, the
// gripper. The centre of mass is in the flange frame.
struct ToolingMass {
  std::string name;
  double mass = 0.0;                              // kg
  Eigen::Vector3d com = Eigen::Vector3d::Zero();  // m, flange frame
};

// What an arm may carry at its flange (cell file: the arm's `payload`). `rated` is the robot's
// datasheet payload; `allowed` is what hila lets the arm carry (default: `rated`), stated
// separately so that a cell which knowingly runs above the datasheet says so in its file and in
// every report. stated == false: the cell gives no payload, and nothing is checked.
struct PayloadSpec {
  bool stated = false;
  double rated = 0.0;    // kg
  double allowed = 0.0;  // kg, >= rated
  std::vector<ToolingMass> tooling;
  double tooling_mass() const;
};

// How an arm holds the part: in the gripper's jaws, or on the suction tool's cup (the tool in
// the gripper).
enum class CarryMode { kGripper, kSuction };
const char* to_string(CarryMode mode);

// One arm carrying one part one way: the masses at its flange and whether they are within the
// payload.
struct PayloadCheck {
  std::string arm;
  CarryMode mode = CarryMode::kGripper;
  bool stated = false;
  double part = 0.0;     // kg
  double tooling = 0.0;  // kg, the arm's tooling
  double tool = 0.0;     // kg, the suction tool (kSuction only)
  double rated = 0.0;
  double allowed = 0.0;
  double total() const { return part + tooling + tool; }
  bool within_allowed() const { return !stated || total() <= allowed + 1e-9; }
  bool within_rated() const { return !stated || total() <= rated + 1e-9; }
  // "part 2.40 kg + tooling 1.30 kg + suction tool 0.25 kg = 3.95 kg > 3.50 kg allowed at arm
  // 'right' (rated 3.00 kg)"; the comparison reads "<=" when within.
  std::string describe() const;
};

PayloadCheck check_payload(const std::string& arm, const PayloadSpec& payload, double part_mass,
                           CarryMode mode, double suction_tool_mass);

}  // namespace hila::core
