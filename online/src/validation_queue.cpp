#include "hila/online/validation_queue.hpp"

#include <algorithm>
#include <cassert>
#include <chrono>
#include <exception>
#include <memory>
#include <optional>
#include <system_error>
#include <utility>

namespace hila::online {

namespace {

// What a piece of work threw, never empty: an empty message must still count as a failure.
std::string describe_current_exception() {
  try {
    throw;
  } catch (const std::exception& e) {
    return *e.what() != '\0' ? e.what() : "an exception without a message";
  } catch (...) {
    return "an exception of unknown type";
  }
}

}  // namespace

ValidationQueue::ValidationQueue(const World& world, const ValidatorSettings& settings,
                                 core::CollisionData& worker_data, core::CollisionData& caller_data)
    : world_(world), settings_(settings), worker_data_(worker_data), caller_data_(caller_data) {
  try {
    worker_ = std::thread([this] { run_worker(); });
  } catch (const std::system_error&) {
    // No second thread: wait() validates everything on the caller's.
  }
}

ValidationQueue::~ValidationQueue() {
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    stopping_ = true;
  }
  changed_.notify_all();
  if (worker_.joinable()) worker_.join();
}

std::size_t ValidationQueue::submit(Motion motion, Finish finish) {
  std::size_t job = 0;
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    job = jobs_.size();
    Job& added = jobs_.emplace_back();
    added.motion = std::move(motion);
    added.finish = std::move(finish);
    ++waiting_;
  }
  changed_.notify_all();
  return job;
}

void ValidationQueue::wait_all(const std::vector<std::size_t>& jobs) {
  std::unique_lock<std::mutex> lock(mutex_);
  for (;;) {
    std::size_t first = jobs_.size();  // the lowest waited-for job with work
    bool all_done = true;
    for (const std::size_t j : jobs) {
      assert(j < jobs_.size());
      const Job& job = jobs_[j];
      if (job.done) continue;
      all_done = false;
      if (has_work(job)) first = std::min(first, j);
    }
    if (all_done) return;
    if (first < jobs_.size()) {
      run(lock, first, caller_data_, kCallerSlot);
    } else {
      changed_.wait(lock);  // the worker has the rest under way
    }
  }
}

const ValidationReport& ValidationQueue::wait(std::size_t job) {
  std::unique_lock<std::mutex> lock(mutex_);
  assert(job < jobs_.size());
  while (!jobs_[job].done) {
    const std::size_t next = next_work();
    if (next < jobs_.size()) {
      run(lock, next, caller_data_, kCallerSlot);
    } else {
      changed_.wait(lock);
    }
  }
  return jobs_[job].report;
}

void ValidationQueue::drain() {
  std::unique_lock<std::mutex> lock(mutex_);
  for (;;) {
    const std::size_t next = next_work();
    if (next < jobs_.size()) {
      run(lock, next, caller_data_, kCallerSlot);
    } else if (running_ > 0) {
      changed_.wait(lock);
    } else {
      return;
    }
  }
}

void ValidationQueue::discard(std::size_t job) {
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    assert(job < jobs_.size());
    Job& j = jobs_[job];
    if (!j.done && !j.discarded) {
      j.discarded = true;  // has_work() no longer hands out any of it
      if (!j.started) {    // no longer waiting (backlog()), never to be run
        j.started = true;
        --waiting_;
        complete(j);
      } else if (j.check && j.parts_done == j.parts_out) {
        complete(j);
      }  // else its start or a part is under way, and completes it when done
    }
  }
  changed_.notify_all();
}

bool ValidationQueue::has_work(const Job& job) {
  // A job that failed (job.failed) is not valid whatever its other parts find.
  if (job.done || job.discarded || job.failed) return false;
  if (!job.started) return true;
  return job.check && job.parts_out < job.check->parts();
}

