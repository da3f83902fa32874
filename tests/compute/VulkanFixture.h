#pragma once
// One Vulkan backend for the whole test binary (lavapipe JIT-compiles each pipeline on
// first use, so sharing keeps the suite fast), created with the validation layers on.
// Every test using the fixture fails when the validation layers reported anything
// while it ran.
#include <gtest/gtest.h>

#include "compute/vulkan/VulkanBackend.h"
#include "compute/vulkan/VulkanContext.h"

namespace plano::test {

/// The shared backend, created on first call with PLANO_VULKAN_VALIDATION=1; null when
/// creation failed (the reason is in *error).
compute::VulkanBackend* sharedVulkanBackend(std::string* error);

/// Settings of a context of its own (PLANO_VULKAN_DEVICE honoured) with the validation layers on.
inline vk::ContextSettings validatedSettings() {
  vk::ContextSettings settings = vk::ContextSettings::fromEnvironment(vk::DeviceSelection::Any);
  settings.validation = true;
  return settings;
}

class VulkanTest : public ::testing::Test {
 protected:
  void SetUp() override;
  void TearDown() override;
  compute::VulkanBackend& backend() { return *backend_; }
  vk::Context& context() { return backend_->context(); }

 private:
  compute::VulkanBackend* backend_ = nullptr;
  std::size_t messagesBefore_ = 0;
};

}  // namespace plano::test
