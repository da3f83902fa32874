// The files a command writes, at the level of the tool: refused before any computation
// when they cannot be written, written all or none, and written through links and into
// FIFOs and devices rather than replacing them with regular files.
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <thread>

#include "mesh/Generators.h"
#include "mesh/MeshIO.h"
#include "support/TestMeshes.h"

namespace plano {
namespace {

std::string slurp(const std::filesystem::path& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

/// Let a reader blocked in opening `fifo` go (it reads nothing) when no writer came.
void releaseReader(const std::string& fifo) {
  const int fd = ::open(fifo.c_str(), O_WRONLY | O_NONBLOCK);
  if (fd >= 0) ::close(fd);
}

class OutputFilesCommand : public ::testing::Test {
 protected:
  void SetUp() override {
    writeMesh(dir_ / "cube.obj", generate::cube());
    writeMesh(dir_ / "hypar.obj", generate::hyparGrid(3));
  }
  std::string path(const std::string& name) const { return (dir_ / name).string(); }
  test::TempDir dir_;
};

TEST_F(OutputFilesCommand, UnwritableOutputsAreUsageErrorsBeforeTheComputation) {
  // Each of these computed first (subdivide --levels 4 for seconds), then failed; the
  // planarization wrote out.obj before its report failed.
  std::filesystem::create_directory(dir_ / "outdir.obj");
  std::filesystem::create_directory(dir_ / "rdir.json");
  for (const std::string& command :
       {"subdivide " + path("cube.obj") + " --levels 4 -o " + path("out.xyz"),
        "subdivide " + path("cube.obj") + " --levels 4 -o " + path("outdir.obj"),
        "planarize " + path("hypar.obj") + " -o " + path("out.obj") + " --report " + path("rdir.json"),
        "dual " + path("cube.obj") + " -o " + path("out.obj") + " --primal " + path("p.xyz"),
        "subdivide " + path("cube.obj") + " -o \"\"", "info " + path("cube.obj") + " --report \"\""}) {
    const auto start = std::chrono::steady_clock::now();
    const test::ToolResult result = test::runTool("-q " + command);
    EXPECT_EQ(result.exitCode, 2) << command << "\n" << result.err;
    EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(3)) << command;
    EXPECT_FALSE(std::filesystem::exists(dir_ / "out.obj")) << command;
    EXPECT_FALSE(std::filesystem::exists(dir_ / "out.xyz")) << command;
  }
  EXPECT_NE(test::runTool("subdivide " + path("cube.obj") + " -o \"\"").err.find("--output: the path is empty"),
            std::string::npos);
}

TEST_F(OutputFilesCommand, DualLeavesItsFirstOutputWhenTheSecondCannotBeWritten) {
  std::ofstream(dir_ / "d.obj") << "KEEP\n";
  std::filesystem::create_directory(dir_ / "p.obj");
  const test::ToolResult result = test::runTool("-q dual " + path("cube.obj") + " -o " + path("d.obj") +
                                                " --primal " + path("p.obj") + " --eigenshape 0");
  EXPECT_EQ(result.exitCode, 2) << result.err;
  EXPECT_EQ(slurp(dir_ / "d.obj"), "KEEP\n");
  EXPECT_EQ(result.out.find("->"), std::string::npos) << result.out;
}

TEST_F(OutputFilesCommand, AReportThroughASymbolicLinkReplacesTheFileItNames) {
  std::ofstream(dir_ / "real.json") << "{}\n";
  std::filesystem::create_symlink("real.json", dir_ / "link.json");
  const test::ToolResult result = test::runTool("-q info " + path("cube.obj") + " --report " + path("link.json"));
  ASSERT_EQ(result.exitCode, 0) << result.err;
  EXPECT_TRUE(std::filesystem::is_symlink(dir_ / "link.json"));
  EXPECT_EQ(nlohmann::json::parse(slurp(dir_ / "real.json"))["vertices"], 8);
}

TEST_F(OutputFilesCommand, AReportIntoAFifoOrDevNullLeavesTheNodeInPlace) {
  // Both were replaced by regular files: /dev/null itself when run as root.
  ASSERT_EQ(::mkfifo(path("fifo").c_str(), 0644), 0);
  std::string received;
  std::thread reader([&] { received = slurp(dir_ / "fifo"); });
  const test::ToolResult result = test::runTool("-q info " + path("cube.obj") + " --report " + path("fifo"));
  if (result.exitCode != 0) releaseReader(path("fifo"));
  reader.join();
  EXPECT_EQ(result.exitCode, 0) << result.err;
  EXPECT_EQ(nlohmann::json::parse(received, nullptr, false)["faces"], 6) << received;
  struct stat info {};
  ASSERT_EQ(::lstat(path("fifo").c_str(), &info), 0);
  EXPECT_TRUE(S_ISFIFO(info.st_mode));

  EXPECT_EQ(test::runTool("-q info " + path("cube.obj") + " --report /dev/null").exitCode, 0);
  ASSERT_EQ(::lstat("/dev/null", &info), 0);
  EXPECT_TRUE(S_ISCHR(info.st_mode));
}

}  // namespace
}  // namespace plano
