// Checks every command's options get before it runs (tools/plano/main.cpp).
#include <gtest/gtest.h>

#include <fstream>
#include <utility>
#include <vector>

#include "mesh/Generators.h"
#include "mesh/MeshIO.h"
#include "support/ScopedEnvironment.h"
#include "support/TestMeshes.h"

namespace plano {
namespace {

TEST(CommandOptions, NonFiniteNumbersAreUsageErrorsOfEveryCommandAndWriteNothing) {
  // A NaN passes every "> 0" range check: before, `subdivide --tolerance nan` and `subspace
  // --rank-tolerance nan` ran, and `explore --amplitude nan` or `embed --height nan` failed
  // as numerical errors after their work.
  const test::TempDir dir;
  writeMesh(dir / "grid.obj", generate::translationalSurface(4, 4));
  {
    std::ofstream(dir / "c.json") << R"({"fixed": [0, 1, 2, 3, 4],
                                        "handles": [{"vertex": 24, "position": [4, 4, 1]}]})";
  }
  const std::string grid = (dir / "grid.obj").string(), out = (dir / "out.obj").string();
  const std::string constraints = (dir / "c.json").string();
  for (const std::string& command :
       {"subdivide " + grid + " -o " + out + " --tolerance nan", "subspace " + grid + " --rank-tolerance nan",
        "explore " + grid + " -o " + out + " --amplitude nan", "embed " + grid + " -o " + out + " --height inf",
        "subspace " + grid + " --space vertical --up 0,nan,1", "info " + grid + " --tolerance -inf",
        "deform " + grid + " --constraints " + constraints + " -o " + out + " --planarity-tolerance nan",
        "prescribe " + grid + " --map scale --strength nan -o " + out,
        "planarize " + grid + " -o " + out + " --closeness inf"}) {
    const test::ToolResult result = test::runTool("-q " + command);
    EXPECT_EQ(result.exitCode, 2) << command << "\n" << result.err;
    EXPECT_FALSE(std::filesystem::exists(out)) << command;
  }
  // Finite values of the same options run.
  EXPECT_EQ(test::runTool("-q explore " + grid + " -o " + out + " --amplitude 0.02").exitCode, 0);
  EXPECT_TRUE(std::filesystem::exists(out));
}

TEST(CommandOptions, ANegativeThreadCountOrAMalformedPlanoThreadsIsAUsageErrorBeforeTheRun) {
  const test::TempDir dir;
  writeMesh(dir / "grid.obj", generate::hyparGrid(6, 0.5));
  const std::string planarize = "-q planarize " + (dir / "grid.obj").string() + " -o " + (dir / "out.obj").string();
  test::ToolResult result = test::runTool("--threads -1 " + planarize);
  EXPECT_EQ(result.exitCode, 2) << result.err;
  EXPECT_NE(result.err.find("--threads"), std::string::npos) << result.err;
  {
    const test::ScopedEnvironment threads("PLANO_THREADS", "many");
    result = test::runTool(planarize);
    EXPECT_EQ(result.exitCode, 2) << result.err;
    EXPECT_NE(result.err.find("PLANO_THREADS is 'many'"), std::string::npos) << result.err;
    EXPECT_FALSE(std::filesystem::exists(dir / "out.obj"));
    // --threads decides, so the variable is not read.
    EXPECT_EQ(test::runTool("--threads 2 " + planarize).exitCode, 0);
  }
  EXPECT_TRUE(std::filesystem::exists(dir / "out.obj"));
}

TEST(CommandOptions, WrittenFilesOverInputsOrIntoMissingFoldersAreRefusedBeforeTheRun) {
  // `subdivide -o` named its input: until 2026-12-05 it was overwritten without --in-place.
  const test::TempDir dir;
  writeMesh(dir / "grid.obj", generate::translationalSurface(4, 4));
  const std::string grid = (dir / "grid.obj").string(), out = (dir / "out.obj").string();
  const std::string missing = (dir / "missing").string();
  const auto before = std::filesystem::last_write_time(grid);
  for (const std::string& command :
       {"subdivide " + grid + " -o " + grid, "explore " + grid + " -o " + out + " --report " + grid,
        "subdivide " + grid + " -o " + missing + "/out.obj",
        "subdivide " + grid + " -o " + out + " --report " + missing + "/r.json",
        "subdivide " + grid + " -o " + out + " --report " + out}) {
    const test::ToolResult result = test::runTool("-q " + command);
    EXPECT_EQ(result.exitCode, 2) << command << "\n" << result.err;
    EXPECT_FALSE(std::filesystem::exists(dir / "out.obj")) << command;
  }
  EXPECT_EQ(std::filesystem::last_write_time(grid), before);
  EXPECT_EQ(test::runTool("-q subdivide " + grid + " --in-place --linear").exitCode, 0);
}

