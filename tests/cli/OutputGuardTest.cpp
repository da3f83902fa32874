#include "plano/OutputGuard.h"

#include <gtest/gtest.h>

#include <fstream>

#include "core/Error.h"
#include "support/TestMeshes.h"

namespace plano::cli {
namespace {

class OutputGuard : public ::testing::Test {
 protected:
  void SetUp() override {
    std::filesystem::create_directories(dir_ / "sub");
    std::ofstream(dir_ / "in.obj") << "v 0 0 0\n";
  }
  std::string path(const std::string& name) const { return (dir_ / name).string(); }

  test::TempDir dir_;
};

/// A command reading `input` and writing `output` (--output), with --in-place available.
CommandPaths reading(const std::string& input, const std::string& output, bool inPlace = false) {
  return {{input}, {{"--output", output}}, inPlace, true};
}

void expectRefused(const std::string& input, const std::string& output) {
  try {
    checkCommandPaths(reading(input, output));
    FAIL() << output << " was accepted as output for " << input;
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::Usage);
    EXPECT_NE(std::string(e.what()).find("--in-place"), std::string::npos) << e.what();
  }
}

TEST_F(OutputGuard, RefusesTheInputPathItself) { expectRefused(path("in.obj"), path("in.obj")); }

TEST_F(OutputGuard, RefusesSpellingsOfTheSameFile) {
  expectRefused(path("in.obj"), path("sub/../in.obj"));
  expectRefused(path("in.obj"), path("./in.obj"));
}

TEST_F(OutputGuard, RefusesSymbolicAndHardLinksToTheInput) {
  std::filesystem::create_symlink(path("in.obj"), path("link.obj"));
  std::filesystem::create_hard_link(path("in.obj"), path("hard.obj"));
  expectRefused(path("in.obj"), path("link.obj"));
  expectRefused(path("in.obj"), path("hard.obj"));
}

TEST_F(OutputGuard, AcceptsOtherFilesAndInPlace) {
  EXPECT_NO_THROW(checkCommandPaths(reading(path("in.obj"), path("out.obj"))));
  EXPECT_NO_THROW(checkCommandPaths(reading(path("in.obj"), path("sub/in.obj"))));
  EXPECT_NO_THROW(checkCommandPaths(reading(path("in.obj"), path("in.obj"), true)));
  EXPECT_NO_THROW(checkCommandPaths(reading(path("in.obj"), "")));
}

/// The message of checkCommandPaths' usage error, or "" when the paths pass.
std::string refusal(const CommandPaths& paths) {
  try {
    checkCommandPaths(paths);
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::Usage);
    return e.what();
  }
  return "";
}

TEST_F(OutputGuard, ACommandsWrittenFilesMustGoToExistingFoldersAndSpareItsInputsAndEachOther) {
  const std::string mesh = path("in.obj"), constraints = path("c.json"), out = path("out.obj");
  std::ofstream(constraints) << "{}";
  const auto writing = [&](std::vector<WrittenFile> outputs, bool inPlace = false) {
    return refusal({{mesh, constraints}, std::move(outputs), inPlace, true});
  };
  EXPECT_EQ(writing({{"--output", out}, {"--primal", ""}, {"--report", path("sub/r.json")}}), "");
  // A folder that does not exist, for the mesh or the report: refused before the run.
  EXPECT_NE(writing({{"--output", path("missing/out.obj")}}).find("--output " + path("missing/out.obj") +
                                                                   ": the folder"),
            std::string::npos);
  EXPECT_NE(writing({{"--output", out}, {"--report", path("missing/r.json")}}).find("does not exist"),
            std::string::npos);
  // Over an input: the mesh only with --in-place, and only by the result mesh.
  EXPECT_EQ(writing({{"--output", mesh}}, true), "");
  EXPECT_NE(writing({{"--output", out}, {"--report", mesh}}, true).find("(write elsewhere)"), std::string::npos);
  EXPECT_NE(writing({{"--output", constraints}}, true).find("is the input file"), std::string::npos);
  // Two written files in one.
  EXPECT_NE(writing({{"--output", out}, {"--primal", path("sub/../out.obj")}}).find("is also the file of --output"),
            std::string::npos);
}

}  // namespace
}  // namespace plano::cli
