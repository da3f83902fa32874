#include "core/Memory.h"

#include <algorithm>
#include <cstdio>
#include <fstream>

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

std::optional<std::uint64_t> controlGroupHeadroom(const std::filesystem::path& root) {
  // cgroup v1 reports "no limit" as a huge page-rounded number.
  constexpr std::uint64_t kNoLimit = std::uint64_t{1} << 60;
  const std::pair<const char*, const char*> files[] = {
      {"memory.max", "memory.current"},                                 // cgroup v2
      {"memory/memory.limit_in_bytes", "memory/memory.usage_in_bytes"}};  // cgroup v1
  for (const auto& [limitFile, usageFile] : files) {
    const std::optional<std::uint64_t> limit = readBytes(root / limitFile);
    if (!limit || *limit >= kNoLimit) continue;
    const std::uint64_t usage = readBytes(root / usageFile).value_or(0);
    return usage < *limit ? *limit - usage : 0;
  }
  return std::nullopt;
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
  throwNumerical("out of memory: " + what + " needs " + sizes);
}

}  // namespace plano
