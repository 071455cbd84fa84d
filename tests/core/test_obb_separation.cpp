#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <random>

#include "hila/core/internal/obb_separation.hpp"

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

// The cached axis is tested alone, from only the rotation entries it reads: the same inequality
// as the full test's (the reference below builds the whole relative rotation first), for every
// axis, separating or not.
TEST(ObbSeparation, SingleAxisTestMatchesTheFullRotation) {
  std::mt19937_64 rng(17);
  int separating = 0;
  for (int n = 0; n < 5000; ++n) {
    const fcl::OBBd p = random_box(rng, 0.5);
    const fcl::OBBd q = random_box(rng, 0.5);
    const Eigen::Vector3d d = q.To - p.To;
    const Eigen::Vector3d t = p.axis.transpose() * d;
    const Eigen::Matrix3d r = p.axis.transpose() * q.axis;
    const Eigen::Matrix3d f = r.cwiseAbs().array() + 1e-6;
    const Eigen::Vector3d& a = p.extent;
    const Eigen::Vector3d& b = q.extent;
    for (int axis = 0; axis < 15; ++axis) {
      double lhs = 0.0;
      double rhs = 0.0;
      if (axis < 3) {
        lhs = std::abs(t[axis]);
        rhs = a[axis] + f.row(axis).dot(b);
      } else if (axis < 6) {
        const int j = axis - 3;
        lhs = std::abs(r.col(j).dot(t));
        rhs = b[j] + f.col(j).dot(a);
      } else {
        const int i = (axis - 6) / 3;
        const int j = (axis - 6) % 3;
        const int i1 = (i + 1) % 3, i2 = (i + 2) % 3, j1 = (j + 1) % 3, j2 = (j + 2) % 3;
        lhs = std::abs(t[i2] * r(i1, j) - t[i1] * r(i2, j));
        rhs = a[i1] * f(i2, j) + a[i2] * f(i1, j) + b[j1] * f(i, j2) + b[j2] * f(i, j1);
      }
      if (std::abs(lhs - rhs) < 1e-12) continue;  // a tie: rounding may go either way
      const bool expected = lhs > rhs;
      separating += expected;
      EXPECT_EQ(hila::core::axis_separates(p, q, t, axis), expected)
          << "pair " << n << ", axis " << axis;
    }
  }
  EXPECT_GT(separating, 10000);
}
