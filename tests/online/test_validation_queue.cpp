#include <gtest/gtest.h>

#include <array>
#include <atomic>
#include <stdexcept>

#include "hila/core/product.hpp"
#include "hila/online/validation_queue.hpp"
#include "util/test_util.hpp"

using namespace hila;

namespace {

const core::ProductSpec& cabinet() {
  static const core::ProductSpec product = core::load_product(test::product_path());
  return product;
}

std::string describe(const online::ValidationReport& r) {
  std::string out = std::to_string(r.samples) + " samples; ";
  for (const auto& v : r.violations) {
    out += v.kind + " @" + std::to_string(v.time) + ": " + v.detail + "; ";
  }
  return out;
}

struct Fixture {
  std::shared_ptr<const core::Cell> cell = test::reference_cell();
  online::Scene scene = online::nominal_scene(*cell, cabinet());
  online::World world{*cell, cabinet(), scene, "top"};
  const core::Arm& left = cell->arm("left");

  // The left arm's first IK solution for a TCP pointing down at `p` (world).
  Eigen::VectorXd left_at(const Eigen::Vector3d& p) const {
    return test::arm_pointing_down_at(*cell, left, p);
  }

  // Slow straight motions of the left arm, some into the table (1.094 m), one with a joint jump.
  std::vector<online::Motion> motions() const {
    const Eigen::VectorXd above = left_at({0.40, 0.20, 1.30});
    const Eigen::VectorXd inside = left_at({0.40, 0.20, 1.084});
    const Eigen::VectorXd aside = left_at({0.30, 0.30, 1.25});
    std::vector<std::vector<Eigen::VectorXd>> paths = {{left.spec.home, above},
                                                       {above, inside},
                                                       {above, aside, above},
                                                       {left.spec.home, above, inside, above},
                                                       {aside, left.spec.home}};
    std::vector<online::Motion> out;
    for (const auto& q : paths) {
      online::Motion m;
      m.arm = "left";
      m.q = q;
      for (std::size_t i = 0; i < q.size(); ++i) m.time.push_back(4.0 * static_cast<double>(i));
      m.robot_q = cell->home_configuration();
      m.board_world = cabinet().part("top").initial;
      out.push_back(m);
    }
    out.back().time.back() = 0.01;  // a jump
    return out;
  }
};

}  // namespace

// Whichever thread validates a job (the worker, or the caller helping while it waits), its
// report is the one validate_motion gives for the motion alone.
TEST(ValidationQueue, ReportsAreThoseOfTheMotionValidatedAlone) {
  Fixture f;
  const auto motions = f.motions();
  std::vector<std::string> alone;
  core::CollisionData data = f.world.make_data();
  for (const auto& m : motions)
    alone.push_back(describe(online::validate_motion(f.world, data, m)));
  int invalid = 0;
  for (const auto& a : alone) invalid += a.find('@') != std::string::npos ? 1 : 0;
  ASSERT_GE(invalid, 2) << "the table and the jump must be caught";
  ASSERT_LT(invalid, static_cast<int>(motions.size())) << "and the clear motions pass";

  core::CollisionData worker = f.world.make_data();
  core::CollisionData caller = f.world.make_data();
  online::ValidationQueue queue(f.world, {}, worker, caller);
  // Three rounds of every motion: the later ones find both threads' data posed by earlier jobs.
  std::vector<std::size_t> jobs;
  for (int round = 0; round < 3; ++round) {
    for (const auto& m : motions) jobs.push_back(queue.submit(m));
  }
  // Waited for from the last: the caller validates whatever is still queued meanwhile.
  for (std::size_t i = jobs.size(); i-- > 0;) {
    EXPECT_EQ(describe(queue.wait(jobs[i])), alone[i % motions.size()]) << "job " << i;
  }
  EXPECT_GT(queue.seconds(), 0.0);
}

TEST(ValidationQueue, DiscardedJobsAreNotValidatedAndDrainWaitsForTheRest) {
  Fixture f;
  const auto motions = f.motions();
  core::CollisionData worker = f.world.make_data();
  core::CollisionData caller = f.world.make_data();
  online::ValidationQueue queue(f.world, {}, worker, caller);
  std::vector<std::size_t> jobs;
  for (const auto& m : motions) jobs.push_back(queue.submit(m));
  // Discarded straight away: unless the worker already finished it, it is not validated (no
  // samples, and a "discarded" violation: it never reads as passed), and it no longer counts as
  // waiting.
  const std::size_t before = queue.backlog();
  queue.discard(jobs.back());
  EXPECT_LE(queue.backlog() + 1, std::max<std::size_t>(before, 1));
  queue.drain();
  for (std::size_t i = 0; i + 1 < jobs.size(); ++i) {
    EXPECT_GT(queue.wait(jobs[i]).samples, 0) << "job " << i << " was validated";
  }
  const auto& discarded = queue.wait(jobs.back());
  if (discarded.samples == 0) {
    ASSERT_EQ(discarded.violations.size(), 1u);
    EXPECT_EQ(discarded.violations.front().kind, "discarded");
    EXPECT_FALSE(discarded.valid());
  }
  // After a drain the queue takes new work as before.
  const std::size_t again = queue.submit(motions.front());
  EXPECT_EQ(describe(queue.wait(again)),
            describe(online::validate_motion(f.world, caller, motions.front())));
}

