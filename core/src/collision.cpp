#include "hila/core/collision.hpp"

#include <fcl/broadphase/broadphase_dynamic_AABB_tree.h>
#include <fcl/geometry/bvh/BVH_model.h>
#include <fcl/geometry/shape/box.h>
#include <fcl/geometry/shape/convex.h>
#include <fcl/geometry/shape/cylinder.h>
#include <fcl/geometry/shape/sphere.h>
#include <fcl/math/bv/OBB.h>
#include <fcl/narrowphase/collision.h>
#include <fcl/narrowphase/distance.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <exception>
#include <limits>

#include "hila/core/error.hpp"
#include "hila/core/internal/obb_separation.hpp"

namespace hila::core {

using FclGeometry = std::shared_ptr<fcl::CollisionGeometryd>;

struct BodyModel {
  std::string name;
  std::vector<FclGeometry> geometries;
  std::vector<Pose> offsets;
  bool is_static = false;
  bool enabled = true;
  Pose initial_pose = Pose::Identity();
};

struct CollisionModelImpl {
  std::vector<BodyModel> bodies;
  std::vector<std::vector<bool>> allowed;
  // Derived, kept current by every mutation: the enabled moving bodies, and the pairs a query
  // tests (both enabled, not both static, not allowed) as a flat byte matrix, so that the
  // planner's hot loop reads bytes instead of vector<bool> bits and skips static bodies.
  std::vector<int> moving_bodies;
  std::vector<int> shaped_bodies;  // enabled, with at least one shape
  std::vector<unsigned char> testable;
  // Bumped by every change of the pairs: what per-thread data derived from them is keyed on.
  std::uint64_t version = 0;

  bool pair_testable(std::size_t a, std::size_t b) const {
    return a != b && bodies[a].enabled && bodies[b].enabled &&
           !(bodies[a].is_static && bodies[b].is_static) && !allowed[a][b];
  }

  void refresh_pairs() {
    ++version;
    const std::size_t n = bodies.size();
    moving_bodies.clear();
    shaped_bodies.clear();
    testable.assign(n * n, 0);
    for (std::size_t a = 0; a < n; ++a) {
      if (bodies[a].enabled && !bodies[a].is_static) moving_bodies.push_back(static_cast<int>(a));
      if (bodies[a].enabled && !bodies[a].geometries.empty()) {
        shaped_bodies.push_back(static_cast<int>(a));
      }
      for (std::size_t b = 0; b < n; ++b) testable[a * n + b] = pair_testable(a, b);
    }
  }

