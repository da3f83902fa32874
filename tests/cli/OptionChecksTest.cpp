// Checks every command's options get before it runs (tools/plano/main.cpp).
#include <gtest/gtest.h>

#include <fstream>

#include "mesh/Generators.h"
#include "mesh/MeshIO.h"
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

}  // namespace
}  // namespace plano
