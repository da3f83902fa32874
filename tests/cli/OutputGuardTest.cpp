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

void expectRefused(const std::string& input, const std::string& output) {
  try {
    checkOutputPath(input, output, false);
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
  EXPECT_NO_THROW(checkOutputPath(path("in.obj"), path("out.obj"), false));
  EXPECT_NO_THROW(checkOutputPath(path("in.obj"), path("sub/in.obj"), false));
  EXPECT_NO_THROW(checkOutputPath(path("in.obj"), path("in.obj"), true));
  EXPECT_NO_THROW(checkOutputPath(path("in.obj"), "", false));
}

}  // namespace
}  // namespace plano::cli
