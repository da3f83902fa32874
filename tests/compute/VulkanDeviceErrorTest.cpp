// Device failures are reported as Error(Device) / exit code 5 with a clear message,
// never a crash. The checks that break the Vulkan loader's view of the system run in a
// child process (the plano tool), so this process's own Vulkan state is untouched.
#include <gtest/gtest.h>

#include <string>

#include "compute/Backend.h"
#include "mesh/Generators.h"
#include "mesh/MeshIO.h"
#include "support/ScopedEnvironment.h"
#include "support/TestMeshes.h"

namespace plano::test {
namespace {

class VulkanDeviceErrors : public ::testing::Test {
 protected:
  void SetUp() override { writeMesh(dir_ / "cube.obj", generate::cube()); }
  std::string meshPath() const { return (dir_ / "cube.obj").string(); }
  TempDir dir_;
};

TEST_F(VulkanDeviceErrors, NoDriverGivesDeviceErrorWithClearMessage) {
  ScopedEnvironment drivers("VK_DRIVER_FILES", (dir_ / "no-such-driver.json").string());
  const ToolResult result = runTool("--backend vulkan info " + meshPath());
  EXPECT_EQ(result.exitCode, 5) << result.err;
  EXPECT_NE(result.err.find("device failure"), std::string::npos) << result.err;
  EXPECT_NE(result.err.find("Vulkan"), std::string::npos) << result.err;
}

TEST_F(VulkanDeviceErrors, AutoWithoutDriverFallsBackToCpuWithWarning) {
  ScopedEnvironment drivers("VK_DRIVER_FILES", (dir_ / "no-such-driver.json").string());
  const ToolResult result = runTool("--backend auto info --json " + meshPath());
  EXPECT_EQ(result.exitCode, 0) << result.err;
  EXPECT_NE(result.err.find("warning: using the CPU backend"), std::string::npos) << result.err;
  EXPECT_NE(result.out.find("\"backend\": \"cpu\""), std::string::npos) << result.out;
}

TEST_F(VulkanDeviceErrors, UnknownForcedDeviceNamesTheAvailableOnes) {
  ScopedEnvironment device("PLANO_VULKAN_DEVICE", "no-such-gpu");
  const ToolResult result = runTool("--backend vulkan info " + meshPath());
  EXPECT_EQ(result.exitCode, 5) << result.err;
  EXPECT_NE(result.err.find("PLANO_VULKAN_DEVICE='no-such-gpu' matches no device"), std::string::npos) << result.err;
}

TEST(VulkanBackendChoice, AutoNeverPicksACpuImplementation) {
  // On lavapipe (a CPU device) auto must give the CPU backend; on a real GPU, Vulkan.
  std::string warnings;
  auto backend = compute::createBackend(compute::BackendChoice::Auto, &warnings);
  if (backend->kind() == compute::BackendKind::Cpu) {
    EXPECT_NE(warnings.find("warning"), std::string::npos);
  } else {
    EXPECT_EQ(backend->name().find("llvmpipe"), std::string::npos);
  }
}

}  // namespace
}  // namespace plano::test
