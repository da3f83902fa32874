// `plano --backend vulkan deform` (the projective shape space): the report gives each
// iteration's host <-> device copies, and they stay those of the step's vectors: no matrix
// crosses per iteration (the polish's K is formed on the device).
#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>

#include "mesh/Generators.h"
#include "mesh/MeshIO.h"
#include "support/TestMeshes.h"

namespace plano::test {
namespace {

class VulkanDeformCommand : public ::testing::Test {
 protected:
  void SetUp() override {
    writeMesh(dir_ / "grid.obj", generate::translationalSurface(4, 4));
    std::ofstream(dir_ / "c.json") << R"({"fixed": [0, 1, 2, 3, 4],
                                           "handles": [{"vertex": 24, "position": [1.0, 1.0, 0.3]}]})";
  }
  std::string path(const std::string& name) const { return quotedPath(dir_ / name); }
  nlohmann::json deform(const std::string& backend) const {
    const ToolResult result = runTool("-q --backend " + backend + " deform " + path("grid.obj") + " --constraints " +
                                      path("c.json") + " -o " + path(backend + ".obj") + " --report " +
                                      path(backend + ".json"));
    EXPECT_EQ(result.exitCode, 0) << result.err;
    std::ifstream in(dir_ / (backend + ".json"));
    return nlohmann::json::parse(in);
  }
  TempDir dir_;
};

TEST_F(VulkanDeformCommand, ReportsEachIterationsDeviceTransfersAndNoMatrixCrossesAfterTheFirst) {
  const nlohmann::json device = deform("vulkan");
  const nlohmann::json cpu = deform("cpu");
  ASSERT_EQ(device["status"], "converged");
  for (const auto& step : cpu["history"]) EXPECT_FALSE(step.contains("device_transfers"));
  const auto faces = device["faces"].get<std::uint64_t>();
  ASSERT_GT(device["history"].size(), 2u);
  for (const auto& step : device["history"]) {
    ASSERT_TRUE(step.contains("device_transfers")) << step.dump();
    const auto& transfers = step["device_transfers"];
    EXPECT_GT(transfers["uploaded_bytes"].get<std::uint64_t>(), 0u);
    EXPECT_GT(transfers["downloaded_bytes"].get<std::uint64_t>(), 0u);
    EXPECT_GT(transfers["copies"].get<std::uint64_t>(), 0u);
    // Every step exact, the first from zero multipliers too: the polish's method of
    // multipliers alone, no ADMM iteration.
    EXPECT_EQ(step["admm_iterations"], 0) << step.dump();
    EXPECT_GT(step["polish_refinements"].get<int>(), 0) << step.dump();
    if (step["iteration"].get<int>() == 1) continue;  // the first uploads the kept solver's matrices
    // Measured 11.5 kB on these 16 faces (0.72 kB per face: corners, 3x3 matrices, scales,
    // the QP's vectors); the polish's K and right-hand sides, built on the host, added about
    // 1.4 kB per face (BM_GlobalStep/vulkan/64: 157 -> 64 KiB per step).
    EXPECT_LT(transfers["uploaded_bytes"].get<std::uint64_t>(), 1024u * faces) << step.dump();
  }
}

}  // namespace
}  // namespace plano::test
