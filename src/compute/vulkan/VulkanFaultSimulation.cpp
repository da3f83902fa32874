#include "compute/vulkan/VulkanFaultSimulation.h"

#include <cstdlib>
#include <string>

#include "core/Error.h"

namespace plano::vk {
namespace {

/// Value of a non-negative integer variable; 0 when unset or empty.
std::uint64_t unsignedVariable(const char* name) {
  const char* text = std::getenv(name);
  if (text == nullptr || *text == '\0') return 0;
  const std::string value(text);
  if (value.find_first_not_of("0123456789") != std::string::npos || value.size() > 19) {
    throwUsage(std::string(name) + "='" + value + "' is not a non-negative integer");
  }
  return std::stoull(value);
}

}  // namespace

SimulatedFaults SimulatedFaults::fromEnvironment() {
  SimulatedFaults faults;
  faults.noFloat64 = unsignedVariable("PLANO_VULKAN_SIMULATE_NO_FLOAT64") != 0;
  faults.memoryLimit = unsignedVariable("PLANO_VULKAN_MEMORY_LIMIT");
  faults.deviceLostAtSubmit = unsignedVariable("PLANO_VULKAN_SIMULATE_DEVICE_LOST");
  return faults;
}

}  // namespace plano::vk
