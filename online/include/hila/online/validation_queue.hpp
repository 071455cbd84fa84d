#pragma once

#include <condition_variable>
#include <cstddef>
#include <deque>
#include <mutex>
#include <thread>

#include "hila/core/collision.hpp"
#include "hila/online/validator.hpp"
#include "hila/online/world.hpp"

namespace hila::online {

// Validates motions on a second thread while the caller plans the next ones: the planner uses
// one core and the validator's dense pass is as much work again, so on two cores most of it
// overlaps. Jobs run in submission order. A caller waiting for a report validates the queued
// jobs itself meanwhile (with its own CollisionData), so nothing stands idle at the end. A
// report depends only on its motion (validate_motion poses everything it checks), never on which
// thread made it or when: plans stay deterministic.
class ValidationQueue {
 public:
  // `worker_data` is the worker thread's, `caller_data` the waiting caller's: each from
  // World::make_data(), used by nothing else while the queue lives. Without a thread to be had,
  // the caller validates every job when it waits.
  ValidationQueue(const World& world, const ValidatorSettings& settings,
                  core::CollisionData& worker_data, core::CollisionData& caller_data);
  ~ValidationQueue();
  ValidationQueue(const ValidationQueue&) = delete;
  ValidationQueue& operator=(const ValidationQueue&) = delete;

  // Queues the motion; the job's number for wait().
  std::size_t submit(Motion motion);
  // The job's report once it is done (a reference that stays valid while the queue lives).
  const ValidationReport& wait(std::size_t job);
  // Returns once every job is done: neither thread validates until the next submit().
  void drain();
  // The job's report is no longer wanted: it is not validated unless it already started.
  void discard(std::size_t job);
  // Seconds spent validating so far, on either thread.
  double seconds() const;

 private:
  struct Job {
    Motion motion;
    ValidationReport report;
    bool done = false;
    bool discarded = false;
  };
  void run_worker();
  // Whether a job waits to be started (discarded ones are passed over). Under the lock.
  bool has_next();
  // Validates the first job not yet started; the lock is released meanwhile.
  void run_next(std::unique_lock<std::mutex>& lock, core::CollisionData& data);

  const World& world_;
  ValidatorSettings settings_;
  core::CollisionData& worker_data_;
  core::CollisionData& caller_data_;
  mutable std::mutex mutex_;
  std::condition_variable changed_;
  std::deque<Job> jobs_;     // references to elements stay valid as it grows
  std::size_t next_ = 0;     // the first job not yet started
  std::size_t running_ = 0;  // jobs being validated
  double seconds_ = 0.0;
  bool stopping_ = false;
  std::thread worker_;
};

}  // namespace hila::online
