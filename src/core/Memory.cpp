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

}  // namespace

std::optional<std::uint64_t> controlGroupHeadroom(const std::filesystem::path& root, const std::string& membership) {
  // The group paths of /proc/self/cgroup's "id:controllers:path" lines.
  std::string v2Group = "/", v1Group = "/";
  std::istringstream lines(membership);
  for (std::string line; std::getline(lines, line);) {
    const std::size_t first = line.find(':');
    const std::size_t second = first == std::string::npos ? first : line.find(':', first + 1);
    if (second == std::string::npos) continue;
    const std::string controllers = line.substr(first + 1, second - first - 1);
    const std::string group = line.substr(second + 1);
    if (line.compare(0, first, "0") == 0 && controllers.empty()) v2Group = group;
    if (("," + controllers + ",").find(",memory,") != std::string::npos) v1Group = group;
  }
  // cgroup v1 reports "no limit" as a huge page-rounded number.
  constexpr std::uint64_t kNoLimit = std::uint64_t{1} << 60;
  struct Hierarchy {
    std::filesystem::path base;
    const std::string& group;
    const char* limitFile;
    const char* usageFile;
  };
  const Hierarchy hierarchies[] = {{root, v2Group, "memory.max", "memory.current"},
                                   {root / "memory", v1Group, "memory.limit_in_bytes", "memory.usage_in_bytes"}};
  std::optional<std::uint64_t> headroom;
  for (const Hierarchy& h : hierarchies) {
    // The group's folder and its ancestors up to the base, as paths below the base.
    std::filesystem::path below = std::filesystem::path(h.group).relative_path().lexically_normal();
    if (below.has_parent_path() && below.filename().empty()) below = below.parent_path();  // "a/b/"
    std::error_code error;
    if (below.empty() || below == "." || *below.begin() == ".." || !std::filesystem::is_directory(h.base / below, error)) {
      below.clear();
    }
    while (true) {
      const std::filesystem::path folder = below.empty() ? h.base : h.base / below;
      const std::optional<std::uint64_t> limit = readBytes(folder / h.limitFile);
      if (limit && *limit < kNoLimit) {
        const std::uint64_t usage = readBytes(folder / h.usageFile).value_or(0);
        const std::uint64_t left = usage < *limit ? *limit - usage : 0;
        headroom = headroom ? std::min(*headroom, left) : left;
      }
      if (below.empty()) break;
      below = below.has_parent_path() ? below.parent_path() : std::filesystem::path();
    }
  }
  return headroom;
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