  // The same for a body just appended (the highest index), touching only its row and column: a
  // world adds its dozens of bodies one by one, and a full refresh for each would dominate its
  // build.
  void append_pairs() {
    ++version;
    const std::size_t n = bodies.size();
    const std::size_t last = n - 1;
    std::vector<unsigned char> grown(n * n, 0);
    for (std::size_t a = 0; a < last; ++a) {
      std::copy_n(testable.begin() + static_cast<std::ptrdiff_t>(a * last), last,
                  grown.begin() + static_cast<std::ptrdiff_t>(a * n));
      grown[a * n + last] = pair_testable(a, last);
      grown[last * n + a] = pair_testable(last, a);
    }
    testable.swap(grown);
    if (bodies[last].enabled && !bodies[last].is_static) {
      moving_bodies.push_back(static_cast<int>(last));
    }
    if (bodies[last].enabled && !bodies[last].geometries.empty()) {
      shaped_bodies.push_back(static_cast<int>(last));
    }
  }
};

namespace {

// A closed mesh is convex when no vertex lies in front of any triangle's plane. Checked only for
// small meshes (boards, boxes), where it pays: FCL refits an OBB of the other shape on every
// shape-vs-mesh query, while a Convex goes through GJK.
bool is_small_convex(const TriangleMesh& mesh) {
  if (mesh.triangles.empty() || mesh.triangles.size() > 64) return false;
  const double size = (mesh.max_corner() - mesh.min_corner()).norm();
  for (const auto& t : mesh.triangles) {
    const Eigen::Vector3d& a = mesh.vertices[static_cast<std::size_t>(t[0])];
    const Eigen::Vector3d n = (mesh.vertices[static_cast<std::size_t>(t[1])] - a)
                                  .cross(mesh.vertices[static_cast<std::size_t>(t[2])] - a);
    if (n.norm() <= 0.0) return false;
    const Eigen::Vector3d unit = n.normalized();
    for (const auto& v : mesh.vertices) {
      if (unit.dot(v - a) > 1e-9 * size) return false;
    }
  }
  return true;
}

FclGeometry make_convex_geometry(const TriangleMesh& mesh, const Eigen::Vector3d& scale) {
  auto vertices = std::make_shared<std::vector<fcl::Vector3d>>();
  for (const auto& v : mesh.vertices) vertices->emplace_back(v.cwiseProduct(scale));
  auto faces = std::make_shared<std::vector<int>>();
  for (const auto& t : mesh.triangles) faces->insert(faces->end(), {3, t[0], t[1], t[2]});
  auto convex =
      std::make_shared<fcl::Convexd>(vertices, static_cast<int>(mesh.triangles.size()), faces);
  convex->computeLocalAABB();
  return convex;
}

FclGeometry make_mesh_geometry(const TriangleMesh& mesh, const Eigen::Vector3d& scale) {
  if (is_small_convex(mesh)) return make_convex_geometry(mesh, scale);
  auto bvh = std::make_shared<fcl::BVHModel<fcl::OBBRSSd>>();
  std::vector<fcl::Vector3d> points;
  points.reserve(mesh.vertices.size());
  for (const auto& v : mesh.vertices) points.emplace_back(v.cwiseProduct(scale));
  std::vector<fcl::Triangle> triangles;
  triangles.reserve(mesh.triangles.size());
  for (const auto& t : mesh.triangles) triangles.emplace_back(t[0], t[1], t[2]);
  bvh->beginModel();
  bvh->addSubModel(points, triangles);
  bvh->endModel();
  bvh->computeLocalAABB();
  return bvh;
}

FclGeometry make_geometry(const GeometrySpec& spec) {
  FclGeometry g;
  switch (spec.type) {
    case GeometrySpec::Type::Box:
      g = std::make_shared<fcl::Boxd>(spec.box_size);
      break;
    case GeometrySpec::Type::Cylinder:
      g = std::make_shared<fcl::Cylinderd>(spec.radius, spec.length);
      break;
    case GeometrySpec::Type::Sphere:
      g = std::make_shared<fcl::Sphered>(spec.radius);
      break;
    case GeometrySpec::Type::Mesh:
      return make_mesh_geometry(load_mesh(spec.mesh_path, 1.0), spec.mesh_scale);
  }
  g->computeLocalAABB();
  return g;
}

void require_new_name(const CollisionModelImpl& m, const std::string& name) {
  for (const auto& b : m.bodies) {
    if (b.name == name) {
      throw InputError("collision scene", "body '" + name + "'", "a unique body name",
                       "a duplicate");
    }
  }
}

// Appends a body with its shapes in place, so that the pairs know it has shapes (shapes added
// after the pairs' refresh would leave a mesh body added last untested by the subset query).
// The caller has checked the name (require_new_name) before making the shapes.
int append_body(CollisionModelImpl& m, const std::string& name, std::vector<FclGeometry> geometries,
                std::vector<Pose> offsets, bool is_static, const Pose& pose) {
  BodyModel body;
  body.name = name;
  body.is_static = is_static;
  body.initial_pose = pose;
  body.geometries = std::move(geometries);
  body.offsets = std::move(offsets);
  m.bodies.push_back(std::move(body));
  for (auto& row : m.allowed) row.push_back(false);
  m.allowed.emplace_back(m.bodies.size(), false);
  m.append_pairs();
  return static_cast<int>(m.bodies.size()) - 1;
}

}  // namespace

CollisionModel::CollisionModel() : impl_(std::make_unique<CollisionModelImpl>()) {}
CollisionModel::~CollisionModel() = default;
CollisionModel::CollisionModel(CollisionModel&&) noexcept = default;
CollisionModel& CollisionModel::operator=(CollisionModel&&) noexcept = default;

int CollisionModel::add_body(const std::string& name, const std::vector<GeometrySpec>& shapes,
                             bool is_static, const Pose& pose) {
  require_new_name(*impl_, name);  // before any mesh is loaded: the error names the real fault
  std::vector<FclGeometry> geometries;
  std::vector<Pose> offsets;
  for (const auto& s : shapes) {
    geometries.push_back(make_geometry(s));
    offsets.push_back(s.origin);
  }
  return append_body(*impl_, name, std::move(geometries), std::move(offsets), is_static, pose);
}

int CollisionModel::add_mesh_body(const std::string& name, const TriangleMesh& mesh, bool is_static,
                                  const Pose& pose) {
  require_new_name(*impl_, name);
  return append_body(*impl_, name, {make_mesh_geometry(mesh, Eigen::Vector3d::Ones())},
                     {Pose::Identity()}, is_static, pose);
}

void CollisionModel::allow(int a, int b) {
  impl_->allowed[a][b] = true;
  impl_->allowed[b][a] = true;
  const std::size_t n = impl_->bodies.size();
  impl_->testable[static_cast<std::size_t>(a) * n + static_cast<std::size_t>(b)] = 0;
  impl_->testable[static_cast<std::size_t>(b) * n + static_cast<std::size_t>(a)] = 0;
  ++impl_->version;
}

void CollisionModel::allow(const std::string& a, const std::string& b) {
  const auto ia = find_body(a);
  const auto ib = find_body(b);
  if (!ia) throw InputError("collision scene", "allowed pair", "a known body name", "'" + a + "'");
  if (!ib) throw InputError("collision scene", "allowed pair", "a known body name", "'" + b + "'");
  allow(*ia, *ib);
}

void CollisionModel::set_enabled(int body, bool enabled) {
  impl_->bodies[body].enabled = enabled;
  impl_->refresh_pairs();
}
int CollisionModel::num_bodies() const {
  return static_cast<int>(impl_->bodies.size());
}
const std::string& CollisionModel::body_name(int body) const {
  return impl_->bodies[body].name;
}
bool CollisionModel::is_static(int body) const {
  return impl_->bodies[body].is_static;
}
bool CollisionModel::is_enabled(int body) const {
  return impl_->bodies[body].enabled;
}
bool CollisionModel::allowed(int a, int b) const {
  return impl_->allowed[a][b];
}
const Pose& CollisionModel::initial_pose(int body) const {
  return impl_->bodies[body].initial_pose;
}

std::optional<int> CollisionModel::find_body(const std::string& name) const {
  for (int i = 0; i < num_bodies(); ++i) {
    if (impl_->bodies[i].name == name) return i;
  }
  return std::nullopt;
}

// --- per-thread data -----------------------------------------------------------------------

namespace {

// A world axis-aligned box, compared inline: the subset query's loops test thousands per call,
// where fcl::AABB::overlap is an out-of-line call into the library.
struct WorldBox {
  double lo[3] = {0.0, 0.0, 0.0};
  double hi[3] = {0.0, 0.0, 0.0};
};

inline WorldBox to_world_box(const fcl::AABBd& box) {
  return {{box.min_[0], box.min_[1], box.min_[2]}, {box.max_[0], box.max_[1], box.max_[2]}};
}

inline void merge(WorldBox& into, const WorldBox& box) {
  for (int k = 0; k < 3; ++k) {
    into.lo[k] = std::min(into.lo[k], box.lo[k]);
    into.hi[k] = std::max(into.hi[k], box.hi[k]);
  }
}

// Touching boxes overlap, as in FCL.
// All six comparisons, then one branch: a query tests hundreds of box pairs that mostly miss
// on some axis, and a branch per axis is mispredicted on many of them.
inline bool overlap(const WorldBox& a, const WorldBox& b) {
  const auto le = [](double x, double y) { return static_cast<unsigned>(x <= y); };
  return (le(a.lo[0], b.hi[0]) & le(b.lo[0], a.hi[0]) & le(a.lo[1], b.hi[1]) &
          le(b.lo[1], a.hi[1]) & le(a.lo[2], b.hi[2]) & le(b.lo[2], a.hi[2])) != 0U;
}

// What the subset query tests for one set of bodies, derived once from the model's pairs: the
// planner asks about the same set (one arm, its tool and board) thousands of times in a row.
struct SubsetPlan {
  std::uint64_t version = 0;
  std::vector<int> key;    // the set as asked
  std::vector<int> rigid;  // its part whose pairs are left out
  struct Active {
    int body = -1;
    std::vector<int> inner;  // later bodies of the set testable with it, ascending
  };
  std::vector<Active> active;  // the set's enabled bodies with shapes, in the set's order
  std::vector<int> outer;  // the other bodies with shapes testable with one of the set, ascending
};

struct ShapeTag {
  int body;
  int object;  // index into CollisionDataImpl::objects / obbs
};

// Each shape's local bounding box (FCL's, in the shape's frame) carried by the shape's pose: an
// oriented box that encloses the shape. Far tighter than the world AABB of a rotated cylinder or
// board, and two of them are told apart in a few dozen flops, where FCL's narrow phase runs GJK.
// Grown by a margin larger than GJK's tolerance, so that a pair the boxes separate is one FCL
// would report separate too: the verdicts are FCL's.
constexpr double kObbMargin = 1e-5;

void fit_obb(const fcl::CollisionObjectd& object, fcl::OBBd& obb) {
  const fcl::Transform3d& tf = object.getTransform();
  const fcl::AABBd& local = object.collisionGeometry()->aabb_local;
  obb.axis = tf.linear();
  obb.To = tf * local.center();
  obb.extent = 0.5 * (local.max_ - local.min_) + Eigen::Vector3d::Constant(kObbMargin);
}

// The world box of an oriented box: its centre +- |axes| * extent. Tighter than FCL's world AABB
// of a rotated shape (a cube around the shape's bounding sphere), so far fewer pairs of shapes
// reach the oriented-box test; it still encloses the shape.
inline WorldBox to_world_box(const fcl::OBBd& obb) {
  WorldBox box;
  for (int k = 0; k < 3; ++k) {
    const double half = std::abs(obb.axis(k, 0)) * obb.extent[0] +
                        std::abs(obb.axis(k, 1)) * obb.extent[1] +
                        std::abs(obb.axis(k, 2)) * obb.extent[2];
    box.lo[k] = obb.To[k] - half;
    box.hi[k] = obb.To[k] + half;
  }
  return box;
}

}  // namespace

// Where a shape's oriented box sits in its body (constant): a pose update places the box from the
// body's pose directly, and FCL's object transform is brought up to date only when FCL itself
// needs it (the narrow phase of a pair the boxes do not separate, a tree query).
struct ShapeFrame {
  Pose offset = Pose::Identity();  // the shape in its body
  bool identity_offset = true;
  bool rotated = false;                              // offset has a rotation
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();  // its local box's centre, body frame
};

struct CollisionDataImpl {
  const CollisionModelImpl* model = nullptr;
  std::vector<Pose> body_poses;
  std::vector<std::unique_ptr<fcl::CollisionObjectd>> objects;
  std::vector<ShapeFrame> shape_frames;  // per object
  std::vector<unsigned char> stale;      // per object: its FCL transform lags its body's pose
  std::vector<std::vector<int>> body_objects;
  std::vector<ShapeTag> tags;
  std::vector<fcl::OBBd> obbs;           // per object, kept with its pose
  std::vector<unsigned char> last_axis;  // per pair of objects (QueryContext::last_axis)
  std::vector<WorldBox> object_boxes;    // per object: the world box of its oriented box
  fcl::DynamicAABBTreeCollisionManagerd static_manager;
  fcl::DynamicAABBTreeCollisionManagerd moving_manager;
  // Objects whose pose changed since the last query: only these are re-fitted in the trees.
  std::vector<fcl::CollisionObjectd*> changed_moving;
  std::vector<fcl::CollisionObjectd*> changed_static;
  std::vector<SubsetPlan> subset_plans;  // a few sets, most recent last
  std::vector<int> near_scratch;
  std::vector<WorldBox> body_boxes;  // each body's shapes' boxes, merged (world)
  bool moving_full_refit = false;
  bool static_full_refit = false;
};

CollisionData::CollisionData(const CollisionModel& model)
    : impl_(std::make_unique<CollisionDataImpl>()) {
  const auto& bodies = model.impl().bodies;
  impl_->body_poses.resize(bodies.size());
  impl_->body_objects.resize(bodies.size());
  std::size_t total = 0;
  for (const auto& b : bodies) total += b.geometries.size();
  impl_->tags.reserve(total);  // tags are referenced by pointer: no reallocation
  std::vector<fcl::CollisionObjectd*> static_objects;
  std::vector<fcl::CollisionObjectd*> moving_objects;
  for (std::size_t b = 0; b < bodies.size(); ++b) {
    impl_->body_poses[b] = bodies[b].initial_pose;
    for (std::size_t s = 0; s < bodies[b].geometries.size(); ++s) {
      auto object = std::make_unique<fcl::CollisionObjectd>(
          bodies[b].geometries[s], bodies[b].initial_pose * bodies[b].offsets[s]);
      object->computeAABB();
      impl_->tags.push_back({static_cast<int>(b), static_cast<int>(impl_->objects.size())});
      ShapeFrame& frame = impl_->shape_frames.emplace_back();
      frame.offset = bodies[b].offsets[s];
      frame.identity_offset = frame.offset.isApprox(Pose::Identity(), 0.0);
      frame.rotated = !frame.offset.linear().isIdentity(0.0);
      frame.centre = frame.offset * bodies[b].geometries[s]->aabb_local.center();
      impl_->stale.push_back(0);
      fit_obb(*object, impl_->obbs.emplace_back());
      impl_->object_boxes.push_back(to_world_box(impl_->obbs.back()));
      object->setUserData(&impl_->tags.back());
      impl_->body_objects[b].push_back(static_cast<int>(impl_->objects.size()));
      if (bodies[b].enabled) {
        (bodies[b].is_static ? static_objects : moving_objects).push_back(object.get());
      }
      impl_->objects.push_back(std::move(object));
    }
  }
  impl_->last_axis.assign(impl_->objects.size() * impl_->objects.size(), 0);
  impl_->body_boxes.resize(bodies.size());
  for (std::size_t b = 0; b < bodies.size(); ++b) {
    for (const int o : impl_->body_objects[b]) {
      if (o == impl_->body_objects[b].front()) {
        impl_->body_boxes[b] = impl_->object_boxes[o];
      } else {
        merge(impl_->body_boxes[b], impl_->object_boxes[o]);
      }
    }
  }
  impl_->static_manager.registerObjects(static_objects);
  impl_->static_manager.setup();
  impl_->moving_manager.registerObjects(moving_objects);
  impl_->moving_manager.setup();
  impl_->model = &model.impl();
}

CollisionData::~CollisionData() = default;
CollisionData::CollisionData(CollisionData&&) noexcept = default;
CollisionData& CollisionData::operator=(CollisionData&&) noexcept = default;

void CollisionData::set_body_pose(int body, const Pose& pose) {
  auto& d = *impl_;
  // Planning moves one arm at a time: skipping unchanged bodies keeps the tree update small.
  if (d.body_poses[body].matrix() == pose.matrix()) return;
  d.body_poses[body] = pose;
  const auto& objs = d.body_objects[body];
  auto& changed = d.model->bodies[body].is_static ? d.changed_static : d.changed_moving;
  // Subset queries never drain the moving list; past one entry per object a full refit is
  // cheaper than replaying the list.
  if (changed.size() > d.objects.size()) {
    changed.clear();
    (d.model->bodies[body].is_static ? d.static_full_refit : d.moving_full_refit) = true;
  }
  for (std::size_t s = 0; s < objs.size(); ++s) {
    const auto o = static_cast<std::size_t>(objs[s]);
    const ShapeFrame& frame = d.shape_frames[o];
    // The oriented box from the body's pose (its extent never changes); FCL's transform and
    // world box wait for a query that needs them (ensure_transform, refresh).
    fcl::OBBd& obb = d.obbs[o];
    if (frame.rotated) {
      obb.axis.noalias() = pose.linear() * frame.offset.linear();
    } else {
      obb.axis = pose.linear();
    }
    obb.To = pose * frame.centre;
    const WorldBox& box = d.object_boxes[o] = to_world_box(obb);
    d.stale[o] = 1;
    changed.push_back(d.objects[o].get());
    if (s == 0) {
      d.body_boxes[body] = box;
    } else {
      merge(d.body_boxes[body], box);
    }
  }
}

const Pose& CollisionData::body_pose(int body) const {
  return impl_->body_poses[body];
}

namespace {

// FCL's transform of object o, from its body's pose, when a pose update left it behind.
inline void ensure_transform(CollisionDataImpl& d, std::size_t o) {
  if (!d.stale[o]) return;
  const ShapeFrame& frame = d.shape_frames[o];
  const Pose& pose = d.body_poses[static_cast<std::size_t>(d.tags[o].body)];
  d.objects[o]->setTransform(frame.identity_offset ? pose : pose * frame.offset);
  d.stale[o] = 0;
}

struct QueryContext {
  const CollisionModelImpl* model;
  CollisionPair* pair;
  CollisionDataImpl* data;  // whose objects' transforms the narrow phase brings up to date
  const std::vector<fcl::OBBd>* obbs = nullptr;  // the oriented-box test first, when given
  // Per pair of shapes (lower object index first), the axis that last separated their boxes:
  // tried first next time (separating_axis).
  std::vector<unsigned char>* last_axis = nullptr;
  bool hit = false;
  double min_distance = std::numeric_limits<double>::infinity();
};

inline bool skip_pair(const CollisionModelImpl& m, int a, int b) {
  if (a == b) return true;
  if (!m.bodies[a].enabled || !m.bodies[b].enabled) return true;
  if (m.bodies[a].is_static && m.bodies[b].is_static) return true;
  return m.allowed[a][b];
}

// The narrow phase of two shapes of a testable pair of bodies (a, b): their oriented boxes when
// the context has them, then FCL.
bool narrow_phase(fcl::CollisionObjectd* o1, fcl::CollisionObjectd* o2, int a, int b,
                  QueryContext* ctx) {
  if (ctx->obbs != nullptr) {
    const auto& obbs = *ctx->obbs;
    const auto i1 = static_cast<std::size_t>(static_cast<ShapeTag*>(o1->getUserData())->object);
    const auto i2 = static_cast<std::size_t>(static_cast<ShapeTag*>(o2->getUserData())->object);
    const std::size_t lo = std::min(i1, i2);
    const std::size_t hi = std::max(i1, i2);
    unsigned char& hint = (*ctx->last_axis)[lo * obbs.size() + hi];
    const int axis = separating_axis(obbs[lo], obbs[hi], hint);
    if (axis >= 0) {
      hint = static_cast<unsigned char>(axis);
      return false;
    }
  }
  ensure_transform(*ctx->data,
                   static_cast<std::size_t>(static_cast<ShapeTag*>(o1->getUserData())->object));
  ensure_transform(*ctx->data,
                   static_cast<std::size_t>(static_cast<ShapeTag*>(o2->getUserData())->object));
  fcl::CollisionRequestd request;
  fcl::CollisionResultd result;
  if (fcl::collide(o1, o2, request, result) > 0) {
    ctx->hit = true;
    if (ctx->pair) *ctx->pair = {std::min(a, b), std::max(a, b), 0.0};
    return true;  // stop at the first contact
  }
  return false;
}

bool collide_callback(fcl::CollisionObjectd* o1, fcl::CollisionObjectd* o2, void* raw) {
  auto* ctx = static_cast<QueryContext*>(raw);
  const int a = static_cast<ShapeTag*>(o1->getUserData())->body;
  const int b = static_cast<ShapeTag*>(o2->getUserData())->body;
  if (skip_pair(*ctx->model, a, b)) return false;
  return narrow_phase(o1, o2, a, b, ctx);
}

bool distance_callback(fcl::CollisionObjectd* o1, fcl::CollisionObjectd* o2, void* raw,
                       double& dist) {
  auto* ctx = static_cast<QueryContext*>(raw);
  const int a = static_cast<ShapeTag*>(o1->getUserData())->body;
  const int b = static_cast<ShapeTag*>(o2->getUserData())->body;
  if (skip_pair(*ctx->model, a, b)) {
    dist = ctx->min_distance;
    return false;
  }
  fcl::DistanceRequestd request;
  request.enable_signed_distance = true;
  fcl::DistanceResultd result;
  double d = 0.0;
  try {
    d = fcl::distance(o1, o2, request, result);
  } catch (const std::exception&) {
    // FCL's signed distance (libccd's EPA) throws on some pairs that touch exactly ("the origin is
    // outside of the polytope"): they are at contact, distance 0.
    d = 0.0;
  }
  if (d < ctx->min_distance) {
    ctx->min_distance = d;
    if (ctx->pair) *ctx->pair = {std::min(a, b), std::max(a, b), d};
  }
  dist = ctx->min_distance;
  return false;
}

// Brings the broad-phase trees up to date with the poses set since the last tree query: FCL's
// world boxes of the changed objects, then the trees' refit.
void refresh(CollisionDataImpl& d) {
  const auto update = [&d](fcl::CollisionObjectd& object) {
    ensure_transform(
        d, static_cast<std::size_t>(static_cast<ShapeTag*>(object.getUserData())->object));
    object.computeAABB();
  };
  if (d.moving_full_refit || d.static_full_refit) {
    for (auto& object : d.objects) update(*object);
  } else {
    for (auto* object : d.changed_moving) update(*object);
    for (auto* object : d.changed_static) update(*object);
  }
  if (d.moving_full_refit) {
    d.moving_manager.update();
    d.moving_full_refit = false;
    d.changed_moving.clear();
  }
  if (d.static_full_refit) {
    d.static_manager.update();
    d.static_full_refit = false;
    d.changed_static.clear();
  }
  if (!d.changed_moving.empty()) {
    d.moving_manager.update(d.changed_moving);
    d.changed_moving.clear();
  }
  if (!d.changed_static.empty()) {
    d.static_manager.update(d.changed_static);
    d.changed_static.clear();
  }
}

}  // namespace

bool in_collision(const CollisionModel& model, CollisionData& data, CollisionPair* first) {
  auto& d = data.impl();
  refresh(d);
  QueryContext ctx{&model.impl(), first, &d, &d.obbs, &d.last_axis};
  d.moving_manager.collide(&ctx, collide_callback);
  if (!ctx.hit) d.moving_manager.collide(&d.static_manager, &ctx, collide_callback);
  return ctx.hit;
}

namespace {

// Planning alternates between a handful of sets (each arm, with or without its load).
constexpr std::size_t kSubsetPlans = 8;

const SubsetPlan& subset_plan(CollisionDataImpl& d, const CollisionModelImpl& m,
                              const std::vector<int>& bodies, const std::vector<int>& rigid) {
  for (auto it = d.subset_plans.rbegin(); it != d.subset_plans.rend(); ++it) {
    if (it->version == m.version && it->key == bodies && it->rigid == rigid) return *it;
  }
  if (d.subset_plans.size() >= kSubsetPlans) d.subset_plans.erase(d.subset_plans.begin());
  SubsetPlan& plan = d.subset_plans.emplace_back();
  plan.version = m.version;
  plan.key = bodies;
  plan.rigid = rigid;
  const std::size_t n = m.bodies.size();
  std::vector<char> in_rigid(n, 0);
  for (const int b : rigid) in_rigid[static_cast<std::size_t>(b)] = 1;
  std::vector<char> in_set(n, 0);
  for (const int b : bodies) {
    if (m.bodies[b].enabled && !d.body_objects[b].empty() && !in_set[b]) {
      in_set[b] = 1;
      plan.active.push_back({b, {}});
    }
  }
  std::vector<char> outer(n, 0);
  for (auto& a : plan.active) {
    const unsigned char* testable = &m.testable[static_cast<std::size_t>(a.body) * n];
    for (const int ob : m.shaped_bodies) {
      if (!testable[ob]) continue;
      if (!in_set[ob]) {
        outer[ob] = 1;
      } else if (ob > a.body && !(in_rigid[static_cast<std::size_t>(a.body)] && in_rigid[ob])) {
        a.inner.push_back(ob);  // each pair within the set once
      }
    }
  }
  for (const int ob : m.shaped_bodies) {
    if (outer[ob]) plan.outer.push_back(ob);
  }
  return plan;
}

}  // namespace

bool in_collision(const CollisionModel& model, CollisionData& data, const std::vector<int>& bodies,
                  CollisionPair* first) {
  static const std::vector<int> none;
  return in_collision(model, data, bodies, first, none);
}

bool in_collision_among(const CollisionModel& model, CollisionData& data,
                        const std::vector<int>& bodies, CollisionPair* first) {
  auto& d = data.impl();
  const auto& m = model.impl();
  QueryContext ctx{&m, first, &d, &d.obbs, &d.last_axis};
  const std::size_t n = m.bodies.size();
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    for (std::size_t j = i + 1; j < bodies.size(); ++j) {
      const int a = std::min(bodies[i], bodies[j]);
      const int b = std::max(bodies[i], bodies[j]);
      if (!m.testable[static_cast<std::size_t>(a) * n + static_cast<std::size_t>(b)]) continue;
      for (const int o1 : d.body_objects[static_cast<std::size_t>(a)]) {
        for (const int o2 : d.body_objects[static_cast<std::size_t>(b)]) {
          if (narrow_phase(d.objects[o1].get(), d.objects[o2].get(), a, b, &ctx)) return true;
        }
      }
    }
  }
  return false;
}

