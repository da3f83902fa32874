// `plano --backend vulkan deform --space ...`: the subspace deformation's iterations run on
// the device (vk::ReducedArapKernels) and give the CPU's mesh and iteration count; a device
// lost in the middle exits with 5 and writes no mesh. `plano --backend vulkan explore`: the
// eigenshapes' reduced operator is formed on the device and gives the CPU's frequencies;
// `plano --backend vulkan embed`: the Tutte solve and the lifting run there and give the CPU's mesh.
#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>

#include "mesh/Generators.h"
#include "mesh/MeshIO.h"
#include "support/ScopedEnvironment.h"
#include "support/TestMeshes.h"

namespace plano::test {
namespace {

class VulkanSubspaceCommand : public ::testing::Test {
 protected:
  void SetUp() override {
    writeMesh(dir_ / "dome.obj", generate::hexagonalDome(2));
    std::ofstream(dir_ / "c.json") << R"({"fixed": [0, 1, 2, 3, 4, 5, 6, 7, 8, 9],
                                           "handles": [{"vertex": 40, "position": [0.0, 0.0, 1.2]}]})";
  }
  std::string path(const std::string& name) const { return quotedPath(dir_ / name); }
  ToolResult deform(const std::string& backend, const std::string& out, const std::string& report) const {
    return runTool("-q --backend " + backend + " deform " + path("dome.obj") + " --space vertical --constraints " +
                   path("c.json") + " -o " + path(out) + " --report " + path(report));
  }
  nlohmann::json report(const std::string& name) const {
    std::ifstream in(dir_ / name);
    return nlohmann::json::parse(in);
  }
  TempDir dir_;
};

TEST_F(VulkanSubspaceCommand, DeviceDeformationWritesTheCpuMesh) {
  const ToolResult cpu = deform("cpu", "cpu.obj", "cpu.json");
  const ToolResult device = deform("vulkan", "device.obj", "device.json");
  ASSERT_EQ(cpu.exitCode, 0) << cpu.err;
  ASSERT_EQ(device.exitCode, 0) << device.err;
  EXPECT_EQ(report("device.json")["iterations"], report("cpu.json")["iterations"]);
  EXPECT_GT(report("cpu.json")["iterations"].get<int>(), 8) << "more than one device block";
  const PolygonMesh a = readMesh(dir_ / "cpu.obj");
  const PolygonMesh b = readMesh(dir_ / "device.obj");
  ASSERT_EQ(a.vertexCount(), b.vertexCount());
  EXPECT_LT((a.vertices - b.vertices).rowwise().norm().maxCoeff(), 1e-9 * boundingBoxDiagonal(a.vertices));
}

TEST_F(VulkanSubspaceCommand, LostDeviceDuringDeformationExitsWithFiveAndWritesNoMesh) {
  ScopedEnvironment fault("PLANO_VULKAN_SIMULATE_DEVICE_LOST", "3");
  const ToolResult result = deform("vulkan", "out.obj", "r.json");
  EXPECT_EQ(result.exitCode, 5) << result.err;
  EXPECT_NE(result.err.find("device lost"), std::string::npos) << result.err;
  EXPECT_FALSE(std::filesystem::exists(dir_ / "out.obj"));
  EXPECT_EQ(report("r.json")["status"], "device_failure");
}

TEST_F(VulkanSubspaceCommand, ExploreFormsTheReducedOperatorOnTheDeviceAndGivesTheCpusFrequencies) {
  const auto explore = [&](const std::string& backend, const std::string& out, const std::string& report) {
    return runTool("--backend " + backend + " explore " + path("dome.obj") + " --space parallel --eigenshapes 8 -o " +
                   path(out) + " --report " + path(report));
  };
  const ToolResult cpu = explore("cpu", "cpu.obj", "cpu.json");
  const ToolResult device = explore("vulkan", "device.obj", "device.json");
  ASSERT_EQ(cpu.exitCode, 0) << cpu.err;
  ASSERT_EQ(device.exitCode, 0) << device.err;
  EXPECT_NE(device.err.find("the reduced operator runs on vulkan"), std::string::npos) << device.err;
  EXPECT_EQ(device.err.find("warning"), std::string::npos) << device.err;
  EXPECT_EQ(report("device.json")["backend"].get<std::string>().rfind("vulkan", 0), 0u);
  const auto a = report("cpu.json")["frequencies"].get<std::vector<double>>();
  const auto b = report("device.json")["frequencies"].get<std::vector<double>>();
  ASSERT_EQ(a.size(), 8u);
  ASSERT_EQ(b.size(), a.size());
  // Frequencies, not meshes: the dome's symmetry repeats eigenvalues, and within a repeated
  // eigenvalue's space rounding may pick other (equally valid) eigenshapes.
  for (std::size_t k = 0; k < a.size(); ++k) EXPECT_NEAR(b[k], a[k], 1e-10 * a.back()) << k;
  EXPECT_LT(report("device.json")["subspace_residual"].get<double>(), 1e-9);
}

TEST_F(VulkanSubspaceCommand, EmbedSolvesOnTheDeviceAndWritesTheCpusMesh) {
  writeMesh(dir_ / "grid.obj", generate::hyparGrid(6));
  const auto embed = [&](const std::string& backend, const std::string& out, const std::string& report) {
    return runTool("--backend " + backend + " embed " + path("grid.obj") + " --lift handle -o " + path(out) +
                   " --report " + path(report));
  };
  const ToolResult cpu = embed("cpu", "cpu.obj", "cpu.json");
  const ToolResult device = embed("vulkan", "device.obj", "device.json");
  ASSERT_EQ(cpu.exitCode, 0) << cpu.err;
  ASSERT_EQ(device.exitCode, 0) << device.err;
  EXPECT_NE(device.err.find("the Tutte solve and the lifting's reduced operator run on vulkan"), std::string::npos)
      << device.err;
  EXPECT_EQ(report("device.json")["backend"].get<std::string>().rfind("vulkan", 0), 0u);
  EXPECT_EQ(report("device.json")["flipped_faces"], 0);
  const PolygonMesh x = readMesh(dir_ / "cpu.obj");
  const PolygonMesh y = readMesh(dir_ / "device.obj");
  ASSERT_EQ(x.vertexCount(), y.vertexCount());
  EXPECT_LT((x.vertices - y.vertices).rowwise().norm().maxCoeff(), 1e-9 * boundingBoxDiagonal(x.vertices));
}

TEST_F(VulkanSubspaceCommand, LostDeviceDuringExploreExitsWithFiveAndWritesNoMesh) {
  ScopedEnvironment fault("PLANO_VULKAN_SIMULATE_DEVICE_LOST", "1");
  const ToolResult result = runTool("-q --backend vulkan explore " + path("dome.obj") + " -o " + path("out.obj") +
                                    " --report " + path("r.json"));
  EXPECT_EQ(result.exitCode, 5) << result.err;
  EXPECT_NE(result.err.find("device lost"), std::string::npos) << result.err;
  EXPECT_FALSE(std::filesystem::exists(dir_ / "out.obj"));
  EXPECT_EQ(report("r.json")["status"], "device_failure");
}

}  // namespace
}  // namespace plano::test