std::size_t ValidationQueue::next_work() {
  // Jobs before scan_from_ are done or have every part handed out.
  while (scan_from_ < jobs_.size()) {
    const Job& job = jobs_[scan_from_];
    const bool spent = job.done || job.discarded || job.failed ||
                       (job.check && job.parts_out == job.check->parts());
    if (!spent) break;
    ++scan_from_;
  }
  for (std::size_t j = scan_from_; j < jobs_.size(); ++j) {
    if (has_work(jobs_[j])) return j;
  }
  return jobs_.size();
}

std::size_t ValidationQueue::backlog() const {
  const std::lock_guard<std::mutex> lock(mutex_);
  return waiting_;
}

double ValidationQueue::seconds() const {
  const std::lock_guard<std::mutex> lock(mutex_);
  return seconds_;
}

void ValidationQueue::run_worker() {
  std::unique_lock<std::mutex> lock(mutex_);
  for (;;) {
    std::size_t next = jobs_.size();
    changed_.wait(lock, [&] {
      if (stopping_) return true;
      next = next_work();
      return next < jobs_.size();
    });
    if (stopping_) return;
    run(lock, next, worker_data_, kWorkerSlot);
  }
}

void ValidationQueue::fail(Job& job, const std::string& what) {
  if (!job.failed) job.error = what;  // the first failure's
  job.failed = true;
}

void ValidationQueue::complete(Job& job) {
  if (job.discarded) {
    // Not validated: a report that says so, never one that passes.
    job.report = {};
    job.report.violations.push_back({"discarded", 0.0, "not validated: the job was discarded"});
  } else if (job.failed) {
    // Out of memory, say: the motion is not known to be valid, so it is not.
    job.report = {};
    job.report.violations.push_back({"internal", 0.0, job.error});
  } else {
    job.report = job.check->report();
  }
  job.check.reset();  // the samples are no longer needed
  job.done = true;
}

void ValidationQueue::run(std::unique_lock<std::mutex>& lock, std::size_t index,
                          core::CollisionData& data, std::size_t slot) {
  Job& job = jobs_[index];
  assert(has_work(job));
  ++running_;
  if (!job.started) {
    // Its start: the finish, then the samples made; its parts follow, taken by either thread.
    job.started = true;
    --waiting_;
    lock.unlock();
    double took = 0.0;
    std::optional<std::string> error;
    std::unique_ptr<MotionValidation> made;  // handed to the job under the lock
    try {
      if (job.finish) job.finish(slot, job.motion);
      const auto started = std::chrono::steady_clock::now();  // seconds() counts validation only
      made = std::make_unique<MotionValidation>(world_, job.motion, settings_);
      took = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
    } catch (...) {
      error = describe_current_exception();
    }
    lock.lock();
    --running_;
    seconds_ += took;
    job.check = std::move(made);
    if (error) fail(job, *error);
    if (job.failed || job.discarded || job.check->parts() == 0) complete(job);
    changed_.notify_all();
    return;
  }
  // A quarter of the parts left (at least one): a thread alone on a long motion poses the robot
  // a few times rather than once per part, and another thread arriving still finds parts.
  const std::size_t left = job.check->parts() - job.parts_out;
  const std::size_t first = job.parts_out;
  const std::size_t last = first + std::max<std::size_t>(1, (left + 3) / 4);
  job.parts_out = last;
  lock.unlock();
  const auto started = std::chrono::steady_clock::now();
  std::optional<std::string> error;
  try {
    job.check->check_parts(first, last, data);
  } catch (...) {
    error = describe_current_exception();
  }
  const double took =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  lock.lock();
  --running_;
  seconds_ += took;
  if (error) fail(job, *error);
  job.parts_done += last - first;
  // Done once nothing of it is under way and nothing more is handed out.
  if (job.parts_done == job.parts_out &&
      (job.discarded || job.failed || job.parts_out == job.check->parts())) {
    complete(job);
  }
  changed_.notify_all();
}

}  // namespace hila::online
