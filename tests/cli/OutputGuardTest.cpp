#include "plano/OutputGuard.h"

#include <gtest/gtest.h>

#include <fcntl.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <unistd.h>

#include <fstream>
#include <sstream>
#include <thread>

#include "core/Cancellation.h"
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

TEST_F(OutputGuard, MeshOutputsNeedAKnownFormatAndAFileNotAFolder) {
  // Checked after the computation before: subdivide --levels 4 -o out.xyz computed for
  // seconds, then failed; -o naming a folder the same.
  std::filesystem::create_directory(dir_ / "folder.obj");
  EXPECT_NE(refusal(reading(path("in.obj"), path("out.xyz"))).find("--output " + path("out.xyz") +
                                                                   ": unknown mesh format '.xyz'"),
            std::string::npos);
  EXPECT_NE(refusal(reading(path("in.obj"), path("folder.obj"))).find("is a folder"), std::string::npos);
  EXPECT_NE(refusal({{path("in.obj")}, {{"--output", path("out.obj")}, {"--report", path("folder.obj")}}, false, true})
                .find("is a folder"),
            std::string::npos);
  // A report may have any name.
  EXPECT_EQ(refusal({{path("in.obj")}, {{"--output", path("out.obj")}, {"--report", path("r.txt")}}, false, true}), "");
}

TEST_F(OutputGuard, AnOptionGivenEmptyIsRefusedNotIgnored) {
  EXPECT_EQ(refusal({{path("in.obj")}, {{"--output", path("out.obj")}, {"--report", "", true}}, false, true}),
            "--report: the path is empty");
  EXPECT_EQ(refusal({{path("in.obj")}, {{"--output", "", true}}, false, true}), "--output: the path is empty");
}

TEST_F(OutputGuard, SymbolicLinksResolveToTheFileTheyName) {
  std::filesystem::create_symlink("real.json", path("link.json"));  // dangling until written
  std::filesystem::create_symlink(path("link.json"), path("link2.json"));
  const OutputTarget target = resolveOutput(path("link2.json"));
  EXPECT_EQ(target.path, dir_ / "real.json");
  EXPECT_FALSE(target.stream);
}

TEST_F(OutputGuard, FifosAndCharacterDevicesAreStreamsSocketsAreRefused) {
  ASSERT_EQ(::mkfifo(path("fifo").c_str(), 0644), 0);
  EXPECT_TRUE(resolveOutput(path("fifo")).stream);
  EXPECT_TRUE(resolveOutput("/dev/null").stream);
  const int fd = ::socket(AF_UNIX, SOCK_STREAM, 0);
  ASSERT_GE(fd, 0);
  sockaddr_un address{};
  address.sun_family = AF_UNIX;
  const std::string socketPath = path("socket");
  ASSERT_LT(socketPath.size(), sizeof address.sun_path);
  std::copy(socketPath.begin(), socketPath.end(), address.sun_path);
  ASSERT_EQ(::bind(fd, reinterpret_cast<const sockaddr*>(&address), sizeof address), 0);
  ::close(fd);
  EXPECT_NE(refusal({{path("in.obj")}, {{"--report", socketPath}}, false, true}).find("is a socket"), std::string::npos);
}

std::string slurp(const std::filesystem::path& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

/// Names in `dir` that start with '.': the temporary files of OutputFiles.
std::vector<std::string> hiddenFiles(const std::filesystem::path& dir) {
  std::vector<std::string> names;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    if (entry.path().filename().string().front() == '.') names.push_back(entry.path().filename().string());
  }
  return names;
}

TEST_F(OutputGuard, FilesOfOneRunAreWrittenAllOrNone) {
  // dual -o d.obj --primal P: d.obj was replaced before P failed.
  std::ofstream(dir_ / "first.obj") << "KEEP\n";
  OutputFiles files;
  files.add(path("first.obj"), "new\n");
  files.add(path("missing/second.obj"), "new\n");  // its temporary file cannot be created
  EXPECT_THROW(files.commit(), Error);
  EXPECT_EQ(slurp(dir_ / "first.obj"), "KEEP\n");
  EXPECT_TRUE(hiddenFiles(dir_.path()).empty());

  OutputFiles both;
  both.add(path("first.obj"), "one\n");
  both.add(path("second.json"), "two\n");
  both.commit();
  EXPECT_EQ(slurp(dir_ / "first.obj"), "one\n");
  EXPECT_EQ(slurp(dir_ / "second.json"), "two\n");
  EXPECT_TRUE(hiddenFiles(dir_.path()).empty()) << "no temporary file and no kept old file stays";
}

