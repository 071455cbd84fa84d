#include "hila/core/payload.hpp"

#include <cstdio>

namespace hila::core {

double PayloadSpec::tooling_mass() const {
  double sum = 0.0;
  for (const auto& t : tooling) sum += t.mass;
  return sum;
}

const char* to_string(CarryMode mode) {
  switch (mode) {
    case CarryMode::kGripper:
      return "gripper";
    case CarryMode::kSuction:
      return "suction";
  }
  return "unknown";
}

PayloadCheck check_payload(const std::string& arm, const PayloadSpec& payload, double part_mass,
                           CarryMode mode, double suction_tool_mass) {
  PayloadCheck c;
  c.arm = arm;
  c.mode = mode;
  c.stated = payload.stated;
  c.part = part_mass;
  c.tooling = payload.tooling_mass();
  c.tool = mode == CarryMode::kSuction ? suction_tool_mass : 0.0;
  c.rated = payload.rated;
  c.allowed = payload.allowed;
  return c;
}

std::string PayloadCheck::describe() const {
  if (!stated) return "no payload stated for arm '" + arm + "'";
  char buffer[256];
  std::string text;
  std::snprintf(buffer, sizeof buffer, "part %.2f kg + tooling %.2f kg", part, tooling);
  text = buffer;
  if (mode == CarryMode::kSuction) {
    std::snprintf(buffer, sizeof buffer, " + suction tool %.2f kg", tool);
    text += buffer;
  }
  std::snprintf(buffer, sizeof buffer, " = %.2f kg %s %.2f kg allowed at arm '%s'", total(),
                within_allowed() ? "<=" : ">", allowed, arm.c_str());
  text += buffer;
  if (allowed != rated) {
    std::snprintf(buffer, sizeof buffer, " (rated %.2f kg)", rated);
    text += buffer;
  }
  return text;
}

}  // namespace hila::core
