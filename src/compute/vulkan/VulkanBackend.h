#pragma once
// The Vulkan compute backend: GLSL kernels from shaders/, embedded as SPIR-V.
#include <memory>

#include "compute/Backend.h"

namespace plano::compute {

enum class VulkanDevicePreference {
  Any,          ///< A discrete/integrated GPU when present, else a CPU device (lavapipe).
  RealGpuOnly,  ///< Refuse CPU implementations (used by --backend auto).
};

/// Create the Vulkan backend. The device can be forced with the environment variable
/// PLANO_VULKAN_DEVICE (index or a substring of the device name). Throws Error(Device)
/// with the reason when no suitable device exists (no loader, no device, no shaderFloat64).
std::unique_ptr<Backend> createVulkanBackend(VulkanDevicePreference preference);

}  // namespace plano::compute