bool in_collision(const CollisionModel& model, CollisionData& data, const std::vector<int>& bodies,
                  CollisionPair* first, const std::vector<int>& rigid) {
  auto& d = data.impl();
  const auto& m = model.impl();
  QueryContext ctx{&m, first, &d, &d.obbs, &d.last_axis};
  const SubsetPlan& plan = subset_plan(d, m, bodies, rigid);
  if (plan.active.empty()) return false;
  // No broad-phase tree: a cell has tens of bodies, and most outside the set fail one inline box
  // test against the set's reach.
  WorldBox reach = d.body_boxes[static_cast<std::size_t>(plan.active.front().body)];
  for (const auto& a : plan.active) merge(reach, d.body_boxes[static_cast<std::size_t>(a.body)]);
  std::vector<int>& near = d.near_scratch;
  near.clear();
  for (const int ob : plan.outer) {
    if (overlap(d.body_boxes[static_cast<std::size_t>(ob)], reach)) near.push_back(ob);
  }
  const std::size_t n = m.bodies.size();
  auto test_bodies = [&](int b, const WorldBox& box_b, int ob) {
    if (!overlap(d.body_boxes[static_cast<std::size_t>(ob)], box_b)) return false;
    for (const int o1 : d.body_objects[b]) {
      const WorldBox& box1 = d.object_boxes[static_cast<std::size_t>(o1)];
      for (const int o2 : d.body_objects[ob]) {
        if (!overlap(box1, d.object_boxes[static_cast<std::size_t>(o2)])) continue;
        if (narrow_phase(d.objects[o1].get(), d.objects[o2].get(), b, ob, &ctx)) return true;
      }
    }
    return false;
  };
  for (const auto& a : plan.active) {
    const int b = a.body;
    const unsigned char* testable = &m.testable[static_cast<std::size_t>(b) * n];
    const WorldBox& box_b = d.body_boxes[static_cast<std::size_t>(b)];
    // The set's later bodies and the near others, merged in ascending order (the order the
    // first contact is reported in does not depend on the caching).
    auto in = a.inner.begin();
    auto out = near.begin();
    while (in != a.inner.end() || out != near.end()) {
      int ob;
      if (out == near.end() || (in != a.inner.end() && *in < *out)) {
        ob = *in++;
      } else {
        ob = *out++;
        if (!testable[ob]) continue;
      }
      if (test_bodies(b, box_b, ob)) return true;
    }
  }
  return false;
}

