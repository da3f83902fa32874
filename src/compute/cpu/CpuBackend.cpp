#include "compute/cpu/CpuBackend.h"

#include <Eigen/CholmodSupport>
#include <Eigen/Dense>
#include <Eigen/SVD>
#include <algorithm>

#include "core/Cancellation.h"
#include "core/Error.h"
#include "core/Memory.h"
#include "core/ParallelFor.h"
#include "mesh/Planarity.h"
#include "projective/IdealMapFit.h"
#include "projective/LocalFit.h"

namespace plano::compute {
namespace {

/// CHOLMOD's Cholesky LL^T, simplicial or supernodal as CHOLMOD's analysis decides from the
/// flops per factor entry (kSupernodalSwitch), with the memory its numeric factorization
/// takes known from the symbolic analysis, before that memory is allocated.
///
/// Why not always supernodal: a supernodal factor's solves run a BLAS call per supernode,
/// and the global steps' matrices of small and mid-sized meshes have many small ones, so
/// its solves (thousands per factorization in the ADMM) took up to 2.5 times a simplicial
/// factor's, while factoring no faster. Measured on a 2-core machine (fl = CHOLMOD's flop
/// count; supernodal vs simplicial, ms): Enneper's first Catmull-Clark level, 21 600 rows,
/// fl/lnz 28-69: solves 1.8-2.5 vs 0.70-1.23, factorizations 21-33 vs 7-24; the cube's
/// 6 144-row level, fl/lnz 111-130: solves 0.64-0.76 vs 0.46-0.51, factorizations 15-18
/// vs 14-17; the 16k-row global step, fl/lnz 177: about equal solves (3.0-3.5), factorizations
/// 84-90 vs 117-120; the 262k-row one, fl/lnz 509: solves 115 vs 139, factorizations 2.1 vs
/// 12.5 s. CHOLMOD's own switch (40) chose supernodal for some of the Enneper matrices.
class CholeskyFactor final : public Eigen::CholmodDecomposition<Eigen::SparseMatrix<double>> {
 public:
  /// Supernodal from this many flops per entry of L on (CHOLMOD's supernodal_switch).
  static constexpr double kSupernodalSwitch = 150.0;

  CholeskyFactor() {
    // LL^T either way (a simplicial factor converted from CHOLMOD's LDL^T), so that a
    // matrix that is not positive definite fails to factor whichever is chosen.
    setMode(Eigen::CholmodSimplicialLLt);
    cholmod().supernodal = CHOLMOD_AUTO;
    cholmod().supernodal_switch = kSupernodalSwitch;
  }
  CholeskyFactor(const CholeskyFactor&) = delete;
  CholeskyFactor& operator=(const CholeskyFactor&) = delete;
  ~CholeskyFactor() {
    cholmod_free_dense(&solution_, &cholmod());
    cholmod_free_dense(&workY_, &cholmod());
    cholmod_free_dense(&workE_, &cholmod());
  }

  /// analyzePattern gave a symbolic factor (CHOLMOD returns none when it fails, e.g. out of
  /// memory, and factorize would then read a null pointer).
  bool analyzed() const { return m_cholmodFactor != nullptr; }

  /// X = A^-1 B with the factor; false when CHOLMOD fails. Unlike Eigen's solve (cholmod_solve),
  /// the solution and CHOLMOD's workspaces are kept for the next solve of the same shape:
  /// the ADMM solves thousands of times with one factor, and each solve allocated (and,
  /// at these sizes, mapped and zeroed) three n x k arrays.
  bool solveInto(const Eigen::MatrixXd& B, Eigen::MatrixXd& X) {
    if (!m_cholmodFactor || !m_factorizationIsOk || info() != Eigen::Success) return false;
    cholmod_dense b{};
    b.nrow = static_cast<std::size_t>(B.rows());
    b.ncol = static_cast<std::size_t>(B.cols());
    b.nzmax = b.nrow * b.ncol;
    b.d = b.nrow;
    // CHOLMOD reads B only; its struct has no const view.
    b.x = const_cast<double*>(B.data());
    b.z = nullptr;
    b.xtype = CHOLMOD_REAL;
    b.dtype = CHOLMOD_DOUBLE;
    if (!cholmod_solve2(CHOLMOD_A, m_cholmodFactor, &b, nullptr, &solution_, nullptr, &workY_, &workE_,
                        &cholmod())) {
      return false;
    }
    X = Eigen::Map<const Eigen::MatrixXd>(static_cast<const double*>(solution_->x), B.rows(), B.cols());
    return true;
  }
  /// Bytes the numeric factorization holds at its peak, after analyzePattern (0 before):
  /// L's values and row indices, its largest update matrix, and the permuted copy of A's
  /// lower triangle (a value and an index per entry) it factors. A simplicial factor holds
  /// an index beside each of its lnz values.
  /// Measured (growth of VmHWM) on global-step matrices of 16k, 262k and 1M rows
  /// (supernodal): 0.011 / 0.387 / 1.99 GiB, against 0.018 / 0.42 / 1.90 GiB estimated here.
  double numericBytes(Eigen::Index lowerNonZeros) {
    const cholmod_factor* L = m_cholmodFactor;
    if (!L) return 0.0;  // no analysis, or a failed one
    constexpr double kEntry = sizeof(double) + sizeof(int);
    const double copy = kEntry * static_cast<double>(lowerNonZeros);
    if (!L->is_super) return kEntry * cholmod().lnz + copy;
    return sizeof(double) * (static_cast<double>(L->xsize) + static_cast<double>(L->maxcsize)) +
           sizeof(int) * static_cast<double>(L->ssize) + copy;
  }

