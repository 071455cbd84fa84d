#include "hila/offline/roadmap.hpp"

#include <ompl/base/PlannerData.h>
#include <ompl/base/PlannerTerminationCondition.h>
#include <ompl/base/ProblemDefinition.h>
#include <ompl/base/SpaceInformation.h>
#include <ompl/base/ValidStateSampler.h>
#include <ompl/base/spaces/RealVectorStateSpace.h>
#include <ompl/datastructures/NearestNeighborsLinear.h>
#include <ompl/geometric/planners/prm/PRM.h>
#include <ompl/util/Console.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <random>
#include <set>

#include "hila/core/collision.hpp"
#include "hila/core/error.hpp"
#include "hila/core/internal/ompl_state.hpp"
#include "hila/core/joint_box.hpp"
#include "hila/core/roadmap_graph.hpp"
#include "hila/core/soft_finger.hpp"
#include "hila/core/stage_scene.hpp"
#include "hila/offline/arm_workspace.hpp"

namespace ob = ompl::base;
namespace og = ompl::geometric;

namespace hila::offline {

namespace {

using core::from_vector;
using core::to_vector;

// Uniform joint-space samples mixed with IK samples of gripper poses whose opening axis is
// near vertical (the slip-constrained region, thin in joint space).
class SlipBiasedSampler : public ob::ValidStateSampler {
 public:
  SlipBiasedSampler(const ob::SpaceInformation* si, const core::Cell& cell, const core::Arm& arm,
                    ArmWorkspace& checker, const RoadmapSettings& settings)
      : ob::ValidStateSampler(si),
        cell_(cell),
        arm_(arm),
        checker_(checker),
        settings_(settings),
        rng_(settings.seed),
        base_(core::arm_base_in_world(cell, arm)) {
    name_ = "slip_biased";
    // Where the TCP goes: a box around the arm's base within its reach, above the table.
    const double reach = 0.55;
    lo_ = base_.translation() - Eigen::Vector3d::Constant(reach);
    hi_ = base_.translation() + Eigen::Vector3d::Constant(reach);
    double table_top = 0.0;
    for (const auto& o : cell.spec().obstacles) {
      table_top = std::max(table_top, o.pose.translation().z() + 0.5 * o.size.z());
    }
    lo_.z() = std::max(lo_.z(), table_top + 0.02);
  }

  bool sample(ob::State* state) override {
    for (int attempt = 0; attempt < 100; ++attempt) {
      Eigen::VectorXd q;
      if (uniform() < settings_.slip_bias) {
        if (!vertical_axis_sample(q)) continue;
      } else {
        q = uniform_joints();
      }
      if (checker_.arm_valid(q)) {
        from_vector(q, state);
        return true;
      }
    }
    return false;
  }
  bool sampleNear(ob::State* state, const ob::State* near, double distance) override {
    const Eigen::VectorXd centre = to_vector(near, arm_.chain.dof());
    std::normal_distribution<double> n(0.0, distance / 2.0);
    for (int attempt = 0; attempt < 100; ++attempt) {
      Eigen::VectorXd q = centre;
      for (Eigen::Index i = 0; i < q.size(); ++i) q[i] += n(rng_);
      if (checker_.arm_valid(q)) {
        from_vector(q, state);
        return true;
      }
    }
    return false;
  }