bool in_collision_brute_force(const CollisionModel& model, CollisionData& data,
                              CollisionPair* first) {
  auto& d = data.impl();
  QueryContext ctx{&model.impl(), first, &d};
  for (std::size_t i = 0; i < d.objects.size(); ++i) {
    for (std::size_t j = i + 1; j < d.objects.size(); ++j) {
      if (collide_callback(d.objects[i].get(), d.objects[j].get(), &ctx)) return true;
    }
  }
  return false;
}

bool in_collision_brute_force(const CollisionModel& model, CollisionData& data,
                              const std::vector<int>& bodies, CollisionPair* first) {
  auto& d = data.impl();
  QueryContext ctx{&model.impl(), first, &d};
  std::vector<char> active(model.impl().bodies.size(), 0);
  for (const int b : bodies) active[b] = 1;
  for (std::size_t i = 0; i < d.objects.size(); ++i) {
    for (std::size_t j = i + 1; j < d.objects.size(); ++j) {
      const int a = static_cast<ShapeTag*>(d.objects[i]->getUserData())->body;
      const int b = static_cast<ShapeTag*>(d.objects[j]->getUserData())->body;
      if (!active[a] && !active[b]) continue;
      if (collide_callback(d.objects[i].get(), d.objects[j].get(), &ctx)) return true;
    }
  }
  return false;
}

