// Constraint files (mesh/Constraints.h) that are not what they should be: every defect is
// Error(BadInput) with a short message naming it, never a crash or another exception.
#include "mesh/Constraints.h"

#include <gtest/gtest.h>

#include <fstream>
#include <string>

#include "core/Error.h"
#include "support/TestMeshes.h"

namespace plano {
namespace {

/// The message of the BadInput error that reading `text` as a constraints file of a
/// 10-vertex mesh raises; fails the test when it raises none or another kind.
std::string badInputMessage(const std::string& text) {
  const test::TempDir dir;
  std::ofstream(dir / "c.json") << text;
  try {
    readConstraints(dir / "c.json", 10);
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::BadInput) << e.what();
    return e.what();
  }
  ADD_FAILURE() << "accepted: " << text.substr(0, 80);
  return {};
}

TEST(Constraints, DeeplyNestedValueIsRefusedWithAShortMessage) {
  // The message used to embed the value's dump: deep enough nesting overflowed the stack of
  // the recursive dump, and 20 000 levels made a 40 000-character message.
  const std::string deep = "{\"fixed\": " + std::string(100000, '[') + std::string(100000, ']') + "}";
  const std::string message = badInputMessage(deep);
  EXPECT_NE(message.find("fixed[0]: vertex index must be an integer, got an array"), std::string::npos) << message;
  EXPECT_LT(message.size(), 300u) << message.substr(0, 300);
}

TEST(Constraints, LongStringIsQuotedOnlyInPart) {
  const std::string message = badInputMessage(R"({"fixed": [")" + std::string(5000, 'x') + R"("]})");
  EXPECT_NE(message.find("got string \"xxx"), std::string::npos) << message;
  EXPECT_LT(message.size(), 300u);
}

TEST(Constraints, NumberTooLargeForADoubleIsBadInput) {
  // nlohmann throws out_of_range, not parse_error, for 1e400: it was an internal error.
  const std::string message = badInputMessage(R"({"fixed": [0, 1e400]})");
  EXPECT_NE(message.find("invalid JSON"), std::string::npos) << message;
}

TEST(Constraints, IndexBeyondInt64IsNamedAsWritten) {
  // Read as a long long it wrapped to -1: "vertex -1 is out of range".
  const std::string message = badInputMessage(R"({"fixed": [18446744073709551615]})");
  EXPECT_NE(message.find("vertex 18446744073709551615 is out of range"), std::string::npos) << message;
  EXPECT_NE(badInputMessage(R"({"fixed": [-3]})").find("vertex -3 is out of range"), std::string::npos);
}

TEST(Constraints, FolderIsBadInputNamingIt) {
  // An ifstream opens a folder and fails only when read, with basic_filebuf's exception.
  const test::TempDir dir;
  std::filesystem::create_directory(dir / "c.json");
  try {
    readConstraints(dir / "c.json", 10);
    FAIL() << "a folder was read as constraints";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::BadInput);
    EXPECT_NE(std::string(e.what()).find("is a folder"), std::string::npos) << e.what();
  }
}

TEST(Constraints, NonNumericPositionNamesTheCoordinate) {
  const std::string message =
      badInputMessage(R"({"handles": [{"vertex": 1, "position": [0, [[[1]]], 2]}]})");
  EXPECT_NE(message.find("handles[0].position[1] must be a number, got an array of size 1"), std::string::npos)
      << message;
}

TEST(Constraints, ValidFileIsRead) {
  const test::TempDir dir;
  std::ofstream(dir / "c.json") << R"({"fixed": [0, 9], "handles": [{"vertex": 3, "position": [1, 2, 3]}]})";
  const PositionalConstraints constraints = readConstraints(dir / "c.json", 10);
  EXPECT_EQ(constraints.fixed, (std::vector<Index>{0, 9}));
  ASSERT_EQ(constraints.handles.size(), 1u);
  EXPECT_EQ(constraints.handles[0].vertex, 3);
}

}  // namespace
}  // namespace plano