 private:
  double uniform() { return static_cast<double>(rng_() >> 11) * 0x1.0p-53; }
  Eigen::VectorXd uniform_joints() {
    const Eigen::VectorXd lo = roadmap_lower(arm_, settings_);
    const Eigen::VectorXd hi = roadmap_upper(arm_, settings_);
    Eigen::VectorXd q(lo.size());
    for (Eigen::Index i = 0; i < q.size(); ++i) q[i] = lo[i] + uniform() * (hi[i] - lo[i]);
    return q;
  }
  bool vertical_axis_sample(Eigen::VectorXd& q) {
    // Opening axis within the cone around +-z, any rotation about it, TCP in the box.
    const double cone = core::deg_to_rad(settings_.vertical_cone_deg);
    const double tilt = std::acos(1.0 - uniform() * (1.0 - std::cos(cone)));
    const double azimuth = 2.0 * core::kPi * uniform();
    Eigen::Vector3d axis(std::sin(tilt) * std::cos(azimuth), std::sin(tilt) * std::sin(azimuth),
                         std::cos(tilt));
    if (uniform() < 0.5) axis = -axis;
    const Eigen::Vector3d opening = cell_.spec().gripper.opening_axis.normalized();
    const Eigen::Matrix3d align =
        Eigen::Quaterniond::FromTwoVectors(opening, axis).toRotationMatrix();
    core::Pose tcp = core::Pose::Identity();
    tcp.linear() = Eigen::AngleAxisd(2.0 * core::kPi * uniform(), axis) * align;
    for (int k = 0; k < 3; ++k) tcp.translation()[k] = lo_[k] + uniform() * (hi_[k] - lo_[k]);
    core::UrIkSolutions solutions;
    const int n = arm_.ur_ik->solve(base_.inverse() * tcp, arm_.spec.home, solutions);
    if (n == 0) return false;
    // Mostly the branch nearest home (dense within one branch, so near neighbours connect).
    const auto pick = uniform() < 0.75 ? 0 : rng_() % static_cast<std::uint64_t>(n);
    q = solutions.q[static_cast<std::size_t>(pick)];
    const Eigen::VectorXd lo = roadmap_lower(arm_, settings_);
    const Eigen::VectorXd hi = roadmap_upper(arm_, settings_);
    return (q.array() >= lo.array()).all() && (q.array() <= hi.array()).all();
  }

