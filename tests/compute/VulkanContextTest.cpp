// The Vulkan context: device choice, feature detection, and a validation messenger
// that really records messages (otherwise "zero messages" in every other test means nothing).
#include <gtest/gtest.h>

#include <cstdlib>
#include <span>
#include <vector>

#include "compute/vulkan/VulkanBuffer.h"
#include "compute/VulkanFixture.h"
#include "compute/vulkan/VulkanContext.h"
#include "compute/vulkan/VulkanPipeline.h"
#include "core/Error.h"

namespace plano::test {
namespace {

TEST(VulkanContext, ReportsDoublePrecisionAndLimits) {
  vk::Context context(validatedSettings());
  EXPECT_TRUE(context.info().shaderFloat64);
  EXPECT_GT(context.info().maxStorageBufferRange, 0u);
  EXPECT_GE(context.info().maxWorkGroupCount[0], 65535u);
  EXPECT_FALSE(context.info().name.empty());
}

TEST(VulkanContext, SweepsGiveEachInvocationSixteenItemsOnCpuDevicesAndOneOnGpus) {
  vk::Context context(validatedSettings());
  const bool cpu = context.info().type == VK_PHYSICAL_DEVICE_TYPE_CPU;
  const std::uint32_t perGroup = vk::kWorkGroupSize * (cpu ? vk::kCpuSweepItemsPerInvocation : 1);
  EXPECT_EQ(vk::sweepGroupsFor(context, 10 * perGroup), 10u);
  EXPECT_EQ(vk::sweepGroupsFor(context, 10 * perGroup + 1), 11u);
  EXPECT_EQ(vk::sweepGroupsFor(context, 1), 1u);
  EXPECT_EQ(vk::sweepGroupsFor(context, 0), 1u);  // Vulkan forbids empty dispatches
  EXPECT_EQ(vk::groupsFor(context, 10 * vk::kWorkGroupSize), 10u);  // other kernels: one item each
}

TEST(VulkanContext, ValidationMessengerRecordsInvalidUsage) {
  vk::Context context(validatedSettings());
  ASSERT_EQ(context.validationMessageCount(), 0u);
  // A zero-sized buffer violates VUID-VkBufferCreateInfo-size-00912.
  auto info = vk::vkStruct<VkBufferCreateInfo>(VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO);
  info.size = 0;
  info.usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
  VkBuffer buffer = VK_NULL_HANDLE;
  vkCreateBuffer(context.device(), &info, nullptr, &buffer);
  if (buffer) vkDestroyBuffer(context.device(), buffer, nullptr);
  EXPECT_GT(context.validationMessageCount(), 0u);
}

TEST(VulkanContext, ForcedDeviceByIndexIsUsed) {
  vk::ContextSettings settings = validatedSettings();
  settings.deviceOverride = std::to_string(0);  // (a literal trips a GCC 12 -Wrestrict false positive)
  vk::Context context(settings);
  EXPECT_EQ(context.info().index, 0u);
}

TEST(VulkanContext, RealGpuOnlyRefusesCpuImplementationsWithReason) {
  vk::ContextSettings settings = validatedSettings();
  settings.selection = vk::DeviceSelection::RealGpuOnly;
  try {
    vk::Context context(settings);
    EXPECT_NE(context.info().type, VK_PHYSICAL_DEVICE_TYPE_CPU);
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::Device);
    EXPECT_NE(std::string(e.what()).find("CPU implementation"), std::string::npos) << e.what();
  }
}

TEST(VulkanContext, ImpossibleAllocationIsADeviceErrorNamingTheBuffer) {
  // Validation off: the layer would (rightly) flag the oversized request itself.
  vk::ContextSettings settings = vk::ContextSettings::fromEnvironment(vk::DeviceSelection::Any);
  settings.validation = false;
  vk::Context context(settings);
  try {
    vk::Buffer huge(context, std::size_t(1) << 42, vk::MemoryClass::Device, "a 4 TiB test buffer");
    FAIL() << "a 4 TiB allocation succeeded";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::Device);
    EXPECT_NE(std::string(e.what()).find("a 4 TiB test buffer"), std::string::npos) << e.what();
  }
}

TEST(VulkanContext, CountsEachCopyBetweenHostAndDeviceOnceWhetherMappedOrStaged) {
  for (const bool staged : {false, true}) {
    vk::ContextSettings settings = validatedSettings();
    settings.forceStaging = staged;
    vk::Context context(settings);
    vk::Array<double> values(context, 100, vk::MemoryClass::Device, "test values");
    std::vector<double> host(100, 1.5);
    values.upload(host);
    values.upload(std::span<const double>(host).first(10), 90);
    values.download(std::span<double>(host).first(25));
    const vk::TransferCounts counts = context.transfers();
    EXPECT_EQ(counts.uploads, 2u) << "staged " << staged;
    EXPECT_EQ(counts.uploadedBytes, 110u * sizeof(double)) << "staged " << staged;
    EXPECT_EQ(counts.downloads, 1u) << "staged " << staged;
    EXPECT_EQ(counts.downloadedBytes, 25u * sizeof(double)) << "staged " << staged;
    EXPECT_EQ(host[0], 1.5);
    EXPECT_EQ(context.validationMessageCount(), 0u);
  }
}

}  // namespace
}  // namespace plano::test