// A job's finish (the board planner's smoothing and timing) runs once, before the validation,
// on the thread that validates the job, with that thread's slot; the report is the one the
// finished motion gets validated alone. A finish that throws is a violation, not a crash,
// whatever it throws.
TEST(ValidationQueue, AFinishCompletesTheMotionOnTheThreadThatValidatesIt) {
  Fixture f;
  const auto motions = f.motions();
  core::CollisionData alone_data = f.world.make_data();
  std::vector<std::string> alone;
  for (const auto& m : motions) {
    alone.push_back(describe(online::validate_motion(f.world, alone_data, m)));
  }
  core::CollisionData worker = f.world.make_data();
  core::CollisionData caller = f.world.make_data();
  online::ValidationQueue queue(f.world, {}, worker, caller);
  constexpr int kRounds = 3;
  std::vector<std::atomic<int>> calls(motions.size() * kRounds);
  std::array<std::atomic<int>, 2> by_slot{};
  std::atomic<int> bad_slot{0};
  std::vector<std::size_t> jobs;
  for (int round = 0; round < kRounds; ++round) {
    for (std::size_t i = 0; i < motions.size(); ++i) {
      online::Motion frame = motions[i];
      frame.q.clear();  // only the finish knows the trajectory
      frame.time.clear();
      const std::size_t index = jobs.size();
      jobs.push_back(queue.submit(frame, [&, i, index](std::size_t slot, online::Motion& m) {
        ++calls[index];
        if (slot > 1) {
          ++bad_slot;
        } else {
          ++by_slot[slot];
        }
        m.q = motions[i].q;
        m.time = motions[i].time;
      }));
    }
  }
  const std::size_t failing = queue.submit(motions.front(), [](std::size_t, online::Motion&) {
    throw std::runtime_error("no memory left");
  });
  for (std::size_t i = jobs.size(); i-- > 0;) {
    EXPECT_EQ(describe(queue.wait(jobs[i])), alone[i % motions.size()]) << "job " << i;
    EXPECT_EQ(calls[i].load(), 1) << "job " << i;
  }
  EXPECT_EQ(bad_slot.load(), 0);
  EXPECT_EQ(by_slot[0] + by_slot[1], static_cast<int>(jobs.size()));
  const auto& report = queue.wait(failing);
  ASSERT_EQ(report.violations.size(), 1u);
  EXPECT_EQ(report.violations.front().kind, "internal");
  EXPECT_NE(report.violations.front().detail.find("no memory left"), std::string::npos);
  // Nor does an exception without a message pass, or one that is not a std::exception.
  const std::size_t silent = queue.submit(
      motions.front(), [](std::size_t, online::Motion&) { throw std::runtime_error(""); });
  const std::size_t odd =
      queue.submit(motions.front(), [](std::size_t, online::Motion&) { throw 42; });
  for (const std::size_t job : {silent, odd}) {
    const auto& r = queue.wait(job);
    ASSERT_EQ(r.violations.size(), 1u) << "job " << job;
    EXPECT_EQ(r.violations.front().kind, "internal");
    EXPECT_FALSE(r.violations.front().detail.empty());
  }
  queue.drain();
}

