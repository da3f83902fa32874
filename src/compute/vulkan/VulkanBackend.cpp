#include "compute/vulkan/VulkanBackend.h"

#include "core/Error.h"

namespace plano::compute {

// Replaced by the Vulkan runtime (context, buffers, pipelines) in the Vulkan backend work.
std::unique_ptr<Backend> createVulkanBackend(VulkanDevicePreference) {
  throwDevice("the Vulkan backend is not available in this build");
}

}  // namespace plano::compute
