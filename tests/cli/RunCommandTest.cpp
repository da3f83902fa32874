// The command runner of the plano tool (tools/plano/RunCommand.h): exit codes, the
// failure report, and the CPU rerun of --backend auto after a device failure.
#include "plano/RunCommand.h"

#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "core/Cancellation.h"
#include "core/Error.h"
#include "support/TestMeshes.h"

namespace plano::cli {
namespace {

/// A command that records the backends it was run with and fails as told while the
/// backend is `failingBackend`.
struct FakeCommand {
  std::vector<std::string> backends;
  std::function<void()> failure;
  std::string failingBackend;

  CommandRun run(const std::string& reportPath) {
    return {"fake", [this](const GlobalOptions& options) {
              backends.push_back(options.backend);
              if (options.backend == failingBackend) failure();
              return 0;
            },
            {{}, {{"--report", reportPath}}}};
  }
};

nlohmann::json readJson(const std::filesystem::path& path) {
  std::ifstream in(path);
  return nlohmann::json::parse(in);
}

GlobalOptions withBackend(const std::string& backend) {
  GlobalOptions options;
  options.backend = backend;
  return options;
}

TEST(RunCommand, AutoRunsAgainOnTheCpuAfterADeviceFailureWithAWarning) {
  FakeCommand fake{{}, [] { throwDevice("Vulkan: waiting for the compute queue failed: VK_ERROR_DEVICE_LOST"); }, "auto"};
  std::ostringstream err;
  EXPECT_EQ(runCommand(fake.run(""), withBackend("auto"), err), 0);
  EXPECT_EQ(fake.backends, (std::vector<std::string>{"auto", "cpu"}));
  EXPECT_NE(err.str().find("warning: the Vulkan device failed"), std::string::npos) << err.str();
  EXPECT_NE(err.str().find("VK_ERROR_DEVICE_LOST"), std::string::npos) << err.str();
}

TEST(RunCommand, ExplicitVulkanDeviceFailureExitsWithFiveAndReportsIt) {
  test::TempDir dir;
  FakeCommand fake{{}, [] { throwDevice("Vulkan: device lost"); }, "vulkan"};
  std::ostringstream err;
  EXPECT_EQ(runCommand(fake.run((dir / "r.json").string()), withBackend("vulkan"), err), 5);
  EXPECT_EQ(fake.backends.size(), 1u);
  EXPECT_NE(err.str().find("plano: device failure: Vulkan: device lost"), std::string::npos) << err.str();
  const nlohmann::json report = readJson(dir / "r.json");
  EXPECT_EQ(report["status"], "device_failure");
  EXPECT_EQ(report["command"], "fake");
  EXPECT_EQ(report["output_written"], false);
}

TEST(RunCommand, NumericalErrorExitsWithFourAndReportsTheReason) {
  test::TempDir dir;
  FakeCommand fake{{}, [] { throwNumerical("singular local fit on face 3"); }, "cpu"};
  std::ostringstream err;
  EXPECT_EQ(runCommand(fake.run((dir / "r.json").string()), withBackend("cpu"), err), 4);
  const nlohmann::json report = readJson(dir / "r.json");
  EXPECT_EQ(report["status"], "numerical_failure");
  EXPECT_EQ(report["reason"], "singular local fit on face 3");
}

TEST(RunCommand, InterruptedRunExitsWith130AndReportsInterrupted) {
  test::TempDir dir;
  FakeCommand fake{{}, [] { throw Interrupted("stopped during planarization"); }, "cpu"};
  std::ostringstream err;
  EXPECT_EQ(runCommand(fake.run((dir / "r.json").string()), withBackend("cpu"), err), 130);
  EXPECT_NE(err.str().find("interrupted"), std::string::npos) << err.str();
  const nlohmann::json report = readJson(dir / "r.json");
  EXPECT_EQ(report["status"], "interrupted");
  EXPECT_EQ(report["reason"], "stopped during planarization");
}

TEST(RunCommand, UsageErrorWritesNoReport) {
  test::TempDir dir;
  FakeCommand fake{{}, [] { throwUsage("no output file"); }, "cpu"};
  std::ostringstream err;
  EXPECT_EQ(runCommand(fake.run((dir / "r.json").string()), withBackend("cpu"), err), 2);
  EXPECT_FALSE(std::filesystem::exists(dir / "r.json"));
}

TEST(Cancellation, ThrowsOnlyAfterARequest) {
  clearCancellation();
  EXPECT_NO_THROW(throwIfCancelled("a test loop"));
  requestCancellation();
  EXPECT_THROW(throwIfCancelled("a test loop"), Interrupted);
  clearCancellation();
  EXPECT_FALSE(cancellationRequested());
}

}  // namespace
}  // namespace plano::cli
