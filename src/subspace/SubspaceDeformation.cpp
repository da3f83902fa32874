#include "subspace/SubspaceDeformation.h"

#include <limits>
#include <string>

#include "core/Cancellation.h"
#include "core/Error.h"

namespace plano::subspace {
namespace {

/// K = sum_f P_f^T C_k P_f: the scalar matrix of the centred-corner energy.
compute::SparseMatrix centredCornerMatrix(const FaceList& faces, Index vertexCount) {
  std::vector<Eigen::Triplet<double>> triplets;
  for (Index f = 0; f < faces.size(); ++f) {
    const auto face = faces[f];
    const Index k = faces.degree(f);
    for (Index i = 0; i < k; ++i)
      for (Index j = 0; j < k; ++j) triplets.emplace_back(face[i], face[j], (i == j ? 1.0 : 0.0) - 1.0 / k);
  }
  compute::SparseMatrix K(vertexCount, vertexCount);
  K.setFromTriplets(triplets.begin(), triplets.end());
  return K;
}

}  // namespace

DeformationEnergy parseDeformationEnergy(const std::string& text) {
  if (text == "asap") return DeformationEnergy::Asap;
  if (text == "arap") return DeformationEnergy::Arap;
  throwUsage("unknown energy '" + text + "' (expected asap or arap)");
}

SubspaceDeformer::SubspaceDeformer(const LinearSpace& space, const PositionalConstraints& constraints,
                                   compute::Backend& backend, const SubspaceDeformationSettings& settings)
    : space_(space), constraints_(constraints), backend_(backend), settings_(settings) {
  const PolygonMesh& Y = space.source;
  constrained_ = constrainSubspace(space.N, constraints, Y.vertices, settings.rankTolerance);
  reduced_ = space.N.reducedOperator(centredCornerMatrix(Y.faces, Y.vertexCount()));
  Eigen::MatrixXd H = constrained_.free.transpose() * reduced_ * constrained_.free;
  // A direction the energy ignores and the constraints leave free (a free translation when
  // nothing is fixed) would make H singular: a tiny relative Tikhonov term picks the
  // smallest such motion instead of failing.
  if (H.rows() > 0) H.diagonal().array() += 1e-12 * std::max(H.diagonal().maxCoeff(), 1.0);
  factor_.compute(H);
  if (factor_.info() != Eigen::Success) throwNumerical("subspace deformation: factorization of the global matrix failed");
  const std::size_t nf = static_cast<std::size_t>(Y.faceCount());
  covariances_.resize(nf);
  rotations_.resize(nf);
  singularValues_.resize(nf);
}

double SubspaceDeformer::localStep(const Positions& X) {
  const PolygonMesh& Y = space_.source;
  const Index nf = Y.faceCount();
  std::vector<Eigen::Vector3d> xc, yc;
  for (Index f = 0; f < nf; ++f) {
    const auto face = Y.faces[f];
    Eigen::Vector3d xm = Eigen::Vector3d::Zero(), ym = Eigen::Vector3d::Zero();
    for (Index v : face) {
      xm += X.row(v).transpose();
      ym += Y.vertices.row(v).transpose();
    }
    xm /= static_cast<double>(face.size());
    ym /= static_cast<double>(face.size());
    Eigen::Matrix3d M = Eigen::Matrix3d::Zero();
    for (Index v : face) M += (X.row(v).transpose() - xm) * (Y.vertices.row(v).transpose() - ym).transpose();
    covariances_[f] = M;
  }
  backend_.closestRotations(covariances_, rotations_, singularValues_);
  targets_ = Positions::Zero(Y.vertexCount(), 3);
  double energy = 0.0;
  for (Index f = 0; f < nf; ++f) {
    const auto face = Y.faces[f];
    Eigen::Vector3d xm = Eigen::Vector3d::Zero(), ym = Eigen::Vector3d::Zero();
    for (Index v : face) {
      xm += X.row(v).transpose();
      ym += Y.vertices.row(v).transpose();
    }
    xm /= static_cast<double>(face.size());
    ym /= static_cast<double>(face.size());
    double scale = 1.0;
    if (settings_.energy == DeformationEnergy::Asap) {
      double norm2 = 0.0;
      for (Index v : face) norm2 += (Y.vertices.row(v).transpose() - ym).squaredNorm();
      scale = norm2 > 0.0 ? singularValues_[f].sum() / norm2 : 1.0;
    }
    for (Index v : face) {
      const Eigen::Vector3d t = scale * rotations_[f] * (Y.vertices.row(v).transpose() - ym);
      targets_.row(v) += t.transpose();
      energy += (X.row(v).transpose() - xm - t).squaredNorm();
    }
  }
  return energy;
}

SubspaceDeformationInfo SubspaceDeformer::solve(Positions& X, const std::function<void(Index, const Positions&)>& onIterate) {
  if (X.rows() != space_.source.vertexCount() || X.cols() != 3) {
    throwUsage("subspace deformation: the warm start has the wrong size");
  }
  SubspaceDeformationInfo info;
  const Eigen::MatrixXd& F = constrained_.free;
  const Eigen::VectorXd& W0 = constrained_.particular;
  const Eigen::VectorXd fixedPart = reduced_ * W0;
  double previous = std::numeric_limits<double>::infinity();
  for (Index k = 0; k < settings_.maxIterations; ++k) {
    throwIfCancelled("subspace deformation");
    const double energy = localStep(X);
    info.energy = energy;
    if (k > 0 && previous - energy <= settings_.tolerance * std::max(previous, 1e-300)) {
      info.status = DeformationStatus::Converged;
      break;
    }
    previous = energy;
    Eigen::VectorXd W = W0;
    if (F.cols() > 0) {
      const Eigen::VectorXd rhs = F.transpose() * (space_.N.coefficients(targets_) - fixedPart);
      W += F * factor_.solve(rhs);
    }
    X = space_.N.shape(W);
    if (!X.allFinite()) throwNumerical("subspace deformation: non-finite positions at iteration " + std::to_string(k));
    info.iterations = k + 1;
    info.maxSubspaceResidual = std::max(info.maxSubspaceResidual, space_.B.residual(X) / std::max(X.norm(), 1e-300));
    if (onIterate) onIterate(k, X);
  }
  info.constraintResidual = constrained_.constraintResidual;
  for (Index v : constraints_.fixed)
    info.maxHandleDistance = std::max(info.maxHandleDistance, (X.row(v) - space_.source.vertices.row(v)).norm());
  for (const Handle& h : constraints_.handles)
    info.maxHandleDistance = std::max(info.maxHandleDistance, (X.row(h.vertex).transpose() - h.position).norm());
  return info;
}

}  // namespace plano::subspace
