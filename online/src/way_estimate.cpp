// A way's estimated robot time before it is planned: what BoardPlanner orders a goal's ways by.

#include <limits>

#include "hila/core/time_parameterization.hpp"
#include "plan_run.hpp"

namespace hila::online::detail {

namespace {

// A way whose estimate cannot be made (its record names an arm or pose the run does not have, or
// the tool it needs is out of the suction arm's reach): tried after every way that has one, where
// its chain says why it fails.
constexpr double kNoEstimate = std::numeric_limits<double>::infinity();

}  // namespace

double Run::straight_seconds(const core::Arm& arm, const Eigen::VectorXd& from,
                             const Eigen::VectorXd& to) const {
  if (from.size() != to.size() || from.size() == 0) return kNoEstimate;  // a malformed record
  return core::rest_to_rest_duration({from, to}, arm.spec.max_velocity, arm.spec.max_acceleration,
                                     settings_.speed_scale);
}

double Run::stored_seconds(const core::Arm& arm, const db::RegraspEdgeRecord* edge,
                           double otherwise) const {
  if (edge == nullptr) return otherwise;
  if (edge->duration > 0.0) return edge->duration;
  return core::rest_to_rest_duration(edge->path, arm.spec.max_velocity, arm.spec.max_acceleration,
                                     settings_.speed_scale);
}

const Run::EstimateIndex& Run::estimate_index() {
  if (estimate_index_) return *estimate_index_;
  EstimateIndex& index = estimate_index_.emplace();
  for (const auto& [id, n] : node_by_id_) {
    if (n->kind == "pick" && n->grasp_kind == "suction" && !n->solutions.empty()) {
      index.suction_pick.try_emplace({n->arm, n->grasp_id}, &n->solutions.front());
    }
  }
  for (const auto& e : edges_) {
    const auto* from = node(e.from_node);
    const auto* to = node(e.to_node);
    if (from == nullptr || to == nullptr) continue;
    if (e.kind == "transfer" && e.arm == suction_.spec.name && from->kind == "pick" &&
        to->kind == "robot_handover") {
      index.exchange_examined.insert(to->robot_handover_id);
    }
    if (!e.connected || e.path.size() < 2) continue;
    if (e.kind == "transit" && from->kind == "home" && to->kind == "robot_handover") {
      index.way_in.try_emplace({to->robot_handover_id, to->grasp_id}, &e);
    } else if (e.kind == "transfer" && from->kind == "pick" && to->kind == "robot_handover") {
      index.to_exchange.try_emplace({to->robot_handover_id, from->grasp_id}, &e);
    } else if (e.kind == "transfer" && e.arm == receiving_.spec.name &&
               from->kind == "robot_handover" && to->kind == "human_handover") {
      index.to_human.try_emplace({from->robot_handover_id, to->grasp_id, to->candidate_id}, &e);
    } else if (e.kind == "transfer" && from->kind == "pick" && to->kind == "human_handover") {
      index.on_cup.try_emplace({e.arm, to->grasp_id, to->candidate_id}, &e);
    }
  }
  return index;
}

double Run::tool_seconds() {
  if (tool_seconds_) return *tool_seconds_;
  const core::Pose tcp = scene_.tool * cell_.spec().suction.handle_in_tcp.inverse();
  const auto at = solutions(cell_, suction_, tcp, suction_.spec.home);
  tool_seconds_ =
      at.empty() ? kNoEstimate : 2.0 * straight_seconds(suction_, suction_.spec.home, at.front());
  return *tool_seconds_;
}

Eigen::VectorXd Run::start_joints(const core::Arm& arm) const {
  return cell_.arm_joints(start_.robot_q, arm);
}

double Run::estimate(const db::HandoverCandidateRecord& /*goal*/,
                     const db::DirectGraspRecord& direct) {
  const core::Arm* arm = arm_named(direct.arm);
  if (arm == nullptr) return kNoEstimate;
  // The suction arm sets the tool down first, from home.
  const bool tool_down = arm == &suction_ && start_.tool_in_hand;
  const Eigen::VectorXd from = tool_down ? arm->spec.home : start_joints(*arm);
  return (tool_down ? tool_seconds() : 0.0) + straight_seconds(*arm, from, direct.joints_pick) +
         straight_seconds(*arm, direct.joints_pick, direct.joints_rh) +
         straight_seconds(*arm, direct.joints_rh, arm->spec.home);
}

double Run::estimate(const db::HandoverCandidateRecord& /*goal*/,
                     const db::TableRegraspRecord& regrasp) {
  const core::Arm* picker = arm_named(regrasp.arm);
  const core::Arm* repicker = arm_named(regrasp.repick_arm);
  if (picker == nullptr || repicker == nullptr) return kNoEstimate;
  const bool tool_down = (picker == &suction_ || repicker == &suction_) && start_.tool_in_hand;
  auto from = [&](const core::Arm& arm) {
    return tool_down && &arm == &suction_ ? arm.spec.home : start_joints(arm);
  };
  double t = (tool_down ? tool_seconds() : 0.0) +
             straight_seconds(*picker, from(*picker), regrasp.joints_pick) +
             straight_seconds(*picker, regrasp.joints_pick, regrasp.joints_place);
  if (picker == repicker) {  // the same arm lets go and takes it again
    t += straight_seconds(*picker, regrasp.joints_place, regrasp.joints_repick);
  } else {  // a relay: the first arm goes home, the other comes
    t += straight_seconds(*picker, regrasp.joints_place, picker->spec.home) +
         straight_seconds(*repicker, from(*repicker), regrasp.joints_repick);
  }
  return t + straight_seconds(*repicker, regrasp.joints_repick, regrasp.joints_rh) +
         straight_seconds(*repicker, regrasp.joints_rh, repicker->spec.home);
}

double Run::estimate(const db::HandoverCandidateRecord& goal,
                     const db::SuctionDeliveryRecord& delivery) {
  const core::Arm* arm = arm_named(delivery.arm);
  if (arm == nullptr) return kNoEstimate;
  const bool tool_up = arm == &suction_ && !start_.tool_in_hand;
  const Eigen::VectorXd from = tool_up ? arm->spec.home : start_joints(*arm);
  double t = tool_up ? tool_seconds() : 0.0;
  const EstimateIndex& index = estimate_index();
  const auto pick = index.suction_pick.find({arm->spec.name, delivery.suction_grasp_id});
  if (pick == index.suction_pick.end()) {
    t += straight_seconds(*arm, from, delivery.joints_rh);
  } else {
    const auto stored = index.on_cup.find({arm->spec.name, delivery.suction_grasp_id, goal.id});
    t += straight_seconds(*arm, from, *pick->second) +
         stored_seconds(*arm, stored == index.on_cup.end() ? nullptr : stored->second,
                        straight_seconds(*arm, *pick->second, delivery.joints_rh));
  }
  return t + straight_seconds(*arm, delivery.joints_rh, arm->spec.home);
}

double Run::estimate(const db::HandoverCandidateRecord& goal, const db::SharedGraspRecord& shared) {
  const auto rr_it = handovers_.find(shared.robot_handover_id);
  if (rr_it == handovers_.end()) return kNoEstimate;
  const db::RobotHandoverRecord& rr = rr_it->second;
  // The suction arm: the tool where it is not in hand, the pick, the transfer to the exchange,
  // home once the other arm holds the board.
  const bool tool_up = !start_.tool_in_hand;
  const Eigen::VectorXd from = tool_up ? suction_.spec.home : start_joints(suction_);
  double t = tool_up ? tool_seconds() : 0.0;
  const std::int64_t cup = suction_grasp_of(rr);
  const EstimateIndex& index = estimate_index();
  auto stored = [](const auto& map, const auto& key) -> const db::RegraspEdgeRecord* {
    const auto it = map.find(key);
    return it == map.end() ? nullptr : it->second;
  };
  const auto pick = index.suction_pick.find({suction_.spec.name, cup});
  if (pick == index.suction_pick.end()) {
    t += straight_seconds(suction_, from, rr.joints);
  } else {
    t += straight_seconds(suction_, from, *pick->second) +
         stored_seconds(suction_, stored(index.to_exchange, std::make_pair(rr.id, cup)),
                        straight_seconds(suction_, *pick->second, rr.joints));
  }
  t += straight_seconds(suction_, rr.joints, suction_.spec.home);
  // The receiving arm: in to the exchange, the transfer to the human, home.
  const auto at = std::make_pair(rr.id, shared.robot_grasp_id);
  return t +
         stored_seconds(receiving_, stored(index.way_in, at),
                        straight_seconds(receiving_, start_joints(receiving_), shared.joints_rr)) +
         stored_seconds(
             receiving_,
             stored(index.to_human, std::make_tuple(rr.id, shared.robot_grasp_id, goal.id)),
             straight_seconds(receiving_, shared.joints_rr, shared.joints_rh)) +
         straight_seconds(receiving_, shared.joints_rh, receiving_.spec.home);
}

}  // namespace hila::online::detail
