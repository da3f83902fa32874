#include "core/ParallelFor.h"

#include <algorithm>
#include <atomic>
#include <cstdlib>
#include <exception>
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
  std::vector<std::thread> threads;
  threads.reserve(static_cast<std::size_t>(chunks - 1));
  try {
    for (int chunk = 1; chunk < chunks; ++chunk) threads.emplace_back(run, chunk);
  } catch (const std::system_error&) {
    // No more threads to be had: the chunks without one run here.
    for (int chunk = static_cast<int>(threads.size()) + 1; chunk < chunks; ++chunk) run(chunk);
  }
  run(0);
  for (std::thread& thread : threads) thread.join();
  for (const std::exception_ptr& failure : failures) {
    if (failure) std::rethrow_exception(failure);
  }
}

}  // namespace plano
