#include "compute/Admm.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <string>

#include "core/Cancellation.h"
#include "core/Error.h"
#include "core/ParallelFor.h"

namespace plano::compute {
namespace {

/// The least primal tolerance an eps gives (AdmmSettings::epsilonToleranceFraction), well
/// above the rounding of rows whose terms are of order 1 (~1e-16): targets compatible to
/// rounding have eps_0 ~1e-17, and their attempt must converge at its start.
constexpr double kPrimalToleranceFloor = 1e-12;

/// Column-wise inf-norms; NaN propagates (Eigen's maxCoeff would skip it).
Eigen::VectorXd columnInfNorms(const Eigen::MatrixXd& m) {
  Eigen::VectorXd norms = Eigen::VectorXd::Zero(m.cols());
  for (Eigen::Index c = 0; c < m.cols(); ++c) {
    for (Eigen::Index i = 0; i < m.rows(); ++i) {
      const double a = std::abs(m(i, c));
      if (a > norms[c] || std::isnan(a)) norms[c] = a;
      if (std::isnan(a)) break;
    }
  }
  return norms;
}

double maxOf(const Eigen::VectorXd& v) { return v.size() == 0 ? 0.0 : v.maxCoeff(); }

bool allFinite(const Eigen::VectorXd& v) { return v.allFinite(); }

/// Rows per thread at the least in the host loop's row passes: a pass over C's rows takes
/// ~20 ns a row for three columns, handing a chunk to another thread ~10 us (core/
/// ParallelFor.h's pool; BM_ParallelForCall).
constexpr std::ptrdiff_t kRowsPerThread = 4096;

/// A row function inlined into the row loop of forEachRowProduct: GCC at -O3 left a call per
/// row and column in the ADMM's passes when Admm.cpp was compiled on its own, not in a unity
/// batch (the Enneper hexagons' first four iterations 15.1-15.5 s against 13.2-14.4 s).
#define PLANO_ROW_FUNCTION __attribute__((always_inline))

/// f(r, c, (A X)(r, c)) for every row r of a row-major A and column c of X, rows split over
/// the CPU threads (f may write entry (r, c) of arrays of its own). Each product is summed
/// in A's entry order from zero, as Eigen's product sums it, so it is the same bit for bit.
template <class RowFunction>
void forEachRowProduct(const SparseMatrix& A, const Eigen::MatrixXd& X, RowFunction&& f) {
  parallelFor(A.rows(), kRowsPerThread, [&](std::ptrdiff_t begin, std::ptrdiff_t end) {
    if (X.cols() == 3) {
      const double* x0 = X.col(0).data();
      const double* x1 = X.col(1).data();
      const double* x2 = X.col(2).data();
      for (auto r = static_cast<Eigen::Index>(begin); r < end; ++r) {
        double s0 = 0.0, s1 = 0.0, s2 = 0.0;
        for (SparseMatrix::InnerIterator it(A, r); it; ++it) {
          const double a = it.value();
          const Eigen::Index j = it.index();
          s0 += a * x0[j];
          s1 += a * x1[j];
          s2 += a * x2[j];
        }
        f(r, 0, s0);
        f(r, 1, s1);
        f(r, 2, s2);
      }
      return;
    }
    for (Eigen::Index c = 0; c < X.cols(); ++c) {
      const double* x = X.col(c).data();
      for (auto r = static_cast<Eigen::Index>(begin); r < end; ++r) {
        double sum = 0.0;
        for (SparseMatrix::InnerIterator it(A, r); it; ++it) sum += it.value() * x[it.index()];
        f(r, c, sum);
      }
    }
  });
}

/// Y = A X (forEachRowProduct).
void multiplyRows(const SparseMatrix& A, const Eigen::MatrixXd& X, Eigen::MatrixXd& Y) {
  Y.resize(A.rows(), X.cols());
  forEachRowProduct(A, X, [&](Eigen::Index r, Eigen::Index c, double product) PLANO_ROW_FUNCTION { Y(r, c) = product; });
}

/// The host loop: the steps of AdmmKernels::iterate as Eigen expressions and row passes
/// over C, K solved by the backend's SPD solver (refactored when rho changes).
class HostAdmmKernels final : public AdmmKernels {
 public:
  HostAdmmKernels(Backend& backend, const SparseMatrix& P, const SparseMatrix& C, const AdmmSettings& settings)
      : backend_(backend), settings_(settings), alpha_(settings.relaxation), P_(P), C_(C), Ct_(C.transpose()) {
    C_.makeCompressed();
  }

