#pragma once
// Test-only simulation of device faults that lavapipe never produces: a device without
// shaderFloat64, a small memory budget, a lost device. It exists so that the error paths
// users hit on real GPUs (exit code 5 with a message naming the problem) can be tested on
// any machine. Each simulated fault is injected where the real one would surface, and from
// there takes the same code path; nothing is simulated unless a variable is set:
//   PLANO_VULKAN_SIMULATE_NO_FLOAT64=1    the device is treated as lacking shaderFloat64
//   PLANO_VULKAN_MEMORY_LIMIT=BYTES       device allocations may not exceed BYTES in total
//   PLANO_VULKAN_SIMULATE_DEVICE_LOST=N   the N-th queue submission (1-based) and every later
//                                         one report VK_ERROR_DEVICE_LOST
#include <cstdint>

namespace plano::vk {

struct SimulatedFaults {
  bool noFloat64 = false;
  std::uint64_t memoryLimit = 0;         ///< 0: no simulated limit.
  std::uint64_t deviceLostAtSubmit = 0;  ///< 0: the device is never lost.

  bool any() const { return noFloat64 || memoryLimit > 0 || deviceLostAtSubmit > 0; }

  /// The faults requested by the PLANO_VULKAN_* variables above. Throws Error(Usage)
  /// for a value that is not a number, so a typo never silently disables a test.
  static SimulatedFaults fromEnvironment();
};

}  // namespace plano::vk
