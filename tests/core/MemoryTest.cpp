#include "core/Memory.h"

#include <gtest/gtest.h>

#include <fstream>

#include "core/Error.h"
#include "support/TestMeshes.h"

namespace plano {
namespace {

void writeFile(const std::filesystem::path& path, const std::string& text) {
  std::filesystem::create_directories(path.parent_path());
  std::ofstream(path) << text;
}

TEST(Memory, AControlGroupsLimitLessItsUsageIsItsHeadroomAndNoLimitIsNone) {
  const test::TempDir v2, v1, unlimited, none;
  writeFile(v2 / "memory.max", "8589934592\n");  // 8 GiB
  writeFile(v2 / "memory.current", "1073741824\n");
  EXPECT_EQ(controlGroupHeadroom(v2.path(), ""), std::uint64_t{7} << 30);
  writeFile(v1 / "memory" / "memory.limit_in_bytes", "4294967296\n");
  writeFile(v1 / "memory" / "memory.usage_in_bytes", "5000000000\n");  // over the limit: nothing left
  EXPECT_EQ(controlGroupHeadroom(v1.path(), ""), 0u);
  writeFile(unlimited / "memory.max", "max\n");
  writeFile(unlimited / "memory" / "memory.limit_in_bytes", "9223372036854771712\n");  // v1's "no limit"
  EXPECT_FALSE(controlGroupHeadroom(unlimited.path(), "").has_value());
  EXPECT_FALSE(controlGroupHeadroom(none.path(), "").has_value());
}

TEST(Memory, TheProcesssOwnGroupAndEveryGroupAboveItBoundTheHeadroom) {
  // A container's runtime that shows the whole tree: the process sits in a group below the
  // root, whose own files say "no limit".
  const test::TempDir v1, v2;
  writeFile(v1 / "memory" / "memory.limit_in_bytes", "9223372036854771712\n");
  writeFile(v1 / "memory" / "jobs" / "memory.limit_in_bytes", "8589934592\n");  // 8 GiB
  writeFile(v1 / "memory" / "jobs" / "memory.usage_in_bytes", "4294967296\n");  // 4 GiB left
  writeFile(v1 / "memory" / "jobs" / "job1" / "memory.limit_in_bytes", "6442450944\n");
  writeFile(v1 / "memory" / "jobs" / "job1" / "memory.usage_in_bytes", "1073741824\n");  // 5 GiB left
  const std::string membership = "9:pids:/\n4:memory:/jobs/job1\n0::/\n";
  EXPECT_EQ(controlGroupHeadroom(v1.path(), membership), std::uint64_t{4} << 30);
  EXPECT_EQ(controlGroupHeadroom(v1.path(), "4:cpu,memory:/jobs/\n"), std::uint64_t{4} << 30);
  // Only the root's files: the group's folder is not in this tree (a container's own mount).
  EXPECT_FALSE(controlGroupHeadroom(v1.path(), "4:memory:/elsewhere/job9\n").has_value());
  EXPECT_FALSE(controlGroupHeadroom(v1.path(), "4:memory:/../jobs\n").has_value());

  writeFile(v2 / "memory.max", "max\n");
  writeFile(v2 / "user" / "memory.max", "3221225472\n");  // 3 GiB
  writeFile(v2 / "user" / "memory.current", "2147483648\n");
  writeFile(v2 / "user" / "session" / "memory.max", "max\n");
  EXPECT_EQ(controlGroupHeadroom(v2.path(), "0::/user/session\n"), std::uint64_t{1} << 30);
  EXPECT_FALSE(controlGroupHeadroom(v2.path(), "0::/\n").has_value());
}

TEST(Memory, ARequestAboveTheLimitIsRefusedNamingBothSizes) {
  EXPECT_NO_THROW(requireMemory(1024.0, "a small thing", 1024));
  try {
    requireMemory(3.0 * (1u << 30), "a large thing", std::uint64_t{1} << 30);
    ADD_FAILURE() << "no error";
  } catch (const OutOfMemory& e) {
    EXPECT_EQ(e.kind(), ErrorKind::Numerical);
    EXPECT_STREQ(e.what(), "out of memory: a large thing needs 3 GiB, more than the 1 GiB allowed");
  }
  // The machine's own figure, where /proc/meminfo exists: some memory is available.
  if (std::filesystem::exists("/proc/meminfo")) {
    EXPECT_GT(availableMemoryBytes().value_or(0), 0u);
  }
}

}  // namespace
}  // namespace plano
