// Reports of runs whose text is not UTF-8 (file names in another encoding): JSON text must
// be UTF-8, and nlohmann refuses to write anything else. Such bytes are replaced by U+FFFD.
#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>

#include "mesh/Generators.h"
#include "mesh/MeshIO.h"
#include "support/TestMeshes.h"

namespace plano {
namespace {

nlohmann::json readJson(const std::filesystem::path& path) {
  std::ifstream in(path);
  return nlohmann::json::parse(in);
}

TEST(ReportEncodingCommand, ANonUtf8FileNameInTheReportIsReplacedNotAnInternalError) {
  // Was "internal error: [json.exception.type_error.316] invalid UTF-8 byte", exit 1.
  const test::TempDir dir;
  const std::string missing = (dir / "nope\xff.obj").string();
  const test::ToolResult result = test::runTool("info " + test::quotedPath(missing) + " --report " +
                                                (dir / "r.json").string());
  EXPECT_EQ(result.exitCode, 3) << result.err;
  const nlohmann::json report = readJson(dir / "r.json");
  EXPECT_EQ(report["status"], "bad_input");
  EXPECT_NE(report["reason"].get<std::string>().find("nope\xEF\xBF\xBD.obj"), std::string::npos) << report.dump();
}

TEST(ReportEncodingCommand, APlanarizationOfANonUtf8FileSucceedsWithItsReport) {
  // It wrote the mesh, then exited 1 on the report.
  const test::TempDir dir;
  const std::filesystem::path input = dir / "h\xff.obj", output = dir / "p\xff.obj";
  writeMesh(input, generate::hyparGrid(3));
  const test::ToolResult result = test::runTool("-q planarize " + test::quotedPath(input) + " -o " +
                                                test::quotedPath(output) + " --report " + (dir / "r.json").string());
  EXPECT_EQ(result.exitCode, 0) << result.err;
  EXPECT_TRUE(std::filesystem::exists(output));
  EXPECT_NE(readJson(dir / "r.json")["input"].get<std::string>().find("h\xEF\xBF\xBD.obj"), std::string::npos);
}

}  // namespace
}  // namespace plano
