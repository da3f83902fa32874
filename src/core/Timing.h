#pragma once
// Wall-clock timing of the algorithms' reports (seconds, as doubles).
#include <chrono>

namespace plano {

using SteadyClock = std::chrono::steady_clock;

/// Seconds from `start` to now.
inline double secondsSince(SteadyClock::time_point start) {
  return std::chrono::duration<double>(SteadyClock::now() - start).count();
}

}  // namespace plano