double min_distance(const CollisionModel& model, CollisionData& data, CollisionPair* closest) {
  auto& d = data.impl();
  refresh(d);
  QueryContext ctx{&model.impl(), closest, &d};
  d.moving_manager.distance(&ctx, distance_callback);
  d.moving_manager.distance(&d.static_manager, &ctx, distance_callback);
  return ctx.min_distance;
}

std::string describe_pair(const CollisionModel& model, const CollisionPair& pair) {
  if (pair.body_a < 0) return "none";
  return model.body_name(pair.body_a) + " <-> " + model.body_name(pair.body_b);
}

RobotBodies add_robot(CollisionModel& model, const RobotModel& robot, const std::string& prefix,
                      bool is_static) {
  RobotBodies bodies;
  bodies.link_to_body.assign(robot.links().size(), -1);
  for (std::size_t l = 0; l < robot.links().size(); ++l) {
    const Link& link = robot.links()[l];
    if (link.collisions.empty()) continue;
    bodies.link_to_body[l] = model.add_body(prefix + link.name, link.collisions, is_static);
  }
  for (std::size_t l = 0; l < robot.links().size(); ++l) {
    if (bodies.link_to_body[l] < 0) continue;
    // Walk up to the nearest ancestor with geometry.
    int link = static_cast<int>(l);
    while (true) {
      const int j = robot.links()[link].parent_joint;
      if (j < 0) break;
      link = robot.joints()[j].parent_link;
      if (bodies.link_to_body[link] >= 0) {
        model.allow(bodies.link_to_body[l], bodies.link_to_body[link]);
        break;
      }
    }
  }
  return bodies;
}

