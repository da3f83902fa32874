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

/// What the memory control groups of a process still allow: the least headroom (limit
/// minus usage) over its own group and every group above it, which all bound it. Read in
/// the cgroup v2 tree at `root` (memory.max, memory.current) and in v1's memory controller
/// at `root`/memory (memory.limit_in_bytes, memory.usage_in_bytes). `membership` is the
/// process's /proc/self/cgroup ("0::/a/b" names its v2 group, "4:memory:/a/b" its v1
/// memory group); a group whose folder is not there (a container that mounts its own group
/// as the root) is read at the root. nullopt without any limit.
std::optional<std::uint64_t> controlGroupHeadroom(const std::filesystem::path& root, const std::string& membership);
/// The same for this process (/sys/fs/cgroup, /proc/self/cgroup).
std::optional<std::uint64_t> controlGroupHeadroom();

/// Throws OutOfMemory (an Error(Numerical)) "out of memory: `what` needs X GiB, ..." when `bytes` exceed
/// `limit`, or with limit 0 the memory available (no check where that is unknown).
void requireMemory(double bytes, const std::string& what, std::uint64_t limit = 0);

}  // namespace plano
