// Ctrl-C (SIGINT) and SIGTERM during a long run of the plano tool: exit code 130,
// "interrupted" on stderr, the previous output file untouched, no temporary file left,
// and the report (when asked for) with status "interrupted". Each child is killed when
// it outlives its deadline, so a broken handler fails the test instead of hanging it.
#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "mesh/Generators.h"
#include "mesh/MeshIO.h"
#include "support/TestMeshes.h"

namespace plano::test {
namespace {

using namespace std::chrono_literals;

std::string slurp(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

struct Interrupted {
  int exitCode = -1;  ///< -1: killed by a signal or by the deadline.
  std::string err;
};

/// Start plano with `arguments`, send `signal` after `delay`, wait at most `deadline`.
Interrupted runAndSignal(const std::vector<std::string>& arguments, int signal, std::chrono::milliseconds delay,
                         const std::filesystem::path& errPath, std::chrono::seconds deadline = 60s) {
  std::vector<std::string> args{PLANO_TOOL_PATH};
  args.insert(args.end(), arguments.begin(), arguments.end());
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  const pid_t child = ::fork();
  if (child == 0) {
    const int err = ::open(errPath.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    const int null = ::open("/dev/null", O_RDWR);
    ::dup2(null, 0);
    ::dup2(null, 1);
    ::dup2(err, 2);
    ::execv(argv[0], argv.data());
    ::_exit(127);
  }
  Interrupted result;
  if (child < 0) return result;
  std::this_thread::sleep_for(delay);
  ::kill(child, signal);
  const auto stop = std::chrono::steady_clock::now() + deadline;
  int status = 0;
  while (::waitpid(child, &status, WNOHANG) == 0) {
    if (std::chrono::steady_clock::now() > stop) {
      ::kill(child, SIGKILL);
      ::waitpid(child, &status, 0);
      ADD_FAILURE() << "plano did not stop within " << deadline.count() << " s of the signal";
      break;
    }
    std::this_thread::sleep_for(20ms);
  }
  if (WIFEXITED(status)) result.exitCode = WEXITSTATUS(status);
  result.err = slurp(errPath);
  return result;
}

/// Names of the files in `dir` (temporary files of atomic writes start with '.').
std::vector<std::string> fileNames(const std::filesystem::path& dir) {
  std::vector<std::string> names;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) names.push_back(entry.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

class InterruptCommand : public ::testing::Test {
 protected:
  void SetUp() override {
    // Large enough that no run below can finish before the signal: the tolerance 0 is
    // never reached and the iteration cap is huge.
    writeMesh(dir_ / "big.obj", generate::hyparGrid(120, 0.5));
    writeMesh(dir_ / "previous.obj", generate::cube());
    ::mkdir((dir_.path().string() + "/logs").c_str(), 0755);
  }
  std::string path(const std::string& name) const { return (dir_ / name).string(); }
  std::filesystem::path log() const { return dir_ / "logs" / "stderr"; }
  TempDir dir_;
};

TEST_F(InterruptCommand, SigintLeavesThePreviousOutputAndNoTemporaryFile) {
  const std::string previous = slurp(dir_ / "previous.obj");
  const auto before = fileNames(dir_.path());
  const Interrupted run = runAndSignal({"planarize", path("big.obj"), "-o", path("previous.obj"), "--method", "shapeup",
                                       "--tolerance", "0", "--max-iterations", "1000000"},
                                      SIGINT, 700ms, log());
  EXPECT_EQ(run.exitCode, 130) << run.err;
  EXPECT_NE(run.err.find("interrupted"), std::string::npos) << run.err;
  EXPECT_EQ(slurp(dir_ / "previous.obj"), previous);
  EXPECT_EQ(fileNames(dir_.path()), before);
}

TEST_F(InterruptCommand, InPlaceRunKeepsTheInputAndReportsInterrupted) {
  const std::string input = slurp(dir_ / "big.obj");
  const Interrupted run =
      runAndSignal({"planarize", path("big.obj"), "--in-place", "-o", path("big.obj"), "--tolerance", "0",
                    "--max-iterations", "1000000", "--method", "shapeup", "--report", path("r.json"), "--keep-partial"},
                   SIGINT, 700ms, log());
  EXPECT_EQ(run.exitCode, 130) << run.err;
  EXPECT_EQ(slurp(dir_ / "big.obj"), input);
  std::ifstream in(dir_ / "r.json");
  ASSERT_TRUE(in) << "no report";
  const nlohmann::json report = nlohmann::json::parse(in);
  EXPECT_EQ(report["status"], "interrupted");
  EXPECT_EQ(report["output_written"], false);
  EXPECT_NE(report["reason"].get<std::string>().find("stopped during"), std::string::npos) << report.dump();
  EXPECT_EQ(fileNames(dir_.path()), (std::vector<std::string>{"big.obj", "logs", "previous.obj", "r.json"}));
}

TEST_F(InterruptCommand, SigtermStopsADeformationWithoutWritingIt) {
  std::ofstream(dir_ / "c.json") << R"({"fixed": [0, 120], "handles": [{"vertex": 14640, "position": [1.0, 1.0, 0.8]}]})";
  const std::string previous = slurp(dir_ / "previous.obj");
  const Interrupted run =
      runAndSignal({"deform", path("big.obj"), "--constraints", path("c.json"), "-o", path("previous.obj"),
                    "--max-iterations", "100000", "--tolerance", "1e-300"},
                   SIGTERM, 700ms, log());
  EXPECT_EQ(run.exitCode, 130) << run.err;
  EXPECT_NE(run.err.find("interrupted"), std::string::npos) << run.err;
  EXPECT_EQ(slurp(dir_ / "previous.obj"), previous);
}

TEST_F(InterruptCommand, SigintStopsGenerateBeforeItWrites) {
  // It ran to the end and replaced the output (800 MB for -n 3000). The generator itself
  // runs on (3 s here); nothing is written after it.
  const std::string previous = slurp(dir_ / "previous.obj");
  const auto before = fileNames(dir_.path());
  const Interrupted run =
      runAndSignal({"generate", "translational", "-n", "1000", "-o", path("previous.obj")}, SIGINT, 300ms, log());
  EXPECT_EQ(run.exitCode, 130) << run.err;
  EXPECT_EQ(slurp(dir_ / "previous.obj"), previous);
  EXPECT_EQ(fileNames(dir_.path()), before);
}

TEST_F(InterruptCommand, SigintStopsTheNullSpaceBasisOfALargeMesh) {
  writeMesh(dir_ / "grid.obj", generate::translationalSurface(300, 300));
  // It ran to the end (7 s here, minutes on a large mesh) and exited 0.
  const Interrupted run = runAndSignal({"subspace", path("grid.obj"), "--report", path("r.json")}, SIGINT, 1000ms, log());
  EXPECT_EQ(run.exitCode, 130) << run.err;
  std::ifstream in(dir_ / "r.json");
  ASSERT_TRUE(in) << "no report";
  EXPECT_EQ(nlohmann::json::parse(in)["status"], "interrupted");
}

TEST_F(InterruptCommand, SigintStopsASparseShapeBetweenItsIterations) {
  // The orthogonal matching pursuit ignored the signal: this one runs 16 s.
  writeMesh(dir_ / "grid.obj", generate::translationalSurface(150, 150));
  const std::string previous = slurp(dir_ / "previous.obj");
  const auto start = std::chrono::steady_clock::now();
  const Interrupted run = runAndSignal({"shapes", path("grid.obj"), "--vertex", "7000", "--kind", "sparse", "-o",
                                       path("previous.obj"), "--max-support", "100000"},
                                      SIGINT, 1000ms, log());
  EXPECT_EQ(run.exitCode, 130) << run.err;
  EXPECT_LT(std::chrono::steady_clock::now() - start, 5s) << run.err;
  EXPECT_EQ(slurp(dir_ / "previous.obj"), previous);
}

}  // namespace
}  // namespace plano::test
