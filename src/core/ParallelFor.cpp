#include "core/ParallelFor.h"

#include <algorithm>
#include <atomic>
#include <condition_variable>
#include <cstdlib>
#include <exception>
#include <mutex>
#include <string>
#include <system_error>
#include <thread>
#include <vector>

#include "core/Error.h"

namespace plano {
namespace {

std::atomic<int> chosenThreads{0};  // 0: the default
constexpr int kMaxThreads = 4096;

int defaultThreads() {
  if (const char* text = std::getenv("PLANO_THREADS"); text != nullptr && *text != '\0') {
    char* end = nullptr;
    const long value = std::strtol(text, &end, 10);
    if (*end != '\0' || value < 1 || value > kMaxThreads) {
      throwUsage("PLANO_THREADS is '" + std::string(text) + "' (need a thread count from 1 to " +
                 std::to_string(kMaxThreads) + ")");
    }
    return static_cast<int>(value);
  }
  return std::max(1u, std::thread::hardware_concurrency());
}

/// Threads kept waiting for parallelFor's chunks: starting a thread per chunk and call cost
/// tens of microseconds of system time each, and the host ADMM loop calls parallelFor twice
/// per iteration, thousands of times per global step (Enneper's level: ~1 s of system
/// time in 13 s). One job at a time: a call made while another runs (another thread's,
/// or one from inside a chunk) starts threads of its own instead (runOnOwnThreads).
class WorkerPool {
 public:
  static WorkerPool& instance() {
    static WorkerPool pool;
    return pool;
  }

  ~WorkerPool() {
    {
      const std::lock_guard<std::mutex> lock(mutex_);
      stopping_ = true;
    }
    wake_.notify_all();
    for (std::thread& worker : workers_) worker.join();
  }

  /// task(1) .. task(chunks - 1) on the workers and task(0) here; returns when all are
  /// done. False (nothing run) when the pool is busy with another job. task must not throw.
  bool tryRun(int chunks, const std::function<void(int)>& task) {
    // A call from inside a job's chunk (here or on a worker) must not wait for the pool.
    if (insideJob) return false;
    const std::unique_lock<std::mutex> job(jobMutex_, std::try_to_lock);
    if (!job.owns_lock()) return false;
    insideJob = true;
    struct Leave {
      ~Leave() { insideJob = false; }
    } leave;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      // Workers as needed, kept after; with none to be had the chunks run here.
      try {
        while (static_cast<int>(workers_.size()) < chunks - 1) workers_.emplace_back([this] { work(); });
      } catch (const std::system_error&) {
      }
      task_ = &task;
      next_ = 1;
      end_ = chunks;
      unfinished_ = chunks - 1;
    }
    wake_.notify_all();
    task(0);
    // Chunks no worker has taken yet run here too.
    std::unique_lock<std::mutex> lock(mutex_);
    while (next_ < end_) {
      const int chunk = next_++;
      lock.unlock();
      task(chunk);
      lock.lock();
      --unfinished_;
    }
    finished_.wait(lock, [this] { return unfinished_ == 0; });
    task_ = nullptr;
    return true;
  }

 private:
  WorkerPool() = default;

  void work() {
    insideJob = true;
    std::unique_lock<std::mutex> lock(mutex_);
    for (;;) {
      wake_.wait(lock, [this] { return stopping_ || next_ < end_; });
      if (stopping_) return;
      const int chunk = next_++;
      const std::function<void(int)>* task = task_;
      lock.unlock();
      (*task)(chunk);
      lock.lock();
      if (--unfinished_ == 0) finished_.notify_all();
    }
  }

  /// This thread runs a job's chunks: the pool's workers, and a caller during its job.
  static thread_local bool insideJob;
  std::mutex jobMutex_;  ///< Held by the call whose job the pool runs.
  std::mutex mutex_;     ///< Guards everything below.
  std::condition_variable wake_, finished_;
  std::vector<std::thread> workers_;
  const std::function<void(int)>* task_ = nullptr;
  int next_ = 0, end_ = 0;  ///< Chunks next_ .. end_ - 1 are not taken yet.
  int unfinished_ = 0;      ///< Chunks 1 .. end_ - 1 not finished.
  bool stopping_ = false;
};

thread_local bool WorkerPool::insideJob = false;

/// task(0) here and the other chunks on threads started for this call.
void runOnOwnThreads(int chunks, const std::function<void(int)>& task) {
  std::vector<std::thread> threads;
  threads.reserve(static_cast<std::size_t>(chunks - 1));
  try {
    for (int chunk = 1; chunk < chunks; ++chunk) threads.emplace_back(task, chunk);
  } catch (const std::system_error&) {
    // No more threads to be had: the chunks without one run here.
    for (int chunk = static_cast<int>(threads.size()) + 1; chunk < chunks; ++chunk) task(chunk);
  }
  task(0);
  for (std::thread& thread : threads) thread.join();
}

}  // namespace

int cpuThreads() {
  const int chosen = chosenThreads.load(std::memory_order_relaxed);
  return chosen > 0 ? chosen : defaultThreads();
}

void setCpuThreads(int threads) {
  if (threads < 0 || threads > kMaxThreads) {
    throwUsage("a CPU thread count of " + std::to_string(threads) + " (need 1 to " + std::to_string(kMaxThreads) +
               ", or 0 for the default)");
  }
  chosenThreads.store(threads, std::memory_order_relaxed);
}

void parallelFor(std::ptrdiff_t count, std::ptrdiff_t minimumChunk,
                 const std::function<void(std::ptrdiff_t, std::ptrdiff_t)>& body) {
  if (count <= 0) return;
  const std::ptrdiff_t byWork = count / std::max<std::ptrdiff_t>(minimumChunk, 1);
  const auto chunks = static_cast<int>(std::clamp<std::ptrdiff_t>(byWork, 1, cpuThreads()));
  if (chunks == 1) {
    body(0, count);
    return;
  }
  const auto bound = [&](int chunk) { return count * chunk / chunks; };
  std::vector<std::exception_ptr> failures(static_cast<std::size_t>(chunks));
  const auto run = [&](int chunk) {
    try {
      body(bound(chunk), bound(chunk + 1));
    } catch (...) {
      failures[static_cast<std::size_t>(chunk)] = std::current_exception();
    }
  };
  const std::function<void(int)> task = run;
  if (!WorkerPool::instance().tryRun(chunks, task)) runOnOwnThreads(chunks, task);
  for (const std::exception_ptr& failure : failures) {
    if (failure) std::rethrow_exception(failure);
  }
}

}  // namespace plano