 private:
  cholmod_dense* solution_ = nullptr;  ///< solveInto's X and workspaces, kept between solves.
  cholmod_dense* workY_ = nullptr;
  cholmod_dense* workE_ = nullptr;
};

/// Prefactored sparse Cholesky (CHOLMOD, CholeskyFactor). Solves are exact up to rounding.
class CholmodSpdSolver final : public SpdSolver {
 public:
  CholmodSpdSolver(const SparseMatrix& A, bool measureResidual, std::uint64_t memoryLimit)
      : size_(A.rows()), measureResidual_(measureResidual) {
    if (A.rows() != A.cols()) throwNumerical("SPD solver: matrix is not square");
    // A failed factorization is reported by the Error below (and its callers' fallbacks),
    // not by CHOLMOD's own "matrix not positive definite" lines on the user's terminal.
    factor_.cholmod().print = 0;
    columnMajor_ = A;
    // The factor of a large global step is many times A's size (fill-in): Linux would
    // grant it and kill the process once it is touched, so it is refused here, with its
    // size, before the numeric factorization allocates it.
    factor_.analyzePattern(columnMajor_);
    if (!factor_.analyzed()) throwNumerical("SPD solver: the symbolic analysis of the Cholesky factorization failed");
    factorBytes_ = factor_.numericBytes((columnMajor_.nonZeros() + size_) / 2);
    requireMemory(factorBytes_,
                  "the Cholesky factor of a sparse " + std::to_string(size_) + " x " + std::to_string(size_) +
                      " matrix (" + std::to_string(columnMajor_.nonZeros()) + " nonzeros)",
                  memoryLimit);
    factor_.factorize(columnMajor_);
    if (factor_.info() != Eigen::Success) {
      throwNumerical("SPD solver: Cholesky factorization failed (matrix not positive definite)");
    }
  }

  LinearSolveInfo solve(const Eigen::MatrixXd& B, Eigen::MatrixXd& X) override {
    // Every ADMM iteration (BoxQp) and most solver iterations make a solve here: polling
    // here makes them interruptible without touching each loop.
    throwIfCancelled("a linear solve");
    const bool solved = factor_.solveInto(B, X);
    LinearSolveInfo info;
    info.iterations = 1;
    // A non-finite B gives a non-finite X, whose residual relative to a NaN ||B|| would
    // read 0: finiteness is checked on X itself.
    info.converged = solved && X.allFinite();
    if (measureResidual_) {
      const double bNorm = B.norm();
      info.relativeResidual = bNorm > 0.0 ? (columnMajor_ * X - B).norm() / bNorm : 0.0;
      info.converged = info.converged && std::isfinite(info.relativeResidual);
    }
    return info;
  }

  Eigen::Index size() const override { return size_; }
  double factorBytes() const override { return factorBytes_; }

  bool refactor(const SparseMatrix& A) override {
    if (A.rows() != size_ || A.cols() != size_) return false;
    Eigen::SparseMatrix<double> columnMajor = A;
    columnMajor.makeCompressed();
    // The symbolic analysis holds for this pattern only.
    if (columnMajor.nonZeros() != columnMajor_.nonZeros() ||
        !std::equal(columnMajor.outerIndexPtr(), columnMajor.outerIndexPtr() + size_ + 1,
                    columnMajor_.outerIndexPtr()) ||
        !std::equal(columnMajor.innerIndexPtr(), columnMajor.innerIndexPtr() + columnMajor.nonZeros(),
                    columnMajor_.innerIndexPtr())) {
      return false;
    }
    columnMajor_ = std::move(columnMajor);
    factor_.factorize(columnMajor_);
    if (factor_.info() != Eigen::Success) {
      throwNumerical("SPD solver: Cholesky factorization failed (matrix not positive definite)");
    }
    return true;
  }

