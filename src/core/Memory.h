#pragma once
// How much memory a dense result may take before it is formed. Linux grants allocations
// larger than the free memory (overcommit) and kills the process once they are touched, so
// a dense matrix that cannot fit must be refused before it is allocated: with a message
// naming it, not a SIGKILL halfway through a run.
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>

namespace plano {

/// Memory the system can still give without swapping, in bytes: MemAvailable of
/// /proc/meminfo, or less where the process's control group has a memory limit (a
/// container's: the kernel kills at that limit whatever the machine has); nullopt where
/// neither is known.
std::optional<std::uint64_t> availableMemoryBytes();

/// What a memory control group mounted at `root` still allows (limit minus usage; cgroup v2
/// memory.max and memory.current, or v1 memory/memory.limit_in_bytes and
/// memory/memory.usage_in_bytes); nullopt without a limit.
std::optional<std::uint64_t> controlGroupHeadroom(const std::filesystem::path& root = "/sys/fs/cgroup");

/// Throws Error(Numerical) "out of memory: `what` needs X GiB, ..." when `bytes` exceed
/// `limit`, or with limit 0 the memory available (no check where that is unknown).
void requireMemory(double bytes, const std::string& what, std::uint64_t limit = 0);

}  // namespace plano
