// Simulated Vulkan faults (compute/vulkan/VulkanFaultSimulation.h) seen through the plano
// tool: --backend vulkan exits with 5, names the problem on stderr and writes no output;
// --backend auto never fails because of them (on lavapipe it takes the CPU anyway, on a
// real GPU it runs again on the CPU after a device failure).
#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>

#include "mesh/Generators.h"
#include "mesh/MeshIO.h"
#include "support/ScopedEnvironment.h"
#include "support/TestMeshes.h"

namespace plano::test {
namespace {

class VulkanFaultCommand : public ::testing::Test {
 protected:
  void SetUp() override {
    writeMesh(dir_ / "grid.obj", generate::hyparGrid(6, 0.5));
    std::ofstream(dir_ / "c.json") << R"({"fixed": [0, 6], "handles": [{"vertex": 48, "position": [1.0, 1.0, 0.3]}]})";
  }
  std::string path(const std::string& name) const { return (dir_ / name).string(); }

  /// `plano --backend BACKEND planarize` writing out.obj and r.json.
  ToolResult planarize(const std::string& backend) const {
    return runTool("--backend " + backend + " planarize " + path("grid.obj") + " -o " + path("out.obj") +
                   " --report " + path("r.json"));
  }
  void expectDeviceFailure(const ToolResult& result, const std::string& problem) const {
    EXPECT_EQ(result.exitCode, 5) << result.err;
    EXPECT_NE(result.err.find("device failure"), std::string::npos) << result.err;
    EXPECT_NE(result.err.find(problem), std::string::npos) << result.err;
    EXPECT_FALSE(std::filesystem::exists(dir_ / "out.obj"));
    std::ifstream in(dir_ / "r.json");
    ASSERT_TRUE(in) << "no report";
    const nlohmann::json report = nlohmann::json::parse(in);
    EXPECT_EQ(report["status"], "device_failure");
    EXPECT_NE(report["reason"].get<std::string>().find(problem), std::string::npos) << report.dump();
  }
  void expectCpuResult(const ToolResult& result) const {
    EXPECT_EQ(result.exitCode, 0) << result.err;
    EXPECT_NE(result.err.find("warning"), std::string::npos) << result.err;
    EXPECT_TRUE(std::filesystem::exists(dir_ / "out.obj"));
  }

  TempDir dir_;
};

TEST_F(VulkanFaultCommand, MissingDriverExitsWithFiveAndWritesNothing) {
  ScopedEnvironment drivers("VK_DRIVER_FILES", path("no-such-driver.json"));
  expectDeviceFailure(planarize("vulkan"), "no Vulkan driver");
}

TEST_F(VulkanFaultCommand, MissingDriverWithAutoRunsOnTheCpu) {
  ScopedEnvironment drivers("VK_DRIVER_FILES", path("no-such-driver.json"));
  expectCpuResult(planarize("auto"));
}

TEST_F(VulkanFaultCommand, DeviceWithoutFloat64ExitsWithFiveNamingTheFeature) {
  ScopedEnvironment fault("PLANO_VULKAN_SIMULATE_NO_FLOAT64", "1");
  expectDeviceFailure(planarize("vulkan"), "shaderFloat64");
}

TEST_F(VulkanFaultCommand, DeviceWithoutFloat64WithAutoRunsOnTheCpu) {
  ScopedEnvironment fault("PLANO_VULKAN_SIMULATE_NO_FLOAT64", "1");
  expectCpuResult(planarize("auto"));
}

TEST_F(VulkanFaultCommand, AllocationOverTheMemoryLimitExitsWithFiveNamingTheSizes) {
  ScopedEnvironment fault("PLANO_VULKAN_MEMORY_LIMIT", "256");
  expectDeviceFailure(planarize("vulkan"), "over the memory limit of 256 bytes");
}

TEST_F(VulkanFaultCommand, AllocationOverTheMemoryLimitWithAutoStillGivesAResult) {
  ScopedEnvironment fault("PLANO_VULKAN_MEMORY_LIMIT", "256");
  expectCpuResult(planarize("auto"));
}

TEST_F(VulkanFaultCommand, LostDeviceExitsWithFiveAndWritesNothing) {
  ScopedEnvironment fault("PLANO_VULKAN_SIMULATE_DEVICE_LOST", "2");
  expectDeviceFailure(planarize("vulkan"), "device lost");
}

TEST_F(VulkanFaultCommand, LostDeviceDuringDeformationExitsWithFive) {
  ScopedEnvironment fault("PLANO_VULKAN_SIMULATE_DEVICE_LOST", "2");
  const ToolResult result = runTool("--backend vulkan deform " + path("grid.obj") + " --constraints " + path("c.json") +
                                    " -o " + path("out.obj") + " --report " + path("r.json"));
  expectDeviceFailure(result, "device lost");
}

TEST_F(VulkanFaultCommand, LostDeviceWithAutoStillGivesAResult) {
  ScopedEnvironment fault("PLANO_VULKAN_SIMULATE_DEVICE_LOST", "1");
  expectCpuResult(planarize("auto"));
}

}  // namespace
}  // namespace plano::test