  void setRelaxation(double alpha) override { alpha_ = alpha; }

  void setRho(const std::vector<char>& equality, double rho) override {
    rho_.resize(static_cast<Eigen::Index>(equality.size()));
    for (std::size_t i = 0; i < equality.size(); ++i) rho_[i] = equality[i] ? rho * settings_.equalityRhoScale : rho;
    SparseMatrix I(P_.rows(), P_.rows());
    I.setIdentity();
    const SparseMatrix K = P_ + I * settings_.sigma + SparseMatrix(Ct_ * rho_.asDiagonal() * C_);
    // K's pattern is the same for every rho and every C on one pattern: a factorization
    // keeps its ordering and symbolic analysis.
    if (!solver_ || !solver_->refactor(K)) {
      LinearSolverSettings linear = settings_.linearSolver;
      linear.measureResidual = false;  // non-finite iterates show in the checks' norms
      solver_ = backend_.createSpdSolver(K, linear);
    }
  }

  void setConstraintValues(const SparseMatrix& C) override {
    SparseMatrix compressed = C;
    compressed.makeCompressed();
    if (!sameSparsityPattern(compressed, C_)) {
      throwUsage("ADMM: new constraint values on a different sparsity pattern");
    }
    C_ = std::move(compressed);
    Ct_ = C_.transpose();
  }

  void setConstraintScaling(const ConstraintScaling& scaling) override {
    checkConstraintScaling(scaling, C_.nonZeros());
    scaling_ = scaling;
  }

  void setConstraintScales(std::span<const double> scales) override {
    fillScaledValues(scaling_, scales, C_.valuePtr());
    Ct_ = C_.transpose();
  }

  void start(const DeviceMatrix& q, const Eigen::MatrixXd& lower, const Eigen::MatrixXd& upper,
             const DeviceMatrix& x, const Eigen::MatrixXd& y, WarmStart warm) override {
    q_ = q.values();
    lower_ = lower;
    upper_ = upper;
    // A held iterate exists once a start set one of these sizes.
    const bool held = warm == WarmStart::Kept && x_.rows() == q.rows() && x_.cols() == q.cols() &&
                      y_.rows() == lower.rows() && y_.cols() == q.cols();
    if (!held) {
      x_ = x.size() > 0 ? x.values() : Eigen::MatrixXd::Zero(q.rows(), q.cols());
      y_ = y.size() > 0 ? y : Eigen::MatrixXd::Zero(lower.rows(), q.cols());
    }
    z_ = (C_ * x_).cwiseMax(lower_).cwiseMin(upper_);
    xTilde_ = x_;
    yPrevious_ = y_;
    linearIterations_ = 0;
  }

  void iterate(int count) override {
    const double alpha = alpha_;
    const double sigma = settings_.sigma;
    // w = rho z - y, which the row pass below keeps up to date.
    w_ = rho_.asDiagonal() * z_ - y_;
    for (int i = 0; i < count; ++i) {
      multiplyRows(Ct_, w_, rhs_);
      rhs_ += sigma * x_ - q_;  // sigma x - q + C^T (rho z - y)
      linearIterations_ += solver_->solve(rhs_, xTilde_).iterations;
      x_ = alpha * xTilde_ + (1.0 - alpha) * x_;
      if (i == count - 1) yPrevious_ = y_;

      // The rest, row by row of C (a row's z and y depend on that row alone): zTilde = C
      // xTilde, the relaxation, the projection onto [l, u], the dual step and w, with no
      // m x k temporaries. The same operations in the same order as the matrix expressions
      // they replaced, so the iterates are the same bit for bit.
      forEachRowProduct(C_, xTilde_, [&](Eigen::Index r, Eigen::Index c, double zTilde) PLANO_ROW_FUNCTION {
        const double rho = rho_[r];
        const double zRelaxed = alpha * zTilde + (1.0 - alpha) * z_(r, c);
        const double zNext = std::min(std::max(zRelaxed + (1.0 / rho) * y_(r, c), lower_(r, c)), upper_(r, c));
        y_(r, c) += rho * (zRelaxed - zNext);
        z_(r, c) = zNext;
        w_(r, c) = rho * zNext - y_(r, c);
      });
    }
  }

