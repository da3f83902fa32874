#include "compute/cpu/CpuBackend.h"

#include <Eigen/CholmodSupport>
#include <Eigen/Dense>
#include <Eigen/SVD>
#include <algorithm>

#include "core/Cancellation.h"
#include "core/Error.h"
#include "mesh/Planarity.h"
#include "projective/IdealMapFit.h"
#include "projective/LocalFit.h"

namespace plano::compute {
namespace {

/// Prefactored sparse Cholesky (supernodal CHOLMOD). Solves are exact up to rounding.
class CholmodSpdSolver final : public SpdSolver {
 public:
  CholmodSpdSolver(const SparseMatrix& A, bool measureResidual) : size_(A.rows()), measureResidual_(measureResidual) {
    if (A.rows() != A.cols()) throwNumerical("SPD solver: matrix is not square");
    // A failed factorization is reported by the Error below (and its callers' fallbacks),
    // not by CHOLMOD's own "matrix not positive definite" lines on the user's terminal.
    factor_.cholmod().print = 0;
    columnMajor_ = A;
    factor_.compute(columnMajor_);
    if (factor_.info() != Eigen::Success) {
      throwNumerical("SPD solver: Cholesky factorization failed (matrix not positive definite)");
    }
  }

  LinearSolveInfo solve(const Eigen::MatrixXd& B, Eigen::MatrixXd& X) override {
    // Every ADMM iteration (BoxQp) and most solver iterations make a solve here: polling
    // here makes them interruptible without touching each loop.
    throwIfCancelled("a linear solve");
    X = factor_.solve(B);
    LinearSolveInfo info;
    info.iterations = 1;
    // A non-finite B gives a non-finite X, whose residual relative to a NaN ||B|| would
    // read 0: finiteness is checked on X itself.
    info.converged = factor_.info() == Eigen::Success && X.allFinite();
    if (measureResidual_) {
      const double bNorm = B.norm();
      info.relativeResidual = bNorm > 0.0 ? (columnMajor_ * X - B).norm() / bNorm : 0.0;
      info.converged = info.converged && std::isfinite(info.relativeResidual);
    }
    return info;
  }

  Eigen::Index size() const override { return size_; }

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
  Eigen::SparseMatrix<double> columnMajor_;
  Eigen::CholmodSupernodalLLT<Eigen::SparseMatrix<double>> factor_;
};

}  // namespace

void CpuBackend::facePlanarity(const PolygonMesh& mesh, std::span<double> out) {
  for (Index f = 0; f < mesh.faceCount(); ++f) out[f] = plano::facePlanarity(mesh.vertices, mesh.faces[f]).mean;
}

void CpuBackend::fitProjectiveMaps(const FaceList& faces, const Positions& source, const Positions& target,
                                   ProjectiveFits& out) {
  checkFitInputs(source, target);
  const Index faceCount = faces.size();
  out.maps.resize(faceCount);
  out.reciprocalScales.resize(faces.cornerCount());
  out.residuals.resize(faceCount);
  out.ranks.resize(faceCount);
  std::vector<Eigen::Vector3d> p;
  std::vector<Eigen::Vector3d> q;
  for (Index f = 0; f < faceCount; ++f) {
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
}

void CpuBackend::closestRotations(std::span<const Eigen::Matrix3d> matrices, std::span<Eigen::Matrix3d> rotations,
                                  std::span<Eigen::Vector3d> singularValues) {
  for (std::size_t i = 0; i < matrices.size(); ++i) {
    Eigen::JacobiSVD<Eigen::Matrix3d> svd(matrices[i], Eigen::ComputeFullU | Eigen::ComputeFullV);
    const Eigen::Matrix3d& U = svd.matrixU();
    const Eigen::Matrix3d& V = svd.matrixV();
    const double d = (U * V.transpose()).determinant() < 0.0 ? -1.0 : 1.0;
    rotations[i] = U * Eigen::Vector3d(1.0, 1.0, d).asDiagonal() * V.transpose();
    singularValues[i] = svd.singularValues();
    singularValues[i][2] *= d;
  }
}

void CpuBackend::closestIdealMaps(const FaceList& faces, const Positions& source,
                                  std::span<const Eigen::Matrix4d> fitted, const Positions* target, bool similar,
                                  IdealMaps& out) {
  checkIdealMapInputs(faces, source, fitted, target);
  const Index faceCount = faces.size();
  out.maps.resize(faceCount);
  out.methods.resize(faceCount);
  Eigen::Matrix<double, Eigen::Dynamic, 3> p, q;
  for (Index f = 0; f < faceCount; ++f) {
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
    closestRotations({&lin.linear, 1}, {&R, 1}, {&singular, 1});
    out.methods[f] = lin.method;
    out.maps[f] = lin.method == IdealMapMethod::CentroidAtInfinity ? Eigen::Matrix4d::Identity()
                                                                    : projective::idealMapOf(lin, R, singular, similar);
  }
}

std::unique_ptr<SpdSolver> CpuBackend::createSpdSolver(const SparseMatrix& A, const LinearSolverSettings& settings) {
  return std::make_unique<CholmodSpdSolver>(A, settings.measureResidual);
}

}  // namespace plano::compute
