#include "projective/BoxQp.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "core/Error.h"

namespace plano::projective {
namespace {

BoxQpStatus toBoxQpStatus(compute::AdmmStatus status) {
  switch (status) {
    case compute::AdmmStatus::Solved: return BoxQpStatus::Solved;
    case compute::AdmmStatus::PrimalInfeasible: return BoxQpStatus::PrimalInfeasible;
    case compute::AdmmStatus::MaxIterationsReached: return BoxQpStatus::MaxIterationsReached;
    case compute::AdmmStatus::NonFinite: return BoxQpStatus::NonFinite;
    case compute::AdmmStatus::Stalled: return BoxQpStatus::Stalled;
  }
  return BoxQpStatus::MaxIterationsReached;
}

double infNorm(const Eigen::MatrixXd& m) { return m.size() == 0 ? 0.0 : m.cwiseAbs().maxCoeff(); }

compute::SparseMatrix identity(Eigen::Index n, double value) {
  compute::SparseMatrix I(n, n);
  I.setIdentity();
  return I * value;
}

double boundViolation(const Eigen::MatrixXd& Cx, const Eigen::MatrixXd& lower, const Eigen::MatrixXd& upper) {
  if (Cx.size() == 0) return 0.0;
  return std::max({0.0, (lower - Cx).maxCoeff(), (Cx - upper).maxCoeff()});
}

}  // namespace

const char* toString(BoxQpStatus status) {
  switch (status) {
    case BoxQpStatus::Solved: return "solved";
    case BoxQpStatus::PrimalInfeasible: return "primal_infeasible";
    case BoxQpStatus::MaxIterationsReached: return "max_iterations";
    case BoxQpStatus::NonFinite: return "non_finite";
    case BoxQpStatus::Stalled: return "stalled";
  }
  return "unknown";
}

BoxQpSolver::BoxQpSolver(compute::Backend& backend, compute::SparseMatrix P, compute::SparseMatrix C,
                         const BoxQpSettings& settings)
    : backend_(backend), settings_(settings), P_(std::move(P)), C_(std::move(C)) {
  C_.makeCompressed();
  if (P_.rows() != P_.cols() || C_.cols() != P_.rows()) {
    throwUsage("box QP: P is " + std::to_string(P_.rows()) + "x" + std::to_string(P_.cols()) + " and C is " +
               std::to_string(C_.rows()) + "x" + std::to_string(C_.cols()) + " (need n x n and m x n)");
  }
  admm_ = backend_.createAdmmSolver(P_, C_, static_cast<const compute::AdmmSettings&>(settings_));
}

void BoxQpSolver::setConstraintScaling(const compute::ConstraintScaling& scaling) {
  admm_->setConstraintScaling(scaling);
}

void BoxQpSolver::setScaledConstraintValues(const compute::SparseMatrix& C, std::span<const double> scales) {
  // C comes from the matrix whose scaling the solver holds (one pattern): the sizes suffice.
  if (C.rows() != C_.rows() || C.cols() != C_.cols() || C.nonZeros() != C_.nonZeros() || !C.isCompressed()) {
    throwUsage("box QP: new constraint values on a different sparsity pattern");
  }
  admm_->setConstraintScales(scales);
  std::copy_n(C.valuePtr(), C.nonZeros(), C_.valuePtr());
}

BoxQpInfo BoxQpSolver::solve(const Eigen::MatrixXd& q, const Eigen::MatrixXd& lower, const Eigen::MatrixXd& upper,
                             Eigen::MatrixXd& x, Eigen::MatrixXd& y) {
  Eigen::MatrixXd z;
  const compute::AdmmInfo admm = admm_->solve(q, lower, upper, x, y, z);
  BoxQpInfo info;
  info.status = toBoxQpStatus(admm.status);
  info.iterations = admm.iterations;
  info.factorizations = admm.factorizations;
  info.linearIterations = admm.linearIterations;
  info.primalResidual = admm.primalResidual;
  info.dualResidual = admm.dualResidual;
  info.rho = admm.rho;
  if (info.status == BoxQpStatus::Solved && settings_.polish && info.iterations > 0) {
    info.polished = polish(q, lower, upper, z, x, y);
  }
  info.maxBoundViolation = boundViolation(C_ * x, lower, upper);
  if (info.polished) info.primalResidual = info.maxBoundViolation;
  return info;
}

bool BoxQpSolver::polish(const Eigen::MatrixXd& q, const Eigen::MatrixXd& lower, const Eigen::MatrixXd& upper,
                         const Eigen::MatrixXd& z, Eigen::MatrixXd& x, Eigen::MatrixXd& y) {
  const Eigen::Index n = P_.rows();
  const Eigen::Index m = C_.rows();
  const double before = boundViolation(C_ * x, lower, upper);
  Eigen::MatrixXd xPolished = x;
  Eigen::MatrixXd yPolished = Eigen::MatrixXd::Zero(m, q.cols());
  const double rhoP = settings_.polishRho;
  // Columns with the same active set (always the case for all-equality problems) share
  // one factorization.
  std::vector<Eigen::Index> factoredRows;
  std::unique_ptr<compute::SpdSolver> solver;
  for (Eigen::Index c = 0; c < q.cols(); ++c) {
    // Active set as in OSQP: equality rows, and rows whose dual pushes z onto a bound.
    std::vector<Eigen::Index> rows;
    std::vector<double> targets;
    for (Eigen::Index i = 0; i < m; ++i) {
      const double l = lower(i, c), u = upper(i, c);
      if (l == u || z(i, c) - l < -y(i, c)) {
        rows.push_back(i);
        targets.push_back(l);
      } else if (u - z(i, c) < y(i, c)) {
        rows.push_back(i);
        targets.push_back(u);
      }
    }
    const auto active = static_cast<Eigen::Index>(rows.size());
    compute::SparseMatrix selector(active, m);
    std::vector<Eigen::Triplet<double>> entries;
    for (Eigen::Index r = 0; r < active; ++r) entries.emplace_back(r, rows[r], 1.0);
    selector.setFromTriplets(entries.begin(), entries.end());
    const compute::SparseMatrix CA = selector * C_;
    const compute::SparseMatrix CAt = CA.transpose();
    const Eigen::VectorXd b = Eigen::Map<const Eigen::VectorXd>(targets.data(), active);
    if (!solver || rows != factoredRows) {
      const compute::SparseMatrix K = P_ + identity(n, settings_.sigma) + compute::SparseMatrix(rhoP * (CAt * CA));
      // The stiff polish system can be too ill-conditioned to factor; polishing is an
      // optional refinement, so the ADMM solution stands.
      try {
        solver = backend_.createSpdSolver(K, settings_.linearSolver);
      } catch (const Error&) {
        return false;
      }
      factoredRows = rows;
    }
    // Method of multipliers on the equality-constrained QP, warm-started from the ADMM duals.
    Eigen::VectorXd lambda = selector * y.col(c);
    Eigen::MatrixXd xc = x.col(c);
    for (int it = 0; it < settings_.polishIterations; ++it) {
      const Eigen::MatrixXd rhs = settings_.sigma * xc - q.col(c) - CAt * lambda + rhoP * (CAt * b);
      solver->solve(rhs, xc);
      const Eigen::VectorXd r = CA * xc - b;
      lambda += rhoP * r;
      if (infNorm(r) <= 1e-15 * std::max(1.0, infNorm(b))) break;
    }
    if (!xc.allFinite()) return false;
    xPolished.col(c) = xc;
    yPolished.col(c) = selector.transpose() * lambda;
  }
  const double after = boundViolation(C_ * xPolished, lower, upper);
  if (!(after <= std::max(before, 1e-12))) return false;
  x = xPolished;
  y = yPolished;
  return true;
}

BoxQpSolver& keptSolver(std::unique_ptr<BoxQpSolver>& kept, compute::Backend& backend, const compute::SparseMatrix& P,
                        const ScaledConstraintMatrix& C, std::span<const double> scales, const BoxQpSettings& settings) {
  if (kept) {
    kept->setScaledConstraintValues(C.matrix(), scales);
  } else {
    kept = std::make_unique<BoxQpSolver>(backend, P, C.matrix(), settings);
    kept->setConstraintScaling(C.scaling());
  }
  return *kept;
}

}  // namespace plano::projective