  AdmmMeasures measure() override {
    AdmmMeasures s;
    // The products as row passes over the threads into kept arrays (the same sums as the
    // matrix products, bit for bit), the norms of their sums as expressions.
    multiplyRows(C_, x_, Cx_);
    multiplyRows(P_, x_, Px_);
    multiplyRows(Ct_, y_, Cty_);
    dy_ = y_ - yPrevious_;
    multiplyRows(Ct_, dy_, Ctdy_);
    s.primalResidual = columnInfNorms(Cx_ - z_);
    s.dualResidual = columnInfNorms(Px_ + q_ + Cty_);
    s.Cx = columnInfNorms(Cx_);
    s.z = columnInfNorms(z_);
    s.Px = columnInfNorms(Px_);
    s.Cty = columnInfNorms(Cty_);
    s.q = columnInfNorms(q_);
    s.x = columnInfNorms(x_);
    s.y = columnInfNorms(y_);
    s.dy = columnInfNorms(dy_);
    s.Ctdy = columnInfNorms(Ctdy_);
    s.support.resize(dy_.cols());
    for (Eigen::Index c = 0; c < dy_.cols(); ++c) {
      s.support[c] = upper_.col(c).dot(dy_.col(c).cwiseMax(0.0)) + lower_.col(c).dot(dy_.col(c).cwiseMin(0.0));
    }
    s.linearIterations = linearIterations_;
    return s;
  }

  void download(Eigen::MatrixXd& x, Eigen::MatrixXd& y, Eigen::MatrixXd& z) override {
    x = x_;
    y = y_;
    z = z_;
  }

