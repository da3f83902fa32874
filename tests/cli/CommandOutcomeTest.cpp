// finishCommand (tools/plano/CommandOutcome.h), the one end of every computing command.
#include "plano/CommandOutcome.h"

#include <gtest/gtest.h>

#include <fstream>
#include <limits>

#include "core/Cancellation.h"
#include "core/Error.h"
#include "mesh/Generators.h"
#include "support/TestMeshes.h"

namespace plano::cli {
namespace {

class CommandOutcomeTest : public ::testing::Test {
 protected:
  std::string path(const std::string& name) const { return (dir_ / name).string(); }
  nlohmann::json report() const {
    std::ifstream in(dir_ / "r.json");
    return nlohmann::json::parse(in);
  }
  /// The message of the Error(Numerical) that finishCommand throws; fails otherwise.
  std::string numericalFailureOf(const CommandOutcome& outcome, bool keepPartial, const PolygonMesh& mesh) {
    try {
      finishCommand("test", outcome, keepPartial, {{path("out.obj"), &mesh}}, {{"command", "test"}}, path("r.json"));
    } catch (const Error& e) {
      EXPECT_EQ(e.kind(), ErrorKind::Numerical);
      return e.what();
    }
    ADD_FAILURE() << "no numerical failure";
    return {};
  }
  test::TempDir dir_;
  PolygonMesh cube_ = generate::cube();
};

TEST_F(CommandOutcomeTest, SuccessWritesTheMeshAndTheStatus) {
  finishCommand("test", {"converged", ""}, false, {{path("out.obj"), &cube_}}, {{"command", "test"}}, path("r.json"));
  EXPECT_TRUE(std::filesystem::exists(dir_ / "out.obj"));
  EXPECT_EQ(report()["status"], "converged");
  EXPECT_EQ(report()["output_written"], true);
  EXPECT_FALSE(report().contains("reason"));
}

TEST_F(CommandOutcomeTest, FailureWritesOnlyTheReportWithoutKeepPartial) {
  const std::string message = numericalFailureOf({"iteration_limit", "cap of 3 iterations reached"}, false, cube_);
  EXPECT_NE(message.find("test: cap of 3 iterations reached; no output written"), std::string::npos) << message;
  EXPECT_FALSE(std::filesystem::exists(dir_ / "out.obj"));
  EXPECT_EQ(report()["status"], "iteration_limit");
  EXPECT_EQ(report()["reason"], "cap of 3 iterations reached");
  EXPECT_EQ(report()["output_written"], false);
}

TEST_F(CommandOutcomeTest, FailureWithKeepPartialWritesTheMeshAndSaysSo) {
  const std::string message = numericalFailureOf({"iteration_limit", "cap reached"}, true, cube_);
  EXPECT_NE(message.find("partial result written to " + path("out.obj")), std::string::npos) << message;
  EXPECT_TRUE(std::filesystem::exists(dir_ / "out.obj"));
  EXPECT_EQ(report()["output_written"], true);
}

TEST_F(CommandOutcomeTest, NonFiniteResultIsAFailureNeverWrittenEvenWithKeepPartial) {
  PolygonMesh broken = cube_;
  broken.vertices(3, 1) = std::numeric_limits<double>::quiet_NaN();
  const std::string message = numericalFailureOf({"converged", ""}, true, broken);
  EXPECT_NE(message.find("non-finite"), std::string::npos) << message;
  EXPECT_FALSE(std::filesystem::exists(dir_ / "out.obj"));
  EXPECT_EQ(report()["status"], "non_finite");
  EXPECT_EQ(report()["output_written"], false);
}

TEST_F(CommandOutcomeTest, CoordinatesNoMeshFileMayHoldAreAFailureNeverWritten) {
  // explore --amplitude 1e300 wrote a mesh that plano itself refused to read (beyond 1e100).
  PolygonMesh huge = cube_;
  huge.vertices(5, 2) = 1e200;
  const std::string message = numericalFailureOf({"converged", ""}, true, huge);
  EXPECT_NE(message.find("coordinates beyond 1e+100"), std::string::npos) << message;
  EXPECT_FALSE(std::filesystem::exists(dir_ / "out.obj"));
  EXPECT_EQ(report()["status"], "out_of_range");
}

TEST_F(CommandOutcomeTest, InterruptionBeforeWritingWritesNothing) {
  requestCancellation();
  EXPECT_THROW(
      finishCommand("test", {"converged", ""}, true, {{path("out.obj"), &cube_}}, {{"command", "test"}}, path("r.json")),
      Interrupted);
  clearCancellation();
  EXPECT_FALSE(std::filesystem::exists(dir_ / "out.obj"));
  EXPECT_FALSE(std::filesystem::exists(dir_ / "r.json"));
}

}  // namespace
}  // namespace plano::cli