TEST_F(OutputGuard, ARenameThatFailsMidwayPutsBackTheFilesRenamedBeforeIt) {
  // All three are staged; then, before the last rename, its target becomes a folder with a
  // file in it, over which no file can be renamed. The first file's old content comes back,
  // the second, which did not exist, goes again.
  std::ofstream(dir_ / "first.obj") << "KEEP\n";
  OutputFiles files;
  files.add(path("first.obj"), "new\n");
  files.add(path("second.json"), "new\n");
  files.add(path("third.json"), "new\n");
  files.setBeforeRename([&](std::size_t i) {
    if (i != 2) return;
    std::filesystem::create_directory(dir_ / "third.json");
    std::ofstream(dir_ / "third.json" / "inside") << "x\n";
  });
  try {
    files.commit();
    ADD_FAILURE() << "the failed rename was not reported";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::BadInput);
    EXPECT_NE(std::string(e.what()).find("third.json"), std::string::npos) << e.what();
  }
  EXPECT_EQ(slurp(dir_ / "first.obj"), "KEEP\n");
  EXPECT_FALSE(std::filesystem::exists(dir_ / "second.json"));
  EXPECT_TRUE(std::filesystem::is_directory(dir_ / "third.json"));
  EXPECT_TRUE(hiddenFiles(dir_.path()).empty());
}

TEST_F(OutputGuard, WritingThroughALinkKeepsTheLink) {
  std::ofstream(dir_ / "real.json") << "old\n";
  std::filesystem::create_symlink("real.json", path("link.json"));
  OutputFiles files;
  files.add(path("link.json"), "new\n");
  files.commit();
  EXPECT_TRUE(std::filesystem::is_symlink(dir_ / "link.json"));
  EXPECT_EQ(slurp(dir_ / "real.json"), "new\n");
}

TEST_F(OutputGuard, AFifoIsWrittenToNotReplaced) {
  ASSERT_EQ(::mkfifo(path("fifo").c_str(), 0644), 0);
  std::string received;
  std::thread reader([&] { received = slurp(dir_ / "fifo"); });
  OutputFiles files;
  files.add(path("fifo"), "through the pipe\n");
  bool written = false;
  EXPECT_NO_THROW({
    files.commit();
    written = true;
  });
  if (!written) {  // No writer came: let the reader go.
    const int fd = ::open(path("fifo").c_str(), O_WRONLY | O_NONBLOCK);
    if (fd >= 0) ::close(fd);
  }
  reader.join();
  EXPECT_EQ(received, "through the pipe\n");
  struct stat info {};
  ASSERT_EQ(::lstat(path("fifo").c_str(), &info), 0);
  EXPECT_TRUE(S_ISFIFO(info.st_mode));
}

TEST_F(OutputGuard, InterruptibleFilesAreNotWrittenAfterCtrlC) {
  std::ofstream(dir_ / "out.obj") << "KEEP\n";
  requestCancellation();
  OutputFiles files(/*interruptible=*/true);
  files.add(path("out.obj"), "new\n");
  EXPECT_THROW(files.commit(), Interrupted);
  // The report of an interrupted run is written all the same.
  OutputFiles report;
  report.add(path("r.json"), "{}\n");
  EXPECT_NO_THROW(report.commit());
  clearCancellation();
  EXPECT_EQ(slurp(dir_ / "out.obj"), "KEEP\n");
  EXPECT_TRUE(std::filesystem::exists(dir_ / "r.json"));
  EXPECT_TRUE(hiddenFiles(dir_.path()).empty());
}

}  // namespace
}  // namespace plano::cli
