// Defective constraint files given to the commands that read them (deform --constraints,
// planarize --fixed, prescribe --constraints): bad input, exit 3, a short message.
#include <gtest/gtest.h>

#include <fstream>

#include "mesh/Generators.h"
#include "mesh/MeshIO.h"
#include "support/TestMeshes.h"

namespace plano {
namespace {

TEST(ConstraintsFileCommand, DefectiveFilesAreBadInputOfEveryCommandThatReadsThem) {
  const test::TempDir dir;
  writeMesh(dir / "grid.obj", generate::translationalSurface(3, 3));
  // 100 000 levels of arrays crashed the tool (SIGSEGV) while it built the message; a
  // number beyond a double and a folder were internal errors (exit 1).
  std::ofstream(dir / "deep.json") << "{\"fixed\":" << std::string(100000, '[') << std::string(100000, ']') << "}";
  std::ofstream(dir / "overflow.json") << R"({"fixed": [0, 1e400]})";
  std::filesystem::create_directory(dir / "folder.json");
  const std::string grid = (dir / "grid.obj").string(), out = (dir / "out.obj").string();
  for (const std::string file : {"deep.json", "overflow.json", "folder.json"}) {
    const std::string constraints = (dir / file).string();
    for (const std::string& command : {"deform " + grid + " --constraints " + constraints + " -o " + out,
                                       "planarize " + grid + " --fixed " + constraints + " -o " + out,
                                       "prescribe " + grid + " --map scale --constraints " + constraints + " -o " + out}) {
      const test::ToolResult result = test::runTool("-q " + command);
      EXPECT_EQ(result.exitCode, 3) << command << "\n" << result.err.substr(0, 500);
      EXPECT_NE(result.err.find(constraints), std::string::npos) << result.err.substr(0, 500);
      EXPECT_LT(result.err.size(), 400u) << result.err.substr(0, 500);
      EXPECT_FALSE(std::filesystem::exists(out)) << command;
    }
  }
}

}  // namespace
}  // namespace plano
