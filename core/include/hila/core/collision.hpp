#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "hila/core/mesh.hpp"
#include "hila/core/pose.hpp"
#include "hila/core/robot_model.hpp"

namespace hila::core {

struct CollisionModelImpl;
struct CollisionDataImpl;

// Rigid bodies (each a set of shapes), whether each is static, and which pairs may touch. Built
// once, then shared read-only between threads; the per-thread mutable part is CollisionData.
class CollisionModel {
 public:
  CollisionModel();
  ~CollisionModel();
  CollisionModel(CollisionModel&&) noexcept;
  CollisionModel& operator=(CollisionModel&&) noexcept;

  // Adds a body made of `shapes` (each with its origin in the body frame). Mesh shapes are loaded
  // from their files. Returns the body index.
  int add_body(const std::string& name, const std::vector<GeometrySpec>& shapes, bool is_static,
               const Pose& pose = Pose::Identity());
  int add_mesh_body(const std::string& name, const TriangleMesh& mesh, bool is_static,
                    const Pose& pose = Pose::Identity());
  void allow(int body_a, int body_b);
  void allow(const std::string& body_a, const std::string& body_b);  // throws if unknown
  // Removes the body from all checks (keeps indices stable).
  void set_enabled(int body, bool enabled);

  int num_bodies() const;
  const std::string& body_name(int body) const;
  std::optional<int> find_body(const std::string& name) const;
  bool is_static(int body) const;
  bool is_enabled(int body) const;
  bool allowed(int body_a, int body_b) const;
  const Pose& initial_pose(int body) const;

  const CollisionModelImpl& impl() const { return *impl_; }

 private:
  std::unique_ptr<CollisionModelImpl> impl_;
};

// Per-thread state: body poses and FCL broad-phase structures. Create one per thread.
class CollisionData {
 public:
  explicit CollisionData(const CollisionModel& model);
  ~CollisionData();
  CollisionData(CollisionData&&) noexcept;
  CollisionData& operator=(CollisionData&&) noexcept;

  void set_body_pose(int body, const Pose& pose);
  const Pose& body_pose(int body) const;

  CollisionDataImpl& impl() { return *impl_; }

 private:
  std::unique_ptr<CollisionDataImpl> impl_;
};

struct CollisionPair {
  int body_a = -1;
  int body_b = -1;
  double distance = 0.0;  // for distance queries
};

// Any collision between enabled bodies, except static-static and allowed pairs. Broad-phase
// (FCL dynamic AABB trees) over the static and the moving bodies; each candidate pair of shapes
// then goes through their oriented bounding boxes (fcl::OBB, the shape's local box carried by its
// pose) before FCL's narrow phase, which leaves the verdict FCL's. Stops at the first contact and
// reports its pair.
bool in_collision(const CollisionModel& model, CollisionData& data, CollisionPair* first = nullptr);
// Collisions involving at least one of `bodies` (against every other enabled body, static or
// moving, and among themselves). This is the planner's query when one arm (with what it holds)
// moves and the rest of the scene is unchanged. No tree: inline world-box tests against the
// moving set's reach, then per body, per shape, the oriented boxes, then FCL's narrow phase.
bool in_collision(const CollisionModel& model, CollisionData& data, const std::vector<int>& bodies,
                  CollisionPair* first = nullptr);
// The same, except pairs of two bodies of `rigid`: a part of `bodies` that moves as one piece
// through the caller's motion (an arm's last link with its gripper and what it holds), whose
// pairs keep their verdict while it does. The caller checks those once, in_collision_among().
bool in_collision(const CollisionModel& model, CollisionData& data, const std::vector<int>& bodies,
                  CollisionPair* first, const std::vector<int>& rigid);
// Collisions between two of `bodies` only (testable pairs).
bool in_collision_among(const CollisionModel& model, CollisionData& data,
                        const std::vector<int>& bodies, CollisionPair* first = nullptr);
// The same answer by testing every candidate pair with FCL's narrow phase (reference for tests).
bool in_collision_brute_force(const CollisionModel& model, CollisionData& data,
                              CollisionPair* first = nullptr);
// Brute-force reference for the subset query.
bool in_collision_brute_force(const CollisionModel& model, CollisionData& data,
                              const std::vector<int>& bodies, CollisionPair* first = nullptr);
// Smallest distance over the same pairs (negative or zero when in collision). Ask in_collision
// first: between touching shapes FCL runs its penetration code (EPA), which asserts, and aborts
// the process, on some mesh pairs. A pair on which FCL throws (exact contact) counts as 0.
double min_distance(const CollisionModel& model, CollisionData& data,
                    CollisionPair* closest = nullptr);

std::string describe_pair(const CollisionModel& model, const CollisionPair& pair);

// Maps a robot's links to collision bodies (one body per link with collision geometry).
struct RobotBodies {
  std::vector<int> link_to_body;  // -1 for links without geometry
};

// Adds the robot's links as bodies named prefix + link name (moving unless `is_static`), and
// allows each link with the nearest ancestor that has geometry (links joined through
// geometry-less frames touch).
RobotBodies add_robot(CollisionModel& model, const RobotModel& robot, const std::string& prefix,
                      bool is_static = false);

// Bodies of the links at and below `root_link` (an arm with its gripper, say).
std::vector<int> subtree_bodies(const RobotModel& robot, const RobotBodies& bodies, int root_link);

// The bodies that move rigidly with `tip_link` while only joints above it move: those below the
// last movable joint on its way up (an arm's last link with the gripper, at a given jaw).
std::vector<int> rigid_tip_bodies(const RobotModel& robot, const RobotBodies& bodies, int tip_link);

// Sets every link body's pose to base * link_poses[link].
void set_robot_pose(CollisionData& data, const RobotBodies& bodies,
                    const std::vector<Pose>& link_poses, const Pose& base = Pose::Identity());

// An object held by a robot link (a board in the gripper, the suction tool): its body follows
// the link. Attach it with the gripper bodies it touches (pads, fingers) allowed.
struct Attachment {
  int body = -1;
  int link = -1;
  Pose link_to_body = Pose::Identity();
};

Attachment attach(CollisionModel& model, int body, int link, const Pose& link_to_body,
                  const std::vector<int>& touching_bodies);

// Sets the attached body's pose from the link's pose (base * link_poses[link] * link_to_body).
void set_attachment_pose(CollisionData& data, const Attachment& attachment,
                         const std::vector<Pose>& link_poses, const Pose& base = Pose::Identity());

}  // namespace hila::core