// wait_all: the jobs waited for come back with the reports they have alone; the caller runs
// only those (each job's finish records the slot that ran it), the rest stay with the worker,
// and a waited-for job discarded before it started comes back unvalidated instead of hanging.
TEST(ValidationQueue, WaitAllRunsOnlyTheJobsItWaitsFor) {
  Fixture f;
  const auto motions = f.motions();
  core::CollisionData data = f.world.make_data();
  std::vector<std::string> alone;
  for (const auto& m : motions)
    alone.push_back(describe(online::validate_motion(f.world, data, m)));

  core::CollisionData worker = f.world.make_data();
  core::CollisionData caller = f.world.make_data();
  online::ValidationQueue queue(f.world, {}, worker, caller);
  constexpr int kRounds = 4;
  std::vector<std::atomic<int>> ran_on(kRounds * motions.size());
  for (auto& r : ran_on) r = -1;
  std::vector<std::size_t> jobs;
  for (int round = 0; round < kRounds; ++round) {
    for (std::size_t i = 0; i < motions.size(); ++i) {
      const std::size_t n = jobs.size();
      jobs.push_back(queue.submit(motions[i], [&ran_on, n](std::size_t slot, online::Motion&) {
        ran_on[n] = static_cast<int>(slot);
      }));
    }
  }
  // The last round's, and one of them discarded straight away.
  std::vector<std::size_t> wanted(jobs.end() - static_cast<std::ptrdiff_t>(motions.size()),
                                  jobs.end());
  queue.discard(wanted.front());
  queue.wait_all(wanted);
  // Done when it returns (each job's finish runs before its validation), not left to wait().
  for (std::size_t k = 1; k < wanted.size(); ++k) {
    EXPECT_NE(ran_on[wanted[k]].load(), -1) << "job " << wanted[k] << " was not run";
  }
  for (std::size_t k = 1; k < wanted.size(); ++k) {
    EXPECT_EQ(describe(queue.wait(wanted[k])), alone[k]) << "job " << wanted[k];
  }
  const auto& discarded = queue.wait(wanted.front());
  if (discarded.samples == 0) {
    ASSERT_EQ(discarded.violations.size(), 1u);
    EXPECT_EQ(discarded.violations.front().kind, "discarded");
  }
  for (std::size_t j = 0; j + motions.size() < jobs.size(); ++j) {
    EXPECT_NE(ran_on[j].load(), static_cast<int>(online::ValidationQueue::kCallerSlot))
        << "job " << j << " was not waited for, yet the caller ran it";
  }
  // The rest are still validated, by the worker or by a later wait.
  for (std::size_t j = 0; j + motions.size() < jobs.size(); ++j) {
    EXPECT_EQ(describe(queue.wait(jobs[j])), alone[j % motions.size()]) << "job " << j;
  }
}

// Long motions (several MotionValidation parts each), one into the table late in its path: the
// caller waiting for the last job takes parts of whatever the worker has started. Each report is
// the motion's alone, however the parts were shared; a long job discarded after it started
// comes back unvalidated (reported as discarded) or whole, never half-validated, and the queue
// goes on.
TEST(ValidationQueue, ALongMotionsPartsSharedByBothThreadsGiveItsReport) {
  Fixture f;
  const Eigen::VectorXd above = f.left_at({0.40, 0.20, 1.30});
  const Eigen::VectorXd inside = f.left_at({0.40, 0.20, 1.084});
  std::vector<online::Motion> motions;
  for (const auto& path : std::vector<std::vector<Eigen::VectorXd>>{
           {f.left.spec.home, above, f.left.spec.home, above, inside},
           {f.left.spec.home, above, f.left.spec.home, above, f.left.spec.home, above}}) {
    online::Motion m = f.motions().front();
    m.q = path;
    m.time.clear();
    for (std::size_t i = 0; i < path.size(); ++i) m.time.push_back(4.0 * static_cast<double>(i));
    motions.push_back(m);
  }
  core::CollisionData data = f.world.make_data();
  std::vector<std::string> alone;
  for (const auto& m : motions) {
    const auto report = online::validate_motion(f.world, data, m);
    ASSERT_GE(report.samples, static_cast<int>(3 * online::MotionValidation::kPartSamples));
    alone.push_back(describe(report));
  }
  ASSERT_NE(alone[0].find("collision"), std::string::npos) << alone[0];
  ASSERT_EQ(alone[1].find('@'), std::string::npos) << alone[1];

  core::CollisionData worker = f.world.make_data();
  core::CollisionData caller = f.world.make_data();
  online::ValidationQueue queue(f.world, {}, worker, caller);
  for (int round = 0; round < 6; ++round) {
    std::vector<std::size_t> jobs;
    for (int k = 0; k < 3; ++k) {
      for (const auto& m : motions) jobs.push_back(queue.submit(m));
    }
    if (round % 2 == 1) {
      queue.discard(jobs[1]);  // likely under way on the worker by now
      const auto& r = queue.wait(jobs[1]);
      EXPECT_TRUE(r.samples == 0 ? !r.valid() && r.violations.front().kind == "discarded"
                                 : describe(r) == alone[1])
          << describe(r);
      jobs.erase(jobs.begin() + 1);
    }
    queue.wait_all({jobs.back()});
    for (std::size_t i = 0; i < jobs.size(); ++i) {
      const std::size_t which = round % 2 == 1 && i >= 1 ? (i + 1) % 2 : i % 2;
      EXPECT_EQ(describe(queue.wait(jobs[i])), alone[which]) << "round " << round << " job " << i;
    }
  }
  queue.drain();
  EXPECT_EQ(queue.backlog(), 0u);
}