std::vector<int> subtree_bodies(const RobotModel& robot, const RobotBodies& bodies, int root_link) {
  std::vector<int> out;
  std::vector<int> stack{root_link};
  while (!stack.empty()) {
    const int link = stack.back();
    stack.pop_back();
    if (bodies.link_to_body[link] >= 0) out.push_back(bodies.link_to_body[link]);
    for (const int j : robot.links()[link].child_joints)
      stack.push_back(robot.joints()[j].child_link);
  }
  std::sort(out.begin(), out.end());
  return out;
}

std::vector<int> rigid_tip_bodies(const RobotModel& robot, const RobotBodies& bodies,
                                  int tip_link) {
  int link = tip_link;
  while (true) {
    const int j = robot.links()[static_cast<std::size_t>(link)].parent_joint;
    if (j < 0 || robot.joints()[static_cast<std::size_t>(j)].type != JointType::Fixed) break;
    link = robot.joints()[static_cast<std::size_t>(j)].parent_link;
  }
  return subtree_bodies(robot, bodies, link);
}

void set_robot_pose(CollisionData& data, const RobotBodies& bodies,
                    const std::vector<Pose>& link_poses, const Pose& base) {
  for (std::size_t l = 0; l < bodies.link_to_body.size(); ++l) {
    if (bodies.link_to_body[l] >= 0)
      data.set_body_pose(bodies.link_to_body[l], base * link_poses[l]);
  }
}

Attachment attach(CollisionModel& model, int body, int link, const Pose& link_to_body,
                  const std::vector<int>& touching_bodies) {
  for (const int other : touching_bodies) model.allow(body, other);
  return Attachment{body, link, link_to_body};
}

void set_attachment_pose(CollisionData& data, const Attachment& attachment,
                         const std::vector<Pose>& link_poses, const Pose& base) {
  data.set_body_pose(attachment.body, base * link_poses[attachment.link] * attachment.link_to_body);
}

}  // namespace hila::core
