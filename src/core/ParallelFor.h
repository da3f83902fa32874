#pragma once
// Parallel loops over independent items (the CPU backend's batched per-face kernels, the
// host ADMM loop's passes over C's rows), on plain std::threads as libigl's parallel_for:
// no OpenMP runtime to match between the compilers that build Plano (GCC, and clang for
// the sanitizer build). The threads wait between calls in a pool (a call costs a wake-up,
// not a thread start); a call made while the pool runs another (from another thread, or
// from inside a chunk) starts threads of its own.
//
// Each item's result depends on that item alone, so the results are the same bit for bit
// whatever the thread count; the threads only divide the items.
#include <cstddef>
#include <functional>

namespace plano {

/// Threads the CPU's batched work uses: the count setCpuThreads gave, else the environment
/// variable PLANO_THREADS (a positive integer), else every hardware thread. Throws
/// Error(Usage) when PLANO_THREADS is set to anything else.
int cpuThreads();
/// Use `threads` threads from now on (1: the calling thread alone); 0 returns to the
/// default above. Throws Error(Usage) for a count below 0 or above 4096. A program that runs several
/// meshes at once on threads of its own sets 1 (or its cores over its threads): each
/// kernel call otherwise uses cpuThreads() threads (the pool's for one of them at a time,
/// threads started for the call for the others).
void setCpuThreads(int threads);

/// body(begin, end) over [0, count) in contiguous chunks, one per thread, each of at least
/// `minimumChunk` items (fewer threads for less work: handing a chunk to a pool thread costs
/// ~10 us, starting one tens of microseconds, as much as a few faces' fits); the calling thread runs the first chunk. Returns
/// once every chunk is done; an exception thrown by a chunk is rethrown then (the lowest
/// chunk's when several throw).
void parallelFor(std::ptrdiff_t count, std::ptrdiff_t minimumChunk,
                 const std::function<void(std::ptrdiff_t begin, std::ptrdiff_t end)>& body);

}  // namespace plano