 private:
  Eigen::Index size_;
  bool measureResidual_;
  double factorBytes_ = 0.0;
  Eigen::SparseMatrix<double> columnMajor_;
  CholeskyFactor factor_;
};

/// Items per thread at the least (core/ParallelFor.h): handing a chunk to another thread
/// (~10 us from the pool, tens of microseconds when a thread is started) pays only for
/// chunks that take far longer, 512 fits (~5 us each) or
/// 16 384 planarities (~20 ns each).
constexpr std::ptrdiff_t kPlanaritiesPerThread = 16384;
constexpr std::ptrdiff_t kFitsPerThread = 512;

}  // namespace

void CpuBackend::facePlanarity(const PolygonMesh& mesh, std::span<double> out) {
  parallelFor(mesh.faceCount(), kPlanaritiesPerThread, [&](std::ptrdiff_t begin, std::ptrdiff_t end) {
    for (auto f = static_cast<Index>(begin); f < end; ++f) {
      out[f] = plano::facePlanarity(mesh.vertices, mesh.faces[f]).mean;
    }
  });
}

void CpuBackend::fitProjectiveMaps(const FaceList& faces, const Positions& source, const Positions& target,
                                   ProjectiveFits& out) {
  checkFitInputs(source, target);
  const Index faceCount = faces.size();
  out.maps.resize(faceCount);
  out.reciprocalScales.resize(faces.cornerCount());
  out.residuals.resize(faceCount);
  out.ranks.resize(faceCount);
  parallelFor(faceCount, kFitsPerThread, [&](std::ptrdiff_t begin, std::ptrdiff_t end) {
    std::vector<Eigen::Vector3d> p;
    std::vector<Eigen::Vector3d> q;
    for (auto f = static_cast<Index>(begin); f < end; ++f) {
      const auto face = faces[f];
      p.clear();
      q.clear();
      for (Index v : face) {
        p.emplace_back(source.row(v).transpose());
        q.emplace_back(target.row(v).transpose());
      }
      const projective::ProjectiveFit fit = projective::fitProjectiveMap(p, q);
      out.maps[f] = fit.map;
      out.residuals[f] = fit.residual;
      out.ranks[f] = fit.rank;
      std::copy(fit.reciprocalScales.begin(), fit.reciprocalScales.end(),
                out.reciprocalScales.begin() + faces.offsets()[f]);
    }
  });
}

void CpuBackend::closestRotations(std::span<const Eigen::Matrix3d> matrices, std::span<Eigen::Matrix3d> rotations,
                                  std::span<Eigen::Vector3d> singularValues) {
  parallelFor(static_cast<std::ptrdiff_t>(matrices.size()), kFitsPerThread,
              [&](std::ptrdiff_t begin, std::ptrdiff_t end) {
                for (auto i = static_cast<std::size_t>(begin); i < static_cast<std::size_t>(end); ++i) {
                  closestRotation(matrices[i], rotations[i], singularValues[i]);
                }
              });
}

void CpuBackend::closestRotation(const Eigen::Matrix3d& matrix, Eigen::Matrix3d& rotation,
                                 Eigen::Vector3d& singularValues) {
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(matrix, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Eigen::Matrix3d& U = svd.matrixU();
  const Eigen::Matrix3d& V = svd.matrixV();
  const double d = (U * V.transpose()).determinant() < 0.0 ? -1.0 : 1.0;
  rotation = U * Eigen::Vector3d(1.0, 1.0, d).asDiagonal() * V.transpose();
  singularValues = svd.singularValues();
  singularValues[2] *= d;
}

void CpuBackend::closestIdealMaps(const FaceList& faces, const Positions& source,
                                  std::span<const Eigen::Matrix4d> fitted, const Positions* target, bool similar,
                                  IdealMaps& out) {
  checkIdealMapInputs(faces, source, fitted, target);
  const Index faceCount = faces.size();
  out.maps.resize(faceCount);
  out.methods.resize(faceCount);
  parallelFor(faceCount, kFitsPerThread, [&](std::ptrdiff_t begin, std::ptrdiff_t end) {
    Eigen::Matrix<double, Eigen::Dynamic, 3> p, q;
    for (auto f = static_cast<Index>(begin); f < end; ++f) {
      const auto face = faces[f];
      const auto k = static_cast<Eigen::Index>(face.size());
      p.resize(k, 3);
      q.resize(k, 3);
      for (Eigen::Index i = 0; i < k; ++i) {
        p.row(i) = source.row(face[i]);
        if (target) q.row(i) = target->row(face[i]);
      }
      const projective::IdealMapLinearization lin = projective::linearizeFaceMap(p, fitted[f], target ? &q : nullptr);
      Eigen::Matrix3d R;
      Eigen::Vector3d singular;
      closestRotation(lin.linear, R, singular);
      out.methods[f] = lin.method;
      out.maps[f] = lin.method == IdealMapMethod::CentroidAtInfinity
                        ? Eigen::Matrix4d::Identity()
                        : projective::idealMapOf(lin, R, singular, similar);
    }
  });
}

std::unique_ptr<SpdSolver> CpuBackend::createSpdSolver(const SparseMatrix& A, const LinearSolverSettings& settings) {
  return std::make_unique<CholmodSpdSolver>(A, settings.measureResidual, settings.memoryLimitBytes);
}

}  // namespace plano::compute