 private:
  Backend& backend_;
  AdmmSettings settings_;
  double alpha_;
  SparseMatrix P_, C_, Ct_;
  ConstraintScaling scaling_;
  std::unique_ptr<SpdSolver> solver_;
  Eigen::VectorXd rho_;
  Eigen::MatrixXd q_, lower_, upper_, x_, y_, z_, xTilde_, yPrevious_;
  Eigen::MatrixXd w_, rhs_;  ///< iterate()'s rho z - y and right-hand side, kept to spare their allocations.
  Eigen::MatrixXd Cx_, Px_, Cty_, dy_, Ctdy_;  ///< measure()'s products, kept likewise.
  long linearIterations_ = 0;
};

}  // namespace

bool sameSparsityPattern(const SparseMatrix& A, const SparseMatrix& B) {
  if (!A.isCompressed() || !B.isCompressed() || A.rows() != B.rows() || A.cols() != B.cols() ||
      A.nonZeros() != B.nonZeros()) {
    return false;
  }
  return std::equal(A.outerIndexPtr(), A.outerIndexPtr() + A.outerSize() + 1, B.outerIndexPtr()) &&
         std::equal(A.innerIndexPtr(), A.innerIndexPtr() + A.nonZeros(), B.innerIndexPtr());
}

std::unique_ptr<AdmmKernels> createHostAdmmKernels(Backend& backend, const SparseMatrix& P, const SparseMatrix& C,
                                                   const AdmmSettings& settings) {
  return std::make_unique<HostAdmmKernels>(backend, P, C, settings);
}

std::unique_ptr<AdmmSolver> Backend::createAdmmSolver(const SparseMatrix& P, const SparseMatrix& C,
                                                      const AdmmSettings& settings) {
  return std::make_unique<AdmmSolver>(createHostAdmmKernels(*this, P, C, settings), P.rows(), C.rows(), settings);
}

AdmmSolver::AdmmSolver(std::unique_ptr<AdmmKernels> kernels, Eigen::Index n, Eigen::Index m,
                       const AdmmSettings& settings)
    : kernels_(std::move(kernels)), n_(n), m_(m), settings_(settings), rho_(settings.rho) {
  if (settings_.checkInterval < 1) throwUsage("ADMM: checkInterval must be at least 1");
  if (settings_.stallIterations < 0) throwUsage("ADMM: stallIterations must be >= 0 (0: never stop as stalled)");
  if (!(settings_.farDualFactor >= 0.0) || std::isinf(settings_.farDualFactor)) {
    throwUsage("ADMM: farDualFactor must be a finite number >= 0 (0: never)");
  }
  if (!(settings_.epsilonToleranceFraction >= 0.0) || std::isinf(settings_.epsilonToleranceFraction)) {
    throwUsage("ADMM: epsilonToleranceFraction must be a finite number >= 0 (0: absoluteTolerance alone)");
  }
  if (!(settings_.stallChange >= 0.0 && settings_.stallChange < 1.0)) {
    throwUsage("ADMM: stallChange must be in [0, 1)");
  }
  for (const double alpha : {settings_.relaxation, settings_.equalityRelaxation}) {
    if (!(alpha > 0.0 && alpha < 2.0)) throwUsage("ADMM: the over-relaxations must be in (0, 2)");
  }
  if (!(settings_.dualToleranceScale >= 1.0) || std::isinf(settings_.dualToleranceScale)) {
    throwUsage("ADMM: dualToleranceScale must be a finite number >= 1");
  }
  if (std::isnan(settings_.inaccurateDualFactor)) throwUsage("ADMM: inaccurateDualFactor must be a number");
  if (!(settings_.linearToleranceFraction > 0.0) || !std::isfinite(settings_.linearToleranceFraction)) {
    throwUsage("ADMM: linearToleranceFraction must be a finite number > 0");
  }
}

void AdmmSolver::setConstraintValues(const SparseMatrix& C) {
  if (C.rows() != m_ || C.cols() != n_) {
    throwUsage("ADMM: new constraint values of " + std::to_string(C.rows()) + "x" + std::to_string(C.cols()) +
               " for a " + std::to_string(m_) + "x" + std::to_string(n_) + " C");
  }
  kernels_->setConstraintValues(C);
  scales_.clear();
  factored_ = false;
}

void checkConstraintScaling(const ConstraintScaling& scaling, Eigen::Index nonZeros) {
  const auto entries = static_cast<std::size_t>(nonZeros);
  if (scaling.coefficients.size() != entries || scaling.scaleOf.size() != entries) {
    throwUsage("ADMM: a constraint scaling of " + std::to_string(scaling.coefficients.size()) + " coefficients and " +
               std::to_string(scaling.scaleOf.size()) + " scale indices for a C of " + std::to_string(entries) +
               " entries");
  }
  for (const std::int32_t s : scaling.scaleOf) {
    if (s < 0 || s >= scaling.scaleCount) {
      throwUsage("ADMM: a constraint scaling's scale index " + std::to_string(s) + " is outside 0 .. " +
                 std::to_string(scaling.scaleCount - 1));
    }
  }
}

void fillScaledValues(const ConstraintScaling& scaling, std::span<const double> scales, double* values) {
  for (std::size_t e = 0; e < scaling.coefficients.size(); ++e) {
    values[e] = scaling.coefficients[e] / scales[static_cast<std::size_t>(scaling.scaleOf[e])];
  }
}

void AdmmSolver::setConstraintScaling(ConstraintScaling scaling, std::span<const double> currentScales) {
  if (!currentScales.empty() && currentScales.size() != static_cast<std::size_t>(scaling.scaleCount)) {
    throwUsage("ADMM: " + std::to_string(currentScales.size()) + " current constraint scales for a scaling of " +
               std::to_string(scaling.scaleCount));
  }
  kernels_->setConstraintScaling(scaling);
  scaleCount_ = scaling.scaleCount;
  scales_.assign(currentScales.begin(), currentScales.end());
}

void AdmmSolver::setConstraintScales(std::span<const double> scales) {
  if (scaleCount_ < 0) throwUsage("ADMM: constraint scales given before a constraint scaling");
  if (scales.size() != static_cast<std::size_t>(scaleCount_)) {
    throwUsage("ADMM: " + std::to_string(scales.size()) + " constraint scales for a scaling of " +
               std::to_string(scaleCount_));
  }
  // The scales of the last call give the same C (bit for bit): nothing to form, and K stays
  // valid. A rigid or similar deformation's global steps all take ideal maps, whose fourth
  // columns are (0, 0, 0, 1): every scale is 1, step after step.
  if (!scales_.empty() && std::memcmp(scales.data(), scales_.data(), scales.size_bytes()) == 0) return;
  kernels_->setConstraintScales(scales);
  scales_.assign(scales.begin(), scales.end());
  factored_ = false;
}

void AdmmSolver::setConstraintScales(const DeviceMatrix& scales) {
  if (scales.onHost()) {
    const Eigen::MatrixXd& values = scales.values();
    setConstraintScales(std::span<const double>(values.data(), static_cast<std::size_t>(values.size())));
    return;
  }
  if (scaleCount_ < 0) throwUsage("ADMM: constraint scales given before a constraint scaling");
  if (scales.cols() != 1 || scales.rows() != scaleCount_) {
    throwUsage("ADMM: " + std::to_string(scales.rows()) + " x " + std::to_string(scales.cols()) +
               " constraint scales for a scaling of " + std::to_string(scaleCount_));
  }
  kernels_->setDeviceConstraintScales(scales);
  scales_.clear();  // not known here: the next host scales are formed whatever they are
  factored_ = false;
}

bool AdmmSolver::refineActiveSet(const ActiveSetRefinement& request, Eigen::MatrixXd& x, Eigen::MatrixXd& y,
                                 ActiveSetRefinementInfo& info) {
  const bool bySides = !request.sides.empty();
  if (request.active.size() != static_cast<std::size_t>(m_) ||
      (bySides ? request.targets.size() != 0 : request.targets.rows() != m_)) {
    throwUsage("ADMM: an active set of " + std::to_string(request.active.size()) + " rows and targets of " +
               std::to_string(request.targets.rows()) + (bySides ? " with sides" : "") + " for " +
               std::to_string(m_) + " constraint rows");
  }
  bool refined = false;
  try {
    refined = kernels_->refineActiveSet(request, x, y, info);
  } catch (...) {
    factored_ = false;  // K may be the polish's
    throw;
  }
  if (refined) factored_ = false;  // K is the polish's now
  return refined;
}

double AdmmSolver::violationAt(const DeviceMatrix& q, const RelaxedBounds& bounds, const DeviceMatrix& x,
                               const std::function<const SparseMatrix&()>& hostC) {
  if (bounds.centre.rows() != m_ || bounds.relaxed.size() != static_cast<std::size_t>(m_) || x.rows() != n_ ||
      q.rows() != n_ || x.cols() != bounds.centre.cols() || q.cols() != x.cols()) {
    throwUsage("ADMM: a violation needs q and x n x k, an m x k centre and m flags");
  }
  if (m_ == 0 || x.cols() == 0) return 0.0;
  if (const auto measured = kernels_->violationAt(q, bounds, x)) return *measured;
  const SparseMatrix& C = hostC();
  if (C.rows() != m_ || C.cols() != n_) throwUsage("ADMM: a violation needs an m x n C");
  return (C * x.values() - bounds.centre).cwiseAbs().maxCoeff<Eigen::PropagateNaN>();
}

void AdmmSolver::setRho(double rho) {
  if (!(rho > 0.0) || !std::isfinite(rho)) throwUsage("ADMM: rho must be a finite number > 0");
  rho_ = rho;
}

Eigen::MatrixXd RelaxedBounds::widened(double offset) const {
  if (relaxed.size() != static_cast<std::size_t>(centre.rows())) {
    throwUsage("relaxed bounds: " + std::to_string(relaxed.size()) + " row flags for a centre of " +
               std::to_string(centre.rows()) + " rows");
  }
  Eigen::MatrixXd bound = centre;
  for (Eigen::Index r = 0; r < bound.rows(); ++r) {
    if (relaxed[static_cast<std::size_t>(r)]) bound.row(r).array() += offset;
  }
  return bound;
}

double AdmmKernels::boundViolation() {
  throwUsage("ADMM: these kernels do not keep the iterate (no bound violation to measure there)");
}

void AdmmKernels::discardRefinement() {
  throwUsage("ADMM: these kernels do not keep the iterate (no refinement to discard)");
}

void AdmmSolver::discardRefinement() {
  kernels_->discardRefinement();
}

AdmmInfo AdmmSolver::solve(const Eigen::MatrixXd& q, const Eigen::MatrixXd& lower, const Eigen::MatrixXd& upper,
                           Eigen::MatrixXd& x, Eigen::MatrixXd& y, Eigen::MatrixXd& z) {
  const AdmmInfo info = iterate(q, lower, upper, nullptr, x, y);
  kernels_->download(x, y, z);
  return info;
}

AdmmInfo AdmmSolver::solve(const Eigen::MatrixXd& q, const RelaxedBounds& bounds, Eigen::MatrixXd& x,
                           Eigen::MatrixXd& y, Eigen::MatrixXd& z) {
  // l and u formed here serve the checks; only the kernels' start takes the relaxation.
  const AdmmInfo info = iterate(q, bounds.lower(), bounds.upper(), &bounds, x, y);
  kernels_->download(x, y, z);
  return info;
}

AdmmInfo AdmmSolver::iterate(const DeviceMatrix& q, const Eigen::MatrixXd& lower, const Eigen::MatrixXd& upper,
                             const RelaxedBounds* relaxed, const DeviceMatrix& x, const Eigen::MatrixXd& y,
                             WarmStart warm) {
  return run(q, lower, upper, relaxed, x, y, warm, true);
}

AdmmInfo AdmmSolver::load(const DeviceMatrix& q, const Eigen::MatrixXd& lower, const Eigen::MatrixXd& upper,
                          const RelaxedBounds* relaxed, const DeviceMatrix& x, const Eigen::MatrixXd& y,
                          WarmStart warm) {
  return run(q, lower, upper, relaxed, x, y, warm, false);
}

AdmmInfo AdmmSolver::run(const DeviceMatrix& q, const Eigen::MatrixXd& lower, const Eigen::MatrixXd& upper,
                         const RelaxedBounds* relaxed, const DeviceMatrix& x, const Eigen::MatrixXd& y,
                         WarmStart warm, bool iterations) {
  if (relaxed) {
    if (relaxed->centre.rows() != m_ || relaxed->centre.cols() != q.cols() ||
        relaxed->relaxed.size() != static_cast<std::size_t>(m_)) {
      throwUsage("ADMM: relaxed bounds need an m x k centre and one flag per row");
    }
    if (!(relaxed->epsilon >= 0.0) || !std::isfinite(relaxed->epsilon)) {
      throwUsage("ADMM: the bounds' relaxation must be finite and >= 0");
    }
  }
  const Eigen::Index k = q.cols();
  if (q.rows() != n_ || lower.rows() != m_ || upper.rows() != m_ || lower.cols() != k || upper.cols() != k) {
    throwUsage("ADMM: q, lower and upper must be n x k, m x k, m x k");
  }
  if ((lower.array() > upper.array()).any()) throwUsage("ADMM: a lower bound exceeds its upper bound");
  // Empty warm starts are zero; the kernels set them where they keep the iterate.
  if ((x.size() != 0 && (x.rows() != n_ || x.cols() != k)) || (y.size() != 0 && (y.rows() != m_ || y.cols() != k))) {
    throwUsage("ADMM: warm starts x and y must be n x k and m x k");
  }

  std::vector<char> equality(m_);
  for (Eigen::Index i = 0; i < m_; ++i) equality[i] = (lower.row(i).array() == upper.row(i).array()).all();
  const bool allEqualities = std::all_of(equality.begin(), equality.end(), [](char e) { return e != 0; });
  kernels_->setRelaxation(allEqualities ? settings_.equalityRelaxation : settings_.relaxation);
  AdmmInfo info;
  if (relaxed) {
    kernels_->startRelaxed(q, *relaxed, x, y, warm);
  } else {
    kernels_->start(q, lower, upper, x, y, warm);
  }

  // An attempt resolves its own eps (AdmmSettings::epsilonToleranceFraction).
  const double ofEpsilon = settings_.epsilonToleranceFraction;
  const double primalAbsoluteTolerance =
      relaxed && relaxed->epsilon > 0.0 && ofEpsilon > 0.0
          ? std::max(std::min(settings_.absoluteTolerance, ofEpsilon * relaxed->epsilon), kPrimalToleranceFloor)
          : settings_.absoluteTolerance;
  // Residuals, tolerances and the rho balance at the current iterate. Returns true when converged.
  AdmmMeasures s;
  double rhoBalance = 1.0;
  double linearTolerance = std::numeric_limits<double>::infinity();
  double primalTolerance = 0.0;
  double dualTolerance = 0.0;
  // `regular`: a check on the checkInterval grid, which also sets what the next blocks use
  // (the rho balance, the inner solves' bound); between them only convergence is tested.
  auto converged = [&](bool regular = true) {
    info.primalResidual = maxOf(s.primalResidual);
    info.dualResidual = maxOf(s.dualResidual);
    const double primalScale = std::max(maxOf(s.Cx), maxOf(s.z));
    const double dualScale = std::max({maxOf(s.Px), maxOf(s.Cty), maxOf(s.q)});
    const double epsPrimal = primalAbsoluteTolerance + settings_.relativeTolerance * primalScale;
    const double epsDual = dualToleranceFor(settings_, dualScale);
    primalTolerance = epsPrimal;
    dualTolerance = epsDual;
    if (!regular) return info.primalResidual <= epsPrimal && info.dualResidual <= epsDual;
    const double tiny = 1e-30;
    rhoBalance = std::sqrt((info.primalResidual / std::max(primalScale, tiny)) /
                           std::max(info.dualResidual / std::max(dualScale, tiny), tiny));
    // The next blocks' bound on the inner solves' residuals (AdmmSettings::linearToleranceFraction).
    const double fraction = settings_.linearToleranceFraction;
    linearTolerance = std::min(linearTolerance, fraction * std::max(std::min(info.primalResidual, info.dualResidual),
                                                                    std::min(epsPrimal, epsDual)));
    return info.primalResidual <= epsPrimal && info.dualResidual <= epsDual;
  };

  // The caller's progress report (AdmmSettings::onCheck) of the check just made.
  auto reportCheck = [&]() {
    if (settings_.onCheck) {
      settings_.onCheck({info.iterations, info.primalResidual, primalTolerance, info.dualResidual, dualTolerance, rho_,
                         s.linearIterations});
    }
  };

  // OSQP's primal infeasibility certificate from the last dual step dy: for d = dy/||dy||,
  // C^T d ~ 0 and u^T max(d, 0) + l^T min(d, 0) < 0. Both are positively homogeneous, so
  // the kernels measure dy and the normalization happens here.
  auto infeasible = [&]() {
    for (Eigen::Index c = 0; c < k; ++c) {
      const double norm = s.dy[c];
      if (!(norm > 0.0)) continue;
      if (s.Ctdy[c] / norm <= settings_.infeasibilityTolerance &&
          s.support[c] / norm <= -settings_.infeasibilityTolerance) {
        return true;
      }
    }
    return false;
  };

  // Feasible, and optimal to within inaccurateDualFactor of the dual tolerance
  // (AdmmStatus::SolvedInaccurate).
  auto nearOptimal = [&]() {
    return settings_.inaccurateDualFactor >= 1.0 && info.primalResidual <= primalTolerance &&
           info.dualResidual <= settings_.inaccurateDualFactor * dualTolerance;
  };

  // The stall window (AdmmSettings::stallIterations): where it began and the range of
  // ||dy|| seen in it; restarted after a rho change.
  struct StallWindow {
    int begin = -1;
    double primal = 0.0;
    double dyMin = 0.0, dyMax = 0.0;
    double dual = 0.0;
  } window;
  auto stalled = [&]() {
    if (settings_.stallIterations <= 0) return false;
    const double dy = maxOf(s.dy);
    if (window.begin < 0) {
      window = {info.iterations, info.primalResidual, dy, dy, info.dualResidual};
      return false;
    }
    window.dyMin = std::min(window.dyMin, dy);
    window.dyMax = std::max(window.dyMax, dy);
    if (info.iterations - window.begin < settings_.stallIterations) return false;
    const double change = settings_.stallChange;
    const bool stuck = window.dyMin > 0.0 && window.dyMax <= (1.0 + change) * window.dyMin &&
                       info.primalResidual >= (1.0 - change) * window.primal;
    // Whether a residual that went from `before` to `now` through the window would, at that
    // rate, reach `tolerance` only past the iteration cap (or not at all).
    auto tooSlowForTheCap = [&](double before, double now, double tolerance) {
      if (!(now < before)) return true;
      const double windowsNeeded = std::log(tolerance / now) / std::log(now / before);
      return windowsNeeded * (info.iterations - window.begin) > settings_.maxIterations - info.iterations;
    };
    // Falling, but too slowly: the attempt would end unconverged at the cap all the same
    // (e.g. a few percent per window at rho's clamp, with ||dy|| shrinking as slowly).
    const bool tooSlow = info.primalResidual > primalTolerance && info.primalResidual < window.primal &&
                         tooSlowForTheCap(window.primal, info.primalResidual, primalTolerance);
    // Near optimal, the dual residual too slow to meet its own tolerance within the cap: the
    // attempt would at best end solved-inaccurate at the cap, so it ends here, solved-
    // inaccurate (set after the loop). On a 3-ring dome's two Catmull-Clark levels: 8 240 ->
    // 5 380 ADMM iterations.
    const bool settledInaccurate = info.dualResidual > dualTolerance && nearOptimal() &&
                                   tooSlowForTheCap(window.dual, info.dualResidual, dualTolerance);
    // Far from optimal and as slow (AdmmSettings::farDualFactor).
    const bool farAndSlow = settings_.farDualFactor > 0.0 &&
                            info.dualResidual > settings_.farDualFactor * dualTolerance &&
                            info.dualResidual < window.dual &&
                            tooSlowForTheCap(window.dual, info.dualResidual, dualTolerance);
    window = {info.iterations, info.primalResidual, dy, dy, info.dualResidual};
    return stuck || tooSlow || settledInaccurate || farAndSlow;
  };

  s = kernels_->measure();
  if (converged()) {
    info.status = AdmmStatus::Solved;
  } else if (!iterations) {
    info.status = AdmmStatus::MaxIterationsReached;
  } else {
    // K is formed (on the CPU: factored) only for a start that needs iterations: a warm
    // start that already meets the tolerances (targets compatible to rounding, e.g. the
    // linear scheme's points of a translational surface) costs no factorization.
    if (!factored_ || equality != factoredEquality_ || factoredRho_ != rho_) {
      kernels_->setRho(equality, rho_);
      factored_ = true;
      factoredEquality_ = equality;
      factoredRho_ = rho_;
      ++info.factorizations;
    }
    // Convergence-only checks after every iteration while the inner solves are long
    // (AdmmSettings::convergenceCheckSolveIterations), decided at each regular check.
    bool checkEveryIteration = false;
    int iterationsAtCheck = 0;
    long solveIterationsAtCheck = s.linearIterations;
    double primalAtCheck = info.primalResidual, dualAtCheck = info.dualResidual;
    // Whether a residual that fell from `before` to `now` over the last block, at that rate,
    // meets `tolerance` within the next block (met already counts).
    const auto withinABlock = [](double before, double now, double tolerance) {
      if (now <= tolerance) return true;
      return now < before && std::log(tolerance / now) / std::log(now / before) <= 1.0;
    };
    while (info.iterations < settings_.maxIterations) {
      // Between check blocks the iterate is consistent: an interruption loses nothing.
      throwIfCancelled("the ADMM iteration");
      // Checks at multiples of checkInterval and at maxIterations, as in OSQP.
      const int regularCheck = std::min(settings_.maxIterations,
                                        (info.iterations / settings_.checkInterval + 1) * settings_.checkInterval);
      const int next = checkEveryIteration ? info.iterations + 1 : regularCheck;
      kernels_->setLinearTolerance(linearTolerance);
      kernels_->iterate(next - info.iterations);
      info.iterations = next;
      s = kernels_->measure();
      if (!allFinite(s.x) || !allFinite(s.y)) {
        info.status = AdmmStatus::NonFinite;
        break;
      }
      if (next < regularCheck) {
        if (converged(false)) {
          reportCheck();
          info.status = AdmmStatus::Solved;
          break;
        }
        continue;
      }
      const int threshold = settings_.convergenceCheckSolveIterations;
      const bool longSolves = threshold > 0 && s.linearIterations - solveIterationsAtCheck >=
                                                   static_cast<long>(threshold) * (info.iterations - iterationsAtCheck);
      iterationsAtCheck = info.iterations;
      solveIterationsAtCheck = s.linearIterations;
      const bool done = converged();
      // Only a block expected to converge is checked iteration by iteration: a long
      // attempt's checks would otherwise cost more than the few iterations they save.
      checkEveryIteration = longSolves && withinABlock(primalAtCheck, info.primalResidual, primalTolerance) &&
                            withinABlock(dualAtCheck, info.dualResidual, dualTolerance);
      primalAtCheck = info.primalResidual;
      dualAtCheck = info.dualResidual;
      reportCheck();
      if (done) {
        info.status = AdmmStatus::Solved;
        break;
      }
      if (infeasible()) {
        info.status = AdmmStatus::PrimalInfeasible;
        break;
      }
      if (stalled()) {
        info.status = AdmmStatus::Stalled;
        break;
      }
      if (settings_.adaptiveRho) {
        const double proposed = std::clamp(rho_ * rhoBalance, 1e-6, 1e6);
        if (proposed > rho_ * settings_.adaptiveRhoFactor || proposed < rho_ / settings_.adaptiveRhoFactor) {
          rho_ = proposed;
          window.begin = -1;
          kernels_->setRho(equality, rho_);
          factoredRho_ = rho_;
          ++info.factorizations;
        }
      }
    }
  }
  // A feasible point whose optimality misses its tolerance by a small factor: on the ε
  // schedule's small attempts the dual residual often creeps down for thousands of
  // iterations while the primal one is long converged, and discarding such a point for
  // the next ε (ten times larger) gave up the step's progress.
  const bool unconverged = info.status == AdmmStatus::MaxIterationsReached || info.status == AdmmStatus::Stalled;
  if (unconverged && info.iterations > 0 && nearOptimal()) info.status = AdmmStatus::SolvedInaccurate;
  info.rho = rho_;
  info.linearIterations = s.linearIterations;
  info.inexactSolves = s.inexactSolves;
  return info;
}

}  // namespace plano::compute
