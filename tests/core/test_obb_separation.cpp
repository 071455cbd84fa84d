#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <random>

#include "hila/core/obb_separation.hpp"

using hila::core::separating_axis;

namespace {

Eigen::Matrix3d random_rotation(std::mt19937_64& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  return Eigen::Quaterniond(n(rng), n(rng), n(rng), n(rng)).normalized().toRotationMatrix();
}

fcl::OBBd random_box(std::mt19937_64& rng, double spread) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::uniform_real_distribution<double> size(0.005, 0.3);
  fcl::OBBd box;
  box.axis = random_rotation(rng);
  box.To = spread * Eigen::Vector3d(u(rng), u(rng), u(rng));
  box.extent = Eigen::Vector3d(size(rng), size(rng), size(rng));
  return box;
}

}  // namespace

// Against fcl::OBB::overlap, for every axis tried first: the same verdict, and the returned
// axis really separates (it separates again when tried first).
TEST(ObbSeparation, SameVerdictAsFclWhicheverAxisIsTriedFirst) {
  std::mt19937_64 rng(11);
  int disjoint = 0;
  int overlapping = 0;
  for (int n = 0; n < 20000; ++n) {
    const fcl::OBBd p = random_box(rng, 0.5);
    const fcl::OBBd q = random_box(rng, 0.5);
    const bool fcl_overlap = p.overlap(q);
    (fcl_overlap ? overlapping : disjoint) += 1;
    for (int first = -1; first < 15; ++first) {
      const int axis = separating_axis(p, q, first);
      ASSERT_EQ(axis < 0, fcl_overlap) << "pair " << n << ", axis " << first << " first";
      if (axis >= 0) {
        EXPECT_EQ(separating_axis(p, q, axis), axis);
      }
    }
  }
  // Both verdicts well represented.
  EXPECT_GT(disjoint, 2000);
  EXPECT_GT(overlapping, 2000);
}

// Boxes slid into contact along a random direction in small steps, the way a motion's samples
// move them: the verdict flips where FCL's does, and a cached axis keeps separating until then.
TEST(ObbSeparation, SameVerdictAsFclAlongApproaches) {
  std::mt19937_64 rng(5);
  int cached_hits = 0;
  int tests = 0;
  for (int n = 0; n < 500; ++n) {
    fcl::OBBd p = random_box(rng, 0.0);
    fcl::OBBd q = random_box(rng, 0.0);
    const Eigen::Vector3d away = random_rotation(rng).col(0);
    const Eigen::AngleAxisd turn(0.002, random_rotation(rng).col(1));
    int last = 0;
    for (int step = 0; step < 400; ++step) {
      q.To = p.To + away * (1.2 - 0.003 * step);
      q.axis = turn.toRotationMatrix() * q.axis;
      const int axis = separating_axis(p, q, last);
      ASSERT_EQ(axis < 0, p.overlap(q)) << "approach " << n << ", step " << step;
      ++tests;
      if (axis >= 0) {
        cached_hits += axis == last ? 1 : 0;
        last = axis;
      }
    }
  }
  // The point of the cache: consecutive poses are mostly separated by the same axis.
  EXPECT_GT(cached_hits, tests / 2);
}
