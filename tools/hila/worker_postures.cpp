#include "worker_postures.hpp"

#include <algorithm>
#include <limits>
#include <utility>

#include "hila/core/comfort.hpp"
#include "hila/core/comfort_map.hpp"
#include "hila/core/ergonomic_scores.hpp"
#include "hila/core/error.hpp"
#include "hila/core/mesh_symmetry.hpp"
#include "hila/offline/build.hpp"
#include "hila/offline/ergonomics.hpp"
#include "hila/online/board_planner.hpp"
#include "plan_sequence.hpp"

namespace hila::tools {

namespace {

// The human's comfort maps as the database stores them, in the cell's human arm order.
offline::HumanComfort stored_comfort(const core::Cell& cell, const db::Database& database) {
  const auto records = database.read_comfort_maps();
  std::vector<core::ComfortMap> maps;
  for (const auto& arm : cell.human_arms()) {
    const auto it = std::find_if(records.begin(), records.end(),
                                 [&](const auto& m) { return m.arm == arm.spec.name; });
    if (it == records.end()) {
      throw core::InputError(database.path(), "comfort_maps",
                             "a comfort map for the human arm '" + arm.spec.name + "'", "none");
    }
    maps.push_back(core::ComfortMap::from_grid(it->origin, it->spacing, it->dims, it->orientations,
                                               it->values, it->coverage));
  }
  return offline::HumanComfort(cell, std::move(maps));
}

// hila's handover as planned: the plan file's scores and posture check (the same functions), and
// the reach, Q and re-orientation by the body's own arms at the plan's joints.
TakenPosture planned_posture(const core::Cell& cell, const online::BoardPlan& plan, double load_kg,
                             const core::Pose& stance, const Eigen::Vector3d& centre_of_mass,
                             const core::Pose& target,
                             const std::vector<Eigen::Matrix3d>& symmetries) {
  TakenPosture t;
  t.status = online::to_string(plan.status);
  if (!plan.solved()) {
    t.why = plan.reason;
    return t;
  }
  t.goal_rank = plan.goal_rank;
  t.candidate = plan.candidate_id;
  t.way = online::to_string(plan.mode);
  t.natural_posture = plan.natural_posture;
  t.reorientation_deg =
      core::least_rotation_angle_deg(plan.human_handover.linear(), target.linear(), symmetries);
  t.ergonomics = plan_receiving_ergonomics(cell, plan, load_kg, stance, centre_of_mass);
  if (!t.ergonomics.scores.scored) {
    t.why = t.ergonomics.error;
    return t;
  }
  t.arm = plan.human_arm;
  t.joints[plan.human_arm] = plan.human_joints;
  if (!plan.second_human_arm.empty()) t.joints[plan.second_human_arm] = plan.second_human_joints;
  t.torso_flexion_deg = t.ergonomics.check.trunk_flexion_deg;
  // The whole posture on the plan's body (the cell's human without one), at the stance.
  const core::HumanBody* body = plan.worker.get();
  const core::RobotModel& human = body != nullptr ? body->model() : cell.human();
  const std::vector<core::HumanArm>& arms = body != nullptr ? body->arms() : cell.human_arms();
  std::vector<std::pair<std::string, Eigen::VectorXd>> held(t.joints.begin(), t.joints.end());
  const Eigen::VectorXd q = body != nullptr ? body->posture(held) : core::human_posture(cell, held);
  std::vector<core::Pose> links;
  human.link_poses(q, links);
  t.quality = std::numeric_limits<double>::infinity();
  for (const auto& arm : arms) {
    const auto joints = t.joints.find(arm.spec.name);
    if (joints == t.joints.end()) continue;
    t.quality = std::min(t.quality, core::comfort_index(arm.chain.jacobian(joints->second),
                                                        core::characteristic_length(arm.chain)));
    if (arm.spec.name != plan.human_arm) continue;
    const core::Pose base =
        stance * links[static_cast<std::size_t>(human.link_index(arm.spec.base_link))];
    t.reach = ((base * arm.chain.fk(joints->second)).translation() -
               base * arm.chain.first_joint_position())
                  .norm();
  }
  t.scored = true;
  return t;
}

// A posture the offline search found for the table drop or the stack, scored on the body it was
// searched on (`body`: nullptr for the cell's human) by the plan file's functions, the one arm's
// posture standing for both where the part needs two hands.
TakenPosture searched_posture(const core::Cell& cell, const core::HumanBody* body,
                              const offline::Posture& p, const db::ErgonomicsRecord& record,
                              double load_kg, bool two_hands,
                              const Eigen::Vector3d& centre_of_mass) {
  TakenPosture t;
  t.status = p.reachable ? "reachable" : "unreachable";
  t.reorientation_deg = record.reorientation_deg;
  if (!p.reachable) {
    t.why = "unreachable";
    return t;
  }
  t.arm = record.arm;
  t.joints[record.arm] = p.arm_joints;
  t.torso_flexion_deg = p.torso_flexion_deg;
  t.reach = p.reach;
  t.quality = p.quality;
  try {
    ReceivingErgonomics& e = t.ergonomics;
    e.scores = online::receiving_scores(cell, body, p.q, {record.arm}, load_kg, two_hands);
    e.check = online::check_receiving_posture(cell, body, p.stance, p.q, {record.arm},
                                              p.board * centre_of_mass, load_kg, two_hands);
    t.scored = e.scores.scored;
  } catch (const core::InputError& error) {
    t.ergonomics = {};
    t.ergonomics.error = error.what();
    t.why = error.what();
  }
  return t;
}

}  // namespace

ErgonomicsContext load_ergonomics_context(const std::string& database, const std::string& scene) {
  ErgonomicsContext c;
  const online::SceneFiles files = online::read_scene_files(scene);
  c.model = online::PlannerModel::load(database, files.cell, files.product);
  c.scene = online::load_scene(scene, c.model->cell(), c.model->product());
  try {
    c.comfort.emplace(stored_comfort(c.model->cell(), c.model->database()));
  } catch (const core::InputError& e) {
    c.comfort_error = e.what();
  }
  // The database was built from these meshes (PlannerModel::load checks the hashes).
  for (const auto& part : c.model->product().parts) {
    c.symmetries[part.name] = core::mesh_symmetries(part.mesh);
  }
  return c;
}

WorkerPostures worker_postures(const ErgonomicsContext& context, const ReportWorker& worker,
                               double deadline_s) {
  const online::PlannerModel& model = *context.model;
  const core::Cell& cell = model.cell();
  const db::Database& database = model.database();
  WorkerPostures out;
  out.worker = worker;
  online::Scene scene = context.scene;
  scene.worker = worker.body;  // as a scene's `worker: {stature, sex}` names it
  out.band = core::natural_height_band(cell, worker.body.get(), scene.human_stance);
  const std::vector<std::string> boards = boards_to_plan(model, scene);
  std::map<std::string, TakenPosture> planned;
  std::map<std::string, core::Pose> handed_over;  // the board where hila's plan hands it over
  // A planner of its own, as one `hila plan --all` run for this worker's scene.
  online::BoardPlanner planner(model);
  plan_in_sequence(
      model, planner, scene, boards, deadline_s,
      [&](const online::BoardPlan& plan, const online::Scene& planned_in) {
        const core::PartSpec& part = model.product().part(plan.board);
        const online::BoardRecords* records = model.board_records(plan.board);
        planned[plan.board] = planned_posture(
            cell, plan, part.mass, planned_in.human_stance,
            records != nullptr ? records->part.mass_properties.com : Eigen::Vector3d::Zero(),
            planned_in.assembly_frame * part.target, context.symmetries.at(part.name));
        handed_over[plan.board] = plan.human_handover;
      });
  // The offline search on the worker's body (nullptr for the cell's human: its own model).
  const core::HumanBody* body =
      worker.body != nullptr && !worker.body->same_as_cell() ? worker.body.get() : nullptr;
  for (const std::string& name : boards) {
    const core::PartSpec& part = model.product().part(name);
    BoardPostures row;
    row.board = name;
    row.order = part.order;
    row.symmetries = static_cast<int>(context.symmetries.at(name).size());
    row.by_method["hila"] = planned.at(name);
    TakenPosture& table = row.by_method["table"];
    TakenPosture& alone = row.by_method["alone"];
    if (!context.comfort) {
      for (TakenPosture* t : {&table, &alone}) {
        t->status = "not evaluated";
        t->why = context.comfort_error;
      }
      out.boards.push_back(std::move(row));
      continue;
    }
    const db::PartRecord& record = database.part(name);
    const auto grasps = database.human_grasps(record.id);
    const auto placements = database.placements(record.id);
    offline::ErgonomicsInputs in;
    in.target = scene.assembly_frame * part.target;
    in.initial = scene.initial_pose(part);
    in.has_placement = !placements.empty();
    if (in.has_placement) in.table_placement = placements.front().part_in_plane;
    in.human_grasps = &grasps;
    in.symmetries = context.symmetries.at(name);
    in.stance = scene.human_stance;
    in.body = body;
    // The build's settings and seed for this part: the cell human's postures are the stored ones.
    offline::ErgonomicsSettings settings;
    settings.seed = offline::part_seed(database.meta().seed, name, 5);
    std::vector<offline::Posture> postures;
    const auto records =
        offline::evaluate_ergonomics(cell, *context.comfort, in, settings, &postures);
    // Two-hand parts (no one-hand grasp): the one arm's posture stands for both.
    const bool two_hands =
        std::none_of(grasps.begin(), grasps.end(), [](const auto& g) { return g.one_hand_stable; });
    table.status = "not evaluated";
    table.why = "no stable placement on the table";
    for (std::size_t k = 0; k < records.size(); ++k) {
      row.by_method[records[k].method] = searched_posture(
          cell, body, postures[k], records[k], part.mass, two_hands, record.mass_properties.com);
    }
    // Each scored take is followed by the turn to the fitted orientation, in front of the worker
    // at the scene's stance, with the grasps the table and alone postures use.
    std::vector<int> usable;
    for (std::size_t g = 0; g < grasps.size(); ++g) {
      if (two_hands || grasps[g].one_hand_stable) usable.push_back(static_cast<int>(g));
    }
    for (std::size_t k = 0; k < records.size(); ++k) {
      TakenPosture& t = row.by_method[records[k].method];
      if (t.scored) {
        t.turn = offline::turn_in_hands(cell, *context.comfort, scene.human_stance,
                                        postures[k].board, in.target.linear(), in.symmetries,
                                        record.mass_properties.com, &part.mesh, grasps, usable,
                                        settings, offline::TurnSettings{}, body);
      }
    }
    if (TakenPosture& t = row.by_method["hila"]; t.scored) {
      t.turn = offline::turn_in_hands(cell, *context.comfort, scene.human_stance,
                                      handed_over.at(name), in.target.linear(), in.symmetries,
                                      record.mass_properties.com, &part.mesh, grasps, usable,
                                      settings, offline::TurnSettings{}, body);
    }
    out.boards.push_back(std::move(row));
  }
  return out;
}

}  // namespace hila::tools
