// The simulated device faults (compute/vulkan/VulkanFaultSimulation.h) surface as
// Error(Device) whose message names the problem, through the same checks a real fault
// takes; validation stays silent on every path.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "compute/vulkan/VulkanBackend.h"
#include "compute/vulkan/VulkanBuffer.h"
#include "compute/VulkanFixture.h"
#include "compute/vulkan/VulkanContext.h"
#include "core/Error.h"
#include "mesh/Generators.h"
#include "support/ScopedEnvironment.h"

namespace plano::test {
namespace {

/// The message of the Error(Device) that `action` throws; fails the test otherwise.
template <class Action>
std::string deviceErrorOf(Action&& action) {
  try {
    action();
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::Device) << e.what();
    return e.what();
  }
  ADD_FAILURE() << "no error was thrown";
  return {};
}

TEST(VulkanFaultSimulation, DeviceWithoutFloat64IsRefusedNamingTheFeature) {
  vk::ContextSettings settings = validatedSettings();
  settings.faults.noFloat64 = true;
  const std::string message = deviceErrorOf([&] { vk::Context context(settings); });
  EXPECT_NE(message.find("shaderFloat64"), std::string::npos) << message;
  EXPECT_NE(message.find("PLANO_VULKAN_SIMULATE_NO_FLOAT64"), std::string::npos) << message;
}

TEST(VulkanFaultSimulation, AllocationOverTheMemoryLimitIsRefusedWithTheSizes) {
  vk::ContextSettings settings = validatedSettings();
  settings.faults.memoryLimit = 1 << 20;
  vk::Context context(settings);
  std::vector<vk::Buffer> kept;
  kept.emplace_back(context, 600 * 1024, vk::MemoryClass::Device, "the first test buffer");
  const std::string message =
      deviceErrorOf([&] { vk::Buffer second(context, 600 * 1024, vk::MemoryClass::Device, "the second test buffer"); });
  EXPECT_NE(message.find("the second test buffer"), std::string::npos) << message;
  EXPECT_NE(message.find("614400 bytes"), std::string::npos) << message;
  EXPECT_NE(message.find("memory limit of 1048576 bytes"), std::string::npos) << message;
  // Freed buffers are no longer counted.
  kept.clear();
  EXPECT_NO_THROW(vk::Buffer(context, 600 * 1024, vk::MemoryClass::Device, "a buffer after the first was freed"));
  EXPECT_TRUE(context.validationMessages().empty());
}

TEST(VulkanFaultSimulation, BufferOverMaxStorageBufferRangeIsRefusedBeforeAllocating) {
  vk::Context context(validatedSettings());
  const std::size_t range = context.info().maxStorageBufferRange;
  const std::string message =
      deviceErrorOf([&] { vk::Buffer huge(context, range + 16, vk::MemoryClass::Device, "an oversized test buffer"); });
  EXPECT_NE(message.find("maxStorageBufferRange of " + std::to_string(range) + " bytes"), std::string::npos) << message;
  EXPECT_NE(message.find(std::to_string(range + 16) + "-byte buffer"), std::string::npos) << message;
  EXPECT_TRUE(context.validationMessages().empty());
}

TEST(VulkanFaultSimulation, LostDeviceFailsTheSubmissionNamingTheLoss) {
  // Through the environment, as the plano tool reads it; the first submission is lost.
  ScopedEnvironment lost("PLANO_VULKAN_SIMULATE_DEVICE_LOST", "1");
  ScopedEnvironment validation("PLANO_VULKAN_VALIDATION", "1");
  compute::VulkanBackend backend(compute::VulkanDevicePreference::Any);
  const PolygonMesh mesh = generate::cube();
  std::vector<double> planarity(mesh.faceCount());
  const std::string message = deviceErrorOf([&] { backend.facePlanarity(mesh, planarity); });
  EXPECT_NE(message.find("device lost"), std::string::npos) << message;
  EXPECT_NE(message.find("VK_ERROR_DEVICE_LOST"), std::string::npos) << message;
  // A lost device stays lost.
  const std::string again = deviceErrorOf([&] { backend.facePlanarity(mesh, planarity); });
  EXPECT_NE(again.find("device lost"), std::string::npos) << again;
  EXPECT_TRUE(backend.context().validationMessages().empty());
}

TEST(VulkanFaultSimulation, SubmissionsBeforeTheLostOneSucceed) {
  ScopedEnvironment lost("PLANO_VULKAN_SIMULATE_DEVICE_LOST", "2");
  compute::VulkanBackend backend(compute::VulkanDevicePreference::Any);
  const PolygonMesh mesh = generate::cube();
  std::vector<double> planarity(mesh.faceCount(), -1.0);
  EXPECT_NO_THROW(backend.facePlanarity(mesh, planarity));
  EXPECT_NEAR(planarity[0], 0.0, 1e-12);
  const std::string message = deviceErrorOf([&] { backend.facePlanarity(mesh, planarity); });
  EXPECT_NE(message.find("device lost"), std::string::npos) << message;
}

TEST(VulkanFaultSimulation, MalformedVariableIsAUsageError) {
  ScopedEnvironment limit("PLANO_VULKAN_MEMORY_LIMIT", "1MB");
  try {
    vk::SimulatedFaults::fromEnvironment();
    FAIL() << "PLANO_VULKAN_MEMORY_LIMIT=1MB was accepted";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::Usage);
    EXPECT_NE(std::string(e.what()).find("PLANO_VULKAN_MEMORY_LIMIT"), std::string::npos) << e.what();
  }
}

TEST(VulkanFaultSimulation, NothingIsSimulatedWithoutTheVariables) {
  EXPECT_FALSE(vk::SimulatedFaults::fromEnvironment().any());
}

}  // namespace
}  // namespace plano::test
