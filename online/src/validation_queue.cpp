#include "hila/online/validation_queue.hpp"

#include <cassert>
#include <chrono>
#include <exception>
#include <system_error>
#include <utility>

namespace hila::online {

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
    jobs_.push_back({std::move(motion), std::move(finish), {}, false, false});
    ++waiting_;
  }
  changed_.notify_all();
  return job;
}

void ValidationQueue::wait_all(const std::vector<std::size_t>& jobs) {
  std::unique_lock<std::mutex> lock(mutex_);
  for (;;) {
    std::size_t first = jobs_.size();  // the lowest waited-for job not started
    bool all_done = true;
    for (const std::size_t j : jobs) {
      assert(j < jobs_.size());
      const Job& job = jobs_[j];
      if (job.done) continue;
      all_done = false;
      if (!job.started) first = std::min(first, j);
    }
    if (all_done) return;
    if (first < jobs_.size()) {
      run(lock, first, caller_data_, kCallerSlot);
    } else {
      changed_.wait(lock);  // the worker has the rest
    }
  }
}

const ValidationReport& ValidationQueue::wait(std::size_t job) {
  std::unique_lock<std::mutex> lock(mutex_);
  assert(job < jobs_.size());
  while (!jobs_[job].done) {
    if (has_next()) {
      run_next(lock, caller_data_, kCallerSlot);
    } else {
      changed_.wait(lock);
    }
  }
  return jobs_[job].report;
}

void ValidationQueue::drain() {
  std::unique_lock<std::mutex> lock(mutex_);
  for (;;) {
    if (has_next()) {
      run_next(lock, caller_data_, kCallerSlot);
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
    if (!j.started) {  // done, unvalidated: no longer waiting (backlog()), never to be run
      j.started = true;
      j.done = true;
      --waiting_;
    }
  }
  changed_.notify_all();
}

bool ValidationQueue::has_next() {
  while (next_ < jobs_.size() && jobs_[next_].started) ++next_;
  return next_ < jobs_.size();
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
    changed_.wait(lock, [this] { return stopping_ || has_next(); });
    if (stopping_) return;
    run_next(lock, worker_data_, kWorkerSlot);
  }
}

void ValidationQueue::run_next(std::unique_lock<std::mutex>& lock, core::CollisionData& data,
                               std::size_t slot) {
  run(lock, next_, data, slot);
}

void ValidationQueue::run(std::unique_lock<std::mutex>& lock, std::size_t index,
                          core::CollisionData& data, std::size_t slot) {
  Job& job = jobs_[index];
  assert(!job.started);
  job.started = true;
  --waiting_;
  ++running_;
  lock.unlock();
  auto started = std::chrono::steady_clock::now();
  ValidationReport report;
  try {
    if (job.finish) {
      job.finish(slot, job.motion);
      started = std::chrono::steady_clock::now();  // seconds() counts the validation only
    }
    report = validate_motion(world_, data, job.motion, settings_);
  } catch (const std::exception& e) {
    // Out of memory, say: the motion is not known to be valid, so it is not.
    report.violations.push_back({"internal", 0.0, e.what()});
  }
  const double took =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  lock.lock();
  job.report = std::move(report);
  job.done = true;
  --running_;
  seconds_ += took;
  changed_.notify_all();
}

}  // namespace hila::online
