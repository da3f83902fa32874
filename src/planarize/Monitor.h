#pragma once
// Internal: per-iteration bookkeeping shared by the planarization methods. Measures the
// papers' planarity of every face through the backend (the stopping criterion), appends
// max and mean to Info, and tells whether the tolerance is met.
#include <vector>

#include "compute/Backend.h"
#include "planarize/Problem.h"

namespace plano::planarize::detail {

class Monitor {
 public:
  Monitor(const Problem& problem, compute::Backend& backend, double tolerance);
  /// Record the planarity of `normalized` positions in info; true when max <= tolerance.
  bool record(const Positions& normalized, Info& info);
  /// Whether `normalized` positions meet the tolerance, without recording them.
  bool wouldConverge(const Positions& normalized);
  double lastMax() const { return lastMax_; }

 private:
  compute::Backend* backend_;
  double tolerance_;
  PolygonMesh mesh_;  // faces copied once; vertices overwritten per record
  std::vector<double> values_;
  double lastMax_ = 0.0;
};

}  // namespace plano::planarize::detail