TEST(CommandOptions, OptionsThatWouldBeIgnoredOrOutOfTheirRangeAreUsageErrorsNamingThem) {
  // Each ran before: silently ignoring the option, or (explore --amplitude 1e300) writing a
  // mesh that plano refuses to read, or (embed --vertex 99) failing as bad input after the work.
  const test::TempDir dir;
  writeMesh(dir / "grid.obj", generate::translationalSurface(4, 4));
  std::ofstream(dir / "c.json") << R"({"fixed": [0], "handles": [{"vertex": 24, "position": [1, 1, 1]}]})";
  const std::string grid = (dir / "grid.obj").string(), out = (dir / "out.obj").string();
  const std::string constraints = (dir / "c.json").string();
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"explore " + grid + " -o " + out + " --amplitude 1e300", "--amplitude: must be in [-100, 100] (got 1e300)"},
      {"shapes " + grid + " --vertex 3 -o " + out + " --amplitude -1e9", "--amplitude: must be in [-100, 100]"},
      {"embed " + grid + " -o " + out + " --height 1e200", "--height: must be in [-100, 100]"},
      {"prescribe " + grid + " --map warp --strength 2 -o " + out, "--strength: must be in (-2, 2) (got 2)"},
      {"prescribe " + grid + " --map rotate --point 1 2 3 -o " + out, "--point is the centre of --pivot point"},
      {"embed " + grid + " -o " + out + " --lift handle --vertex -3", "--vertex: must be >= 0 (got -3)"},
      {"embed " + grid + " -o " + out + " --lift handle --vertex 99", "--vertex 99 is out of range"},
      {"embed " + grid + " -o " + out + " --vertex 3", "--vertex is the handle of --lift handle"},
      {"deform " + grid + " --constraints " + constraints + " -o " + out + " --base " + grid, "--base requires --multires"},
      {"deform " + grid + " --constraints " + constraints + " -o " + out + " --scheme four-point",
       "--scheme requires --multires"},
      {"deform " + grid + " --constraints " + constraints + " -o " + out + " --multires-level 1",
       "--multires-level requires --multires"},
      {"subspace " + grid + " --rank-tolerance -1", "--rank-tolerance: must be > 0 (got -1)"},
  };
  for (const auto& [command, message] : cases) {
    const test::ToolResult result = test::runTool("-q " + command);
    EXPECT_EQ(result.exitCode, 2) << command << "\n" << result.err;
    EXPECT_NE(result.err.find(message), std::string::npos) << command << "\n" << result.err;
    EXPECT_FALSE(std::filesystem::exists(out)) << command;
  }
}

TEST(CommandOptions, MessagesOfNumericChecksAreShortAndNameTheValueGiven) {
  // CLI11's own ranges printed the largest double in 300 digits; the generator named the
  // number of quads around the axis (2n), not the -n given.
  const test::TempDir dir;
  writeMesh(dir / "grid.obj", generate::translationalSurface(4, 4));
  const std::string grid = (dir / "grid.obj").string(), out = (dir / "out.obj").string();
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"info " + grid + " --tolerance 0", "--tolerance: must be > 0 (got 0)"},
      {"planarize " + grid + " -o " + out + " --tolerance inf", "--tolerance: must be finite (got inf)"},
      {"planarize " + grid + " -o " + out + " --closeness -1", "--closeness: must be >= 0 (got -1)"},
      {"explore " + grid + " -o " + out + " --eigenshapes 0", "--eigenshapes: must be > 0 (got 0)"},
      {"generate revolution -n 1 -o " + out, "-n must be at least 2 (got 1)"},
      {"planarize " + grid, "--output is required"},
  };
  for (const auto& [command, message] : cases) {
    const test::ToolResult result = test::runTool("-q " + command);
    EXPECT_EQ(result.exitCode, 2) << command << "\n" << result.err;
    EXPECT_NE(result.err.find(message), std::string::npos) << command << "\n" << result.err;
    EXPECT_LT(result.err.size(), 300u) << result.err;
  }
}

}  // namespace
}  // namespace plano