  const core::Cell& cell_;
  const core::Arm& arm_;
  ArmWorkspace& checker_;
  RoadmapSettings settings_;
  std::mt19937_64 rng_;
  core::Pose base_;
  Eigen::Vector3d lo_, hi_;
};

// PRM with OMPL's exact linear nearest-neighbour structure (deterministic: GNAT's pivots draw
// from OMPL's global RNG). PRM::setup only wires the distance function into a structure it made
// itself, so it is wired here.
class LinearPrm : public og::PRM {
 public:
  explicit LinearPrm(const ob::SpaceInformationPtr& si) : og::PRM(si) {
    setNearestNeighbors<ompl::NearestNeighborsLinear>();
    nn_->setDistanceFunction(
        [this](const Vertex a, const Vertex b) { return distanceFunction(a, b); });
  }
};

}  // namespace

Eigen::VectorXd roadmap_lower(const core::Arm& arm, const RoadmapSettings& settings) {
  return core::joint_box(arm, settings.joint_range).lower;
}

Eigen::VectorXd roadmap_upper(const core::Arm& arm, const RoadmapSettings& settings) {
  return core::joint_box(arm, settings.joint_range).upper;
}

std::vector<Attachment> attach_configuration(ArmWorkspace& workspace, const Roadmap& roadmap,
                                             const GraspSlip& grasp, const Eigen::VectorXd& q,
                                             int k, double resolution) {
  const double step = resolution > 0.0 ? resolution : roadmap.resolution;
  const Eigen::Matrix3d base_rotation = workspace.base().linear();
  const SlipTest holds(grasp);
  auto ok = [&](const Eigen::VectorXd& x) {
    return holds(gravity_in_tcp(workspace.arm(), base_rotation, x)) && workspace.valid(x);
  };
  std::vector<Attachment> out;
  if (!ok(q)) return out;
  std::vector<std::pair<double, int>> near;
  near.reserve(roadmap.nodes.size());
  for (std::size_t i = 0; i < roadmap.nodes.size(); ++i) {
    near.emplace_back((roadmap.nodes[i] - q).norm(), static_cast<int>(i));
  }
  const auto take = std::min<std::size_t>(near.size(), static_cast<std::size_t>(k));
  std::partial_sort(near.begin(), near.begin() + static_cast<std::ptrdiff_t>(take), near.end());
  for (std::size_t j = 0; j < take; ++j) {
    const auto& node = roadmap.nodes[static_cast<std::size_t>(near[j].second)];
    bool free = ok(node);
    for (const auto& x : edge_samples(q, node, step)) {
      if (!free) break;
      free = ok(x);
    }
    if (free) out.push_back({near[j].second, near[j].first});
  }
  return out;
}

SlipTest::SlipTest(const GraspSlip& grasp)
    : normal_(grasp.axis.cross(grasp.lever)),
      limit_(std::sin(core::deg_to_rad(std::min(grasp.theta_c_deg, 90.0))) + 1e-12) {}

std::vector<bool> held_board_filter(ArmWorkspace& workspace, const Roadmap& roadmap,
                                    std::vector<bool> edges) {
  // Node verdicts: -1 unknown, 0 blocked, 1 clear.
  std::vector<signed char> node_clear(roadmap.nodes.size(), -1);
  auto clear_node = [&](int n) {
    auto& v = node_clear[static_cast<std::size_t>(n)];
    if (v < 0) v = workspace.board_clear(roadmap.nodes[static_cast<std::size_t>(n)]) ? 1 : 0;
    return v == 1;
  };
  for (std::size_t e = 0; e < edges.size(); ++e) {
    if (!edges[e]) continue;
    const auto [a, b] = roadmap.edges[e];
    bool ok = clear_node(a) && clear_node(b);
    if (ok) {
      for (const auto& q :
           edge_samples(roadmap.nodes[static_cast<std::size_t>(a)],
                        roadmap.nodes[static_cast<std::size_t>(b)], roadmap.resolution)) {
        if (!workspace.board_clear(q)) {
          ok = false;
          break;
        }
      }
    }
    edges[e] = ok;
  }
  return edges;
}

db::RoadmapRecord to_record(const Roadmap& roadmap) {
  db::RoadmapRecord r;
  r.arm = roadmap.arm;
  r.dof = roadmap.dof;
  r.resolution = roadmap.resolution;
  r.nodes = roadmap.nodes;
  r.node_gravity = roadmap.node_gravity;
  r.node_inclination_deg = roadmap.node_inclination_deg;
  r.edges = roadmap.edges;
  r.edge_length = roadmap.edge_length;
  r.edge_max_inclination_deg = roadmap.edge_max_inclination_deg;
  return r;
}

std::vector<bool> slip_filter(const Roadmap& roadmap, const GraspSlip& grasp) {
  const SlipTest holds(grasp);
  std::vector<bool> node_ok(roadmap.nodes.size());
  for (std::size_t i = 0; i < node_ok.size(); ++i) node_ok[i] = holds(roadmap.node_gravity[i]);
  std::vector<bool> out(roadmap.edges.size(), false);
  for (std::size_t e = 0; e < roadmap.edges.size(); ++e) {
    const auto [a, b] = roadmap.edges[e];
    bool ok = node_ok[static_cast<std::size_t>(a)] && node_ok[static_cast<std::size_t>(b)];
    for (std::size_t k = 0; ok && k < roadmap.edge_gravity[e].size(); ++k) {
      ok = holds(roadmap.edge_gravity[e][k]);
    }
    out[e] = ok;
  }
  return out;
}

std::vector<int> connected_components(const Roadmap& roadmap, const std::vector<bool>& edges) {
  return core::connected_components(static_cast<int>(roadmap.nodes.size()), roadmap.edges, edges);
}

Eigen::Vector3d gravity_in_tcp(const core::Arm& arm, const Eigen::Matrix3d& base_rotation,
                               const Eigen::VectorXd& q) {
  const Eigen::Matrix3d r = base_rotation * arm.chain.fk(q).linear();
  return r.transpose() * Eigen::Vector3d(0.0, 0.0, -1.0);
}

Roadmap build_roadmap(const core::Cell& cell, const std::string& arm_name,
                      const RoadmapSettings& settings,
                      const std::function<void(int milestones)>& progress) {
  const auto start = std::chrono::steady_clock::now();
  const core::Arm& arm = cell.arm(arm_name);
  if (!arm.ur_ik) {
    throw core::InputError(cell.spec().file, "robot.arms." + arm_name + ".kinematics",
                           "UR DH parameters (the roadmap's slip-biased sampler uses the "
                           "analytic IK)",
                           "none");
  }
  const int dof = arm.chain.dof();
  const Eigen::Matrix3d base_rotation = core::arm_base_in_world(cell, arm).linear();
  ompl::msg::setLogLevel(ompl::msg::LOG_WARN);

  auto space = std::make_shared<ob::RealVectorStateSpace>(static_cast<unsigned>(dof));
  ob::RealVectorBounds bounds(static_cast<unsigned>(dof));
  for (int i = 0; i < dof; ++i) {
    bounds.setLow(static_cast<unsigned>(i), roadmap_lower(arm, settings)[i]);
    bounds.setHigh(static_cast<unsigned>(i), roadmap_upper(arm, settings)[i]);
  }
  space->setBounds(bounds);
  auto si = std::make_shared<ob::SpaceInformation>(space);
  ArmWorkspace checker(cell, arm_name, settings.suction_arm);
  si->setStateValidityChecker(
      [&](const ob::State* s) { return checker.arm_valid(to_vector(s, dof)); });
  si->setStateValidityCheckingResolution(settings.resolution / space->getMaximumExtent());
  si->setValidStateSamplerAllocator([&](const ob::SpaceInformation* s) {
    return std::make_shared<SlipBiasedSampler>(s, cell, arm, checker, settings);
  });
  si->setup();

  LinearPrm prm(si);
  prm.setMaxNearestNeighbors(static_cast<unsigned>(settings.neighbours));
  prm.setProblemDefinition(std::make_shared<ob::ProblemDefinition>(si));
  prm.setup();
  unsigned long reported = 0;
  prm.growRoadmap(ob::PlannerTerminationCondition([&] {
    const unsigned long count = prm.milestoneCount();
    if (progress && count >= reported + 250) {
      reported = count - count % 250;
      progress(static_cast<int>(reported));
    }
    return count >= static_cast<unsigned long>(settings.nodes);
  }));

  ob::PlannerData data(si);
  prm.getPlannerData(data);
  Roadmap map;
  map.arm = arm_name;
  map.dof = dof;
  map.resolution = settings.resolution;
  const Eigen::Vector3d opening = cell.spec().gripper.opening_axis.normalized();
  for (unsigned v = 0; v < data.numVertices(); ++v) {
    map.nodes.push_back(to_vector(data.getVertex(v).getState(), dof));
    map.node_gravity.push_back(gravity_in_tcp(arm, base_rotation, map.nodes.back()));
    map.node_inclination_deg.push_back(
        core::axis_inclination_deg(opening, map.node_gravity.back()));
  }
  std::set<std::pair<int, int>> seen;
  for (unsigned v = 0; v < data.numVertices(); ++v) {
    std::vector<unsigned> out;
    data.getEdges(v, out);
    for (const unsigned w : out) {
      const std::pair<int, int> key{static_cast<int>(std::min(v, w)),
                                    static_cast<int>(std::max(v, w))};
      if (key.first == key.second || !seen.insert(key).second) continue;
      const auto& a = map.nodes[static_cast<std::size_t>(key.first)];
      const auto& b = map.nodes[static_cast<std::size_t>(key.second)];
      // Re-checked and annotated at exactly the documented resolution.
      const auto samples = edge_samples(a, b, settings.resolution);
      bool free = true;
      std::vector<Eigen::Vector3d> gravity;
      double worst = std::max(map.node_inclination_deg[static_cast<std::size_t>(key.first)],
                              map.node_inclination_deg[static_cast<std::size_t>(key.second)]);
      for (const auto& q : samples) {
        if (!checker.arm_valid(q)) {
          free = false;
          break;
        }
        gravity.push_back(gravity_in_tcp(arm, base_rotation, q));
        worst = std::max(worst, core::axis_inclination_deg(opening, gravity.back()));
      }
      if (!free) continue;
      map.edges.push_back(key);
      map.edge_length.push_back((b - a).norm());
      map.edge_max_inclination_deg.push_back(worst);
      map.edge_gravity.push_back(std::move(gravity));
    }
  }
  map.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return map;
}

}  // namespace hila::offline
