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
