#pragma once
// Internal: one local/global iteration of ShapeUp planarization (Bouaziz, Deuss,
// Schwartzburg, Weise, Pauly, "Shape-Up", SGP 2012), the map G whose fixed point both
// ShapeUpPlanarizer and AndersonPlanarizer compute.
//
// Energy (normalized coordinates y, face sizes h_f, closeness weight w):
//   E(Y, P) = sum_f 1/h_f^2 sum_{i in f} |(y_i - c_f(Y)) - (p_i - c_f(P))|^2 + w sum_i |y_i - y0_i|^2
// Local step: P = corners projected onto each face's least-squares plane (minimizes E
// over planar P). Global step: minimize E over the free vertices; the matrix
//   A = sum_f C_f^T C_f / h_f^2 + w I   (C_f the centring matrix of face f)
// does not depend on Y, so it is factored once (precompute) and every step is one
// back-substitution with three right-hand sides.
#include <memory>

#include "compute/Backend.h"
#include "planarize/Problem.h"

namespace plano::planarize::detail {

class ShapeUpStep {
 public:
  /// Assemble and factor A (freeCount x freeCount).
  ShapeUpStep(const Problem& problem, double closeness, compute::Backend& backend);

  /// Local step at Y (#V x 3): projections onto best-fit planes, kept for the next
  /// globalStep. Returns E(Y, P(Y)), the energy the safeguard of Anderson compares.
  double project(const Positions& Y);

  /// Global step: overwrite the free rows of Y with the minimizer for the last projections.
  void globalStep(Positions& Y);

  /// Relative residual of the last linear solve.
  double linearResidual() const { return linearResidual_; }

 private:
  const Problem* problem_;
  double closeness_;
  std::unique_ptr<compute::SpdSolver> solver_;
  Eigen::MatrixXd fixedRhs_;  // closeness target and couplings to fixed vertices (freeCount x 3)
  Eigen::MatrixXd rhs_;       // fixedRhs_ + projection terms of the last project()
  Eigen::MatrixXd solution_;
  double linearResidual_ = 0.0;
};

}  // namespace plano::planarize::detail
