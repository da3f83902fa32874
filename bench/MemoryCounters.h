#pragma once
// Memory counters of one benchmark: how much host memory its run needed (the growth of
// the peak resident set over the run: Linux's VmHWM, reset at the start through
// /proc/self/clear_refs) and, on the Vulkan backend, the peak of the device allocations
// the backend made during the run. Both in MiB; a counter that cannot be measured is left
// out rather than reported as zero. On Vulkan also the host <-> device copies per iteration
// of the benchmark loop (`uploaded_KiB`, `downloaded_KiB`, and `transfers`, their number:
// each one a synchronisation with the device), what a loop meant to stay on the device
// still moves; counted from construction or from markLoopStart().
#include <benchmark/benchmark.h>

#include <algorithm>
#include <fstream>
#include <optional>
#include <string>

#include "compute/Backend.h"
#include "compute/vulkan/VulkanBackend.h"
#include "compute/vulkan/VulkanContext.h"

namespace plano::bench {

/// A field of /proc/self/status in KiB ("VmRSS", "VmHWM"), when readable.
inline std::optional<double> procStatusKiB(const std::string& field) {
  std::ifstream status("/proc/self/status");
  std::string line;
  while (std::getline(status, line)) {
    if (line.rfind(field + ":", 0) == 0) return std::stod(line.substr(field.size() + 1));
  }
  return std::nullopt;
}

/// Declare at the top of a benchmark body; sets the counters when the body ends.
class MemoryCounters {
 public:
  explicit MemoryCounters(benchmark::State& state, compute::Backend* backend = nullptr)
      : state_(state), vulkan_(dynamic_cast<compute::VulkanBackend*>(backend)) {
    std::ofstream clear("/proc/self/clear_refs");
    clear << "5";  // resets VmHWM to the current resident set
    clear.close();
    if (clear) startKiB_ = procStatusKiB("VmRSS");
    if (vulkan_) {
      vulkan_->context().resetPeakAllocatedBytes();
      transfersBefore_ = vulkan_->context().transfers();
    }
  }
  /// Count transfers from here on: call right before the benchmark loop when the set-up
  /// uploads (a solver's matrices) should not be averaged into the loop's figures.
  void markLoopStart() {
    if (vulkan_) transfersBefore_ = vulkan_->context().transfers();
  }
  ~MemoryCounters() {
    const std::optional<double> peakKiB = procStatusKiB("VmHWM");
    // RSS counters are cached per thread and can lag a little: never report a negative growth.
    if (startKiB_ && peakKiB) state_.counters["host_peak_MiB"] = std::max(0.0, *peakKiB - *startKiB_) / 1024.0;
    if (vulkan_) {
      state_.counters["device_peak_MiB"] = static_cast<double>(vulkan_->context().peakAllocatedBytes()) / (1 << 20);
      const vk::TransferCounts after = vulkan_->context().transfers();
      const auto perIteration = [](double value) {
        return benchmark::Counter(value, benchmark::Counter::kAvgIterations);
      };
      state_.counters["uploaded_KiB"] =
          perIteration(static_cast<double>(after.uploadedBytes - transfersBefore_.uploadedBytes) / 1024.0);
      state_.counters["downloaded_KiB"] =
          perIteration(static_cast<double>(after.downloadedBytes - transfersBefore_.downloadedBytes) / 1024.0);
      state_.counters["transfers"] = perIteration(static_cast<double>(after.uploads + after.downloads -
                                                                      transfersBefore_.uploads -
                                                                      transfersBefore_.downloads));
    }
  }
  MemoryCounters(const MemoryCounters&) = delete;
  MemoryCounters& operator=(const MemoryCounters&) = delete;

 private:
  benchmark::State& state_;
  compute::VulkanBackend* vulkan_;
  std::optional<double> startKiB_;
  vk::TransferCounts transfersBefore_;
};

}  // namespace plano::bench
