#include "core/Memory.h"

#include <cstdio>
#include <fstream>

#include "core/Error.h"

namespace plano {

std::optional<std::uint64_t> availableMemoryBytes() {
  std::ifstream meminfo("/proc/meminfo");
  std::string key;
  std::uint64_t kib = 0;
  std::string unit;
  while (meminfo >> key >> kib >> unit) {
    if (key == "MemAvailable:") return kib * 1024u;
  }
  return std::nullopt;
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
