// What one parallelFor call costs beyond its work: the host ADMM loop makes two per
// iteration, thousands per global step. Each of `threads` chunks sums 4 096 items (a few
// microseconds: long enough for another thread to take it), so against one thread the
// time shows what starting (or waking) the others costs.
#include <benchmark/benchmark.h>

#include <atomic>

#include "core/ParallelFor.h"

namespace {

constexpr std::ptrdiff_t kItemsPerChunk = 4096;

void BM_ParallelForCall(benchmark::State& state) {
  const auto threads = static_cast<int>(state.range(0));
  plano::setCpuThreads(threads);
  std::atomic<long> sum{0};
  for (auto _ : state) {
    plano::parallelFor(threads * kItemsPerChunk, kItemsPerChunk, [&](std::ptrdiff_t begin, std::ptrdiff_t end) {
      long local = 0;
      for (std::ptrdiff_t i = begin; i < end; ++i) local += i * i % 7;
      sum.fetch_add(local, std::memory_order_relaxed);
    });
  }
  benchmark::DoNotOptimize(sum.load());
  plano::setCpuThreads(0);
  state.counters["cpu_threads"] = threads;
}

BENCHMARK(BM_ParallelForCall)->Arg(1)->Arg(2)->Arg(4)->UseRealTime();

}  // namespace
