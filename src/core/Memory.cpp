#include "core/Memory.h"

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <sstream>

#include "core/Error.h"

namespace plano {

namespace {

/// The number a control-group file holds; nullopt for "max" (no limit) or no file.
std::optional<std::uint64_t> readBytes(const std::filesystem::path& path) {
  std::ifstream in(path);
  std::uint64_t value = 0;
  if (!(in >> value)) return std::nullopt;
  return value;
}

/// The process's group in each hierarchy, from /proc/self/cgroup's "id:controllers:path"
/// lines ("/" where a hierarchy is not named).
struct Membership {
  std::string v2 = "/";  ///< Of the line "0::path".
  std::string v1 = "/";  ///< Of the line whose controllers include memory.
};

Membership parseMembership(const std::string& text) {
  Membership membership;
  std::istringstream lines(text);
  for (std::string line; std::getline(lines, line);) {
    const std::size_t first = line.find(':');
    const std::size_t second = first == std::string::npos ? first : line.find(':', first + 1);
    if (second == std::string::npos) continue;
    const std::string controllers = line.substr(first + 1, second - first - 1);
    const std::string group = line.substr(second + 1);
    if (line.compare(0, first, "0") == 0 && controllers.empty()) membership.v2 = group;
    if (("," + controllers + ",").find(",memory,") != std::string::npos) membership.v1 = group;
  }
  return membership;
}

/// The least limit-minus-usage over `group`'s folder below `base` and every folder above it
/// up to `base` (only `base` when the group's folder is not there); nullopt without a limit.
std::optional<std::uint64_t> leastHeadroom(const std::filesystem::path& base, const std::string& group,
                                           const char* limitFile, const char* usageFile) {
  // cgroup v1 reports "no limit" as a huge page-rounded number.
  constexpr std::uint64_t kNoLimit = std::uint64_t{1} << 60;
  std::filesystem::path below = std::filesystem::path(group).relative_path().lexically_normal();
  if (below.has_parent_path() && below.filename().empty()) below = below.parent_path();  // "a/b/"
  std::error_code error;
  if (below.empty() || below == "." || *below.begin() == ".." || !std::filesystem::is_directory(base / below, error)) {
    below.clear();
  }
  std::optional<std::uint64_t> headroom;
  while (true) {
    const std::filesystem::path folder = below.empty() ? base : base / below;
    const std::optional<std::uint64_t> limit = readBytes(folder / limitFile);
    if (limit && *limit < kNoLimit) {
      const std::uint64_t usage = readBytes(folder / usageFile).value_or(0);
      const std::uint64_t left = usage < *limit ? *limit - usage : 0;
      headroom = headroom ? std::min(*headroom, left) : left;
    }
    if (below.empty()) return headroom;
    below = below.has_parent_path() ? below.parent_path() : std::filesystem::path();
  }
}

}  // namespace

std::optional<std::uint64_t> controlGroupHeadroom(const std::filesystem::path& root, const std::string& membership) {
  const Membership groups = parseMembership(membership);
  const std::optional<std::uint64_t> v2 = leastHeadroom(root, groups.v2, "memory.max", "memory.current");
  const std::optional<std::uint64_t> v1 =
      leastHeadroom(root / "memory", groups.v1, "memory.limit_in_bytes", "memory.usage_in_bytes");
  if (v2 && v1) return std::min(*v2, *v1);
  return v2 ? v2 : v1;
}

std::optional<std::uint64_t> controlGroupHeadroom() {
  std::ifstream in("/proc/self/cgroup");
  std::ostringstream membership;
  membership << in.rdbuf();
  return controlGroupHeadroom("/sys/fs/cgroup", membership.str());
}

std::optional<std::uint64_t> availableMemoryBytes() {
  std::optional<std::uint64_t> available;
  std::ifstream meminfo("/proc/meminfo");
  std::string key, unit;
  std::uint64_t kib = 0;
  while (meminfo >> key >> kib >> unit) {
    if (key == "MemAvailable:") {
      available = kib * 1024u;
      break;
    }
  }
  if (const std::optional<std::uint64_t> headroom = controlGroupHeadroom()) {
    available = available ? std::min(*available, *headroom) : *headroom;
  }
  return available;
}

void requireMemory(double bytes, const std::string& what, std::uint64_t limit) {
  const std::optional<std::uint64_t> available =
      limit > 0 ? std::optional<std::uint64_t>(limit) : availableMemoryBytes();
  if (!available || bytes <= static_cast<double>(*available)) return;
  constexpr double kGiB = 1024.0 * 1024.0 * 1024.0;
  char sizes[96];
  std::snprintf(sizes, sizeof sizes, "%.3g GiB, more than the %.3g GiB %s", bytes / kGiB,
                static_cast<double>(*available) / kGiB, limit > 0 ? "allowed" : "of memory available");
  throw OutOfMemory("out of memory: " + what + " needs " + sizes);
}

}  // namespace plano
