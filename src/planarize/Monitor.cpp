#include "planarize/Monitor.h"

#include <algorithm>
#include <cmath>

#include "core/Cancellation.h"
#include "core/Error.h"

namespace plano::planarize::detail {

Monitor::Monitor(const Problem& problem, compute::Backend& backend, double tolerance)
    : backend_(&backend), tolerance_(tolerance) {
  mesh_.faces = *problem.faces;
  values_.resize(static_cast<std::size_t>(mesh_.faces.size()));
}

bool Monitor::record(const Positions& normalized, Info& info) {
  // Every planarization method records once per iteration: the one place to poll.
  throwIfCancelled("planarization");
  mesh_.vertices = normalized;
  backend_->facePlanarity(mesh_, values_);
  double maxValue = 0.0;
  double sum = 0.0;
  for (double v : values_) {
    if (!std::isfinite(v)) throwNumerical("planarize: planarity became non-finite (iteration " +
                                          std::to_string(info.iterations) + ")");
    maxValue = std::max(maxValue, v);
    sum += v;
  }
  lastMax_ = maxValue;
  info.maxPlanarity.push_back(maxValue);
  info.meanPlanarity.push_back(values_.empty() ? 0.0 : sum / static_cast<double>(values_.size()));
  return maxValue <= tolerance_;
}

bool Monitor::wouldConverge(const Positions& normalized) {
  mesh_.vertices = normalized;
  backend_->facePlanarity(mesh_, values_);
  for (double v : values_) {
    if (!(v <= tolerance_)) return false;
  }
  return true;
}

}  // namespace plano::planarize::detail
