#pragma once

#include <condition_variable>
#include <cstddef>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "hila/core/collision.hpp"
#include "hila/online/validator.hpp"
#include "hila/online/world.hpp"

namespace hila::online {

// Validates motions on a second thread while the caller plans the next ones: the planner uses
// one core and the validator's dense pass is as much work again, so on two cores most of it
// overlaps. Jobs run in submission order. A caller waiting for a report validates queued work
// itself meanwhile (with its own CollisionData): whole jobs not yet started, and the parts of a
// started one (MotionValidation) the worker has not taken, so that at the end both threads share
// the last long motion instead of one waiting for the other. A report depends only on its motion
// (validate_motion poses everything it checks), never on which thread checked which part or
// when: plans stay deterministic.
//
// A job may first finish its motion (`Finish`: e.g. smooth the found path and time it) on the
// thread that takes it, so that work leaves the planner's thread as well. The finish gets the
// thread's slot, 0 on the worker and 1 on the caller, for per-thread state it keeps (the
// smoother's validity checks): a slot is used by one thread at a time.
class ValidationQueue {
 public:
  static constexpr std::size_t kWorkerSlot = 0;
  static constexpr std::size_t kCallerSlot = 1;
  using Finish = std::function<void(std::size_t slot, Motion& motion)>;

  // `worker_data` is the worker thread's, `caller_data` the waiting caller's: each from
  // World::make_data(), used by nothing else while the queue lives. Without a thread to be had,
  // the caller validates every job when it waits.
  ValidationQueue(const World& world, const ValidatorSettings& settings,
                  core::CollisionData& worker_data, core::CollisionData& caller_data);
  ~ValidationQueue();
  ValidationQueue(const ValidationQueue&) = delete;
  ValidationQueue& operator=(const ValidationQueue&) = delete;

  // Queues the motion, to be finished by `finish` (when given) before it is validated; the job's
  // number for wait(). `finish` must not throw for want of a valid result (an exception is
  // reported as an "internal" violation).
  std::size_t submit(Motion motion, Finish finish = {});
  // The job's report once it is done (a reference that stays valid while the queue lives).
  const ValidationReport& wait(std::size_t job);
  // Returns once every job is done: neither thread validates until the next submit().
  void drain();
  // Returns once every one of `jobs` is done. Meanwhile the caller works on those of them only,
  // lowest first: it starts the ones not yet started and takes parts of started ones (the
  // worker's too). The jobs it does not wait for stay queued for the worker (the attempts a
  // plan did not use, say, need not hold up the one it did).
  void wait_all(const std::vector<std::size_t>& jobs);
  // The job's report is no longer wanted: one not started is done at once, one started stops
  // after the parts under way; either comes back unvalidated: no samples, and a "discarded"
  // violation, so that it never reads as passed. One already done keeps its report.
  void discard(std::size_t job);
  // Jobs submitted and not yet started, discarded ones left out.
  std::size_t backlog() const;
  // Seconds spent validating so far, on either thread.
  double seconds() const;

 private:
  struct Job {
    Motion motion;
    Finish finish;
    ValidationReport report;
    std::unique_ptr<MotionValidation> check;  // made once finished; its parts are handed out
    std::size_t parts_out = 0;                // parts handed out
    std::size_t parts_done = 0;
    std::string error;       // what threw first, when failed
    bool failed = false;     // a piece threw: no part handed out from now on
    bool started = false;    // taken: being finished, then its parts handed out
    bool discarded = false;  // no part handed out from now on
    bool done = false;
  };
  // Whether the job has work for a thread: its start, or parts not yet handed out. Under the
  // lock.
  static bool has_work(const Job& job);
  // The lowest job with work, or jobs_.size(). Under the lock.
  std::size_t next_work();
  void run_worker();
  // Does one piece of job `index`'s work (has_work): its start (the finish and the
  // MotionValidation), or some of its parts. The lock is released meanwhile.
  void run(std::unique_lock<std::mutex>& lock, std::size_t index, core::CollisionData& data,
           std::size_t slot);
  // The job's report, once nothing of it is under way. Under the lock.
  void complete(Job& job);
  // Records that a piece of the job threw. Under the lock.
  static void fail(Job& job, const std::string& what);

  const World& world_;
  ValidatorSettings settings_;
  core::CollisionData& worker_data_;
  core::CollisionData& caller_data_;
  mutable std::mutex mutex_;
  std::condition_variable changed_;
  std::deque<Job> jobs_;       // references to elements stay valid as it grows
  std::size_t scan_from_ = 0;  // no job before it has work or will have
  std::size_t waiting_ = 0;    // jobs not started and not discarded
  std::size_t running_ = 0;    // pieces of work under way
  double seconds_ = 0.0;
  bool stopping_ = false;
  std::thread worker_;
};

}  // namespace hila::online
