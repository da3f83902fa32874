#pragma once
// How much memory a dense result may take before it is formed. Linux grants allocations
// larger than the free memory (overcommit) and kills the process once they are touched, so
// a dense matrix that cannot fit must be refused before it is allocated: with a message
// naming it, not a SIGKILL halfway through a run.
#include <cstdint>
#include <optional>
#include <string>

namespace plano {

/// Memory the system can still give without swapping (MemAvailable of /proc/meminfo),
/// in bytes; nullopt where that is unknown.
std::optional<std::uint64_t> availableMemoryBytes();

/// Throws Error(Numerical) "out of memory: `what` needs X GiB, ..." when `bytes` exceed
/// `limit`, or with limit 0 the memory available (no check where that is unknown).
void requireMemory(double bytes, const std::string& what, std::uint64_t limit = 0);

}  // namespace plano
