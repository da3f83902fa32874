#pragma once
// Cooperative cancellation of long computations (Ctrl-C in the plano tool). A signal
// handler may only touch lock-free atomics, so it merely sets a flag; the solvers' loops
// poll it between iterations, where stopping leaves no half-updated state behind, and
// throw Interrupted. Polling is one relaxed atomic load: cheap enough for any loop whose
// body does real work.
#include <atomic>
#include <stdexcept>
#include <string>

namespace plano {

/// Exit code of an interrupted run: 128 + SIGINT, as shells report a Ctrl-C.
inline constexpr int kInterruptedExitCode = 130;

/// Thrown when a computation stops because cancellation was requested. Deliberately not a
/// plano::Error: code that turns numerical errors into a failed status (catch Error) must
/// let an interruption pass through to the caller.
class Interrupted : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

namespace detail {
inline std::atomic<bool> cancellationFlag{false};
static_assert(std::atomic<bool>::is_always_lock_free, "the flag is set from a signal handler");
}  // namespace detail

/// Ask running computations to stop. Async-signal-safe.
inline void requestCancellation() noexcept { detail::cancellationFlag.store(true, std::memory_order_relaxed); }

/// Forget an earlier request (tests, or a tool that runs several jobs).
inline void clearCancellation() noexcept { detail::cancellationFlag.store(false, std::memory_order_relaxed); }

inline bool cancellationRequested() noexcept { return detail::cancellationFlag.load(std::memory_order_relaxed); }

/// Throw Interrupted naming `where` when cancellation was requested.
inline void throwIfCancelled(const char* where) {
  if (cancellationRequested()) throw Interrupted(std::string("stopped during ") + where);
}

/// throwIfCancelled at every 65536th index of a loop whose body is too cheap to poll each
/// time (formatting a file, generating or measuring a mesh): over millions of elements such
/// a loop takes seconds, and a Ctrl-C should not wait for it.
inline void throwIfCancelledAt(long long index, const char* where) {
  if ((index & 0xFFFF) == 0) throwIfCancelled(where);
}

}  // namespace plano
