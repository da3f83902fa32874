#include "subspace/SubspaceDeformation.h"

#include <cmath>
#include <limits>
#include <memory>
#include <span>
#include <string>

#include "core/Cancellation.h"
#include "core/Error.h"
#include "compute/ReducedArap.h"

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
  reduced_ = space.N.reducedOperator(backend_, centredCornerMatrix(Y.faces, Y.vertexCount()));
  Eigen::MatrixXd H = constrained_.free.transpose() * reduced_ * constrained_.free;
  // A direction the energy ignores and the constraints leave free (a free translation when
  // nothing is fixed) would make H singular: a tiny relative Tikhonov term picks the
  // smallest such motion instead of failing.
  if (H.rows() > 0) H.diagonal().array() += 1e-12 * std::max(H.diagonal().maxCoeff(), 1.0);
  factor_.compute(H);
  if (factor_.info() != Eigen::Success) throwNumerical("subspace deformation: factorization of the global matrix failed");
  fixedPart_ = reduced_ * constrained_.particular;
}

SubspaceDeformer::~SubspaceDeformer() = default;

/// The host kernels: the Eigen loop, the global step solved with the deformer's LDLT.
class SubspaceDeformer::HostKernels final : public compute::ReducedArapKernels {
 public:
  explicit HostKernels(SubspaceDeformer& deformer) : d_(deformer) {
    const std::size_t nf = static_cast<std::size_t>(d_.space_.source.faceCount());
    covariances_.resize(nf);
    rotations_.resize(nf);
    singularValues_.resize(nf);
    xCentroids_.resize(nf);
    yCentroids_.resize(nf);
  }
  int preferredBlock() const override { return 1; }
  void start(const Positions& X) override { X_ = X; }
  std::vector<compute::ReducedArapMeasures> iterate(int count) override {
    std::vector<compute::ReducedArapMeasures> measures(count);
    before_.resize(count);
    for (int k = 0; k < count; ++k) {
      before_[k] = X_;
      measures[k].energy = localStep();
      globalStep();
      measures[k].constraintNorm = d_.space_.B.residual(X_);
      measures[k].positionsNorm = X_.norm();
    }
    return measures;
  }
  void positions(int index, Positions& X) override { X = index < static_cast<int>(before_.size()) ? before_[index] : X_; }

 private:
  /// Fills targets_ (G = sum_f P_f^T (s_f C Y_f R_f^T)), returns the energy at X_.
  double localStep() {
    const PolygonMesh& Y = d_.space_.source;
    const Index nf = Y.faceCount();
    for (Index f = 0; f < nf; ++f) {
      const auto face = Y.faces[f];
      centroid(face, X_, xCentroids_[f]);
      centroid(face, Y.vertices, yCentroids_[f]);
      Eigen::Matrix3d M = Eigen::Matrix3d::Zero();
      for (Index v : face) {
        M += (X_.row(v).transpose() - xCentroids_[f]) * (Y.vertices.row(v).transpose() - yCentroids_[f]).transpose();
      }
      covariances_[f] = M;
    }
    d_.backend_.closestRotations(covariances_, rotations_, singularValues_);
    targets_ = Positions::Zero(Y.vertexCount(), 3);
    double energy = 0.0;
    for (Index f = 0; f < nf; ++f) {
      const auto face = Y.faces[f];
      const Eigen::Vector3d& xm = xCentroids_[f];
      const Eigen::Vector3d& ym = yCentroids_[f];
      double scale = 1.0;
      if (d_.settings_.energy == DeformationEnergy::Asap) {
        double norm2 = 0.0;
        for (Index v : face) norm2 += (Y.vertices.row(v).transpose() - ym).squaredNorm();
        scale = norm2 > 0.0 ? singularValues_[f].sum() / norm2 : 1.0;
      }
      for (Index v : face) {
        const Eigen::Vector3d t = scale * rotations_[f] * (Y.vertices.row(v).transpose() - ym);
        targets_.row(v) += t.transpose();
        energy += (X_.row(v).transpose() - xm - t).squaredNorm();
      }
    }
    return energy;
  }

  static void centroid(std::span<const Index> face, const Positions& P, Eigen::Vector3d& out) {
    out.setZero();
    for (Index v : face) out += P.row(v).transpose();
    out /= static_cast<double>(face.size());
  }

  void globalStep() {
    const Eigen::MatrixXd& F = d_.constrained_.free;
    Eigen::VectorXd W = d_.constrained_.particular;
    if (F.cols() > 0) {
      const Eigen::VectorXd rhs = F.transpose() * (d_.space_.N.coefficients(targets_) - d_.fixedPart_);
      W += F * d_.factor_.solve(rhs);
    }
    X_ = d_.space_.N.shape(W);
  }

  SubspaceDeformer& d_;
  Positions X_;
  std::vector<Positions> before_;  ///< X before each global step of the last block.
  Positions targets_;
  std::vector<Eigen::Matrix3d> covariances_, rotations_;
  std::vector<Eigen::Vector3d> singularValues_;
  std::vector<Eigen::Vector3d> xCentroids_, yCentroids_;  ///< Per face, of X_ and the rest shape.
};

compute::ReducedArapProblem SubspaceDeformer::reducedProblem() const {
  // x = N W with W = W0 + G (N^T g - R W0), G = F H^-1 F^T: offset N (W0 - G R W0), basis N
  // (as a 3 #V x d matrix: coefficient 3 a + c of a separable space moves coordinate c
  // along scalar column a), gain G.
  const SubspaceBasis& N = space_.N;
  const Index d = N.dimension();
  const Index V = N.vertexCount();
  const Eigen::MatrixXd& columns = N.columns();
  std::vector<Eigen::Triplet<double>> entries;
  entries.reserve(static_cast<std::size_t>(columns.size()) * (N.separable() ? 3 : 1));
  for (Index a = 0; a < columns.cols(); ++a) {
    for (Index r = 0; r < columns.rows(); ++r) {
      const double value = columns(r, a);
      if (value == 0.0) continue;
      if (N.separable()) {
        for (Index c = 0; c < 3; ++c) entries.emplace_back(3 * r + c, 3 * a + c, value);
      } else {
        entries.emplace_back(r, a, value);
      }
    }
  }
  compute::ReducedArapProblem problem;
  problem.basis.resize(3 * V, d);
  problem.basis.setFromTriplets(entries.begin(), entries.end());
  problem.basis.makeCompressed();
  const Eigen::MatrixXd& F = constrained_.free;
  problem.gain = Eigen::MatrixXd::Zero(d, d);
  if (F.cols() > 0) problem.gain = F * factor_.solve(F.transpose());
  const Eigen::VectorXd W = constrained_.particular - problem.gain * fixedPart_;
  problem.offset = problem.basis * W;
  problem.faces = space_.source.faces;
  problem.source = space_.source.vertices;
  problem.asap = settings_.energy == DeformationEnergy::Asap;
  problem.constraints = space_.B.fullMatrix();
  return problem;
}

SubspaceDeformationInfo SubspaceDeformer::solve(Positions& X, const std::function<void(Index, const Positions&)>& onIterate) {
  if (X.rows() != space_.source.vertexCount() || X.cols() != 3) {
    throwUsage("subspace deformation: the warm start has the wrong size");
  }
  if (!kernels_) {  // once per deformer: a backend uploads the problem only once
    kernels_ = backend_.createReducedArapKernels([this] { return reducedProblem(); });
    if (!kernels_) kernels_ = std::make_unique<HostKernels>(*this);
  }
  compute::ReducedArapKernels* kernels = kernels_.get();
  kernels->start(X);

  SubspaceDeformationInfo info;
  double previous = std::numeric_limits<double>::infinity();
  Index k = 0;
  bool stopped = false;
  Positions iterate;
  while (!stopped && k < settings_.maxIterations) {
    throwIfCancelled("subspace deformation");
    const int count = static_cast<int>(std::min<Index>(kernels->preferredBlock(), settings_.maxIterations - k));
    const std::vector<compute::ReducedArapMeasures> measures = kernels->iterate(count);
    for (int j = 0; j < count; ++j, ++k) {
      const compute::ReducedArapMeasures& m = measures[j];
      info.energy = m.energy;
      // The energy at X_k decides whether X_k is the answer; the global steps the kernels
      // ran past it in this block are discarded. The warm start X_0 need not meet the
      // constraints (the rest shape has energy 0), so the first comparison is X_2 with X_1,
      // both global-step results, between which the energy can only decrease.
      if (k > 1 && previous - m.energy <= settings_.tolerance * std::max(previous, 1e-300)) {
        info.status = DeformationStatus::Converged;
        kernels->positions(j, X);
        stopped = true;
        break;
      }
      previous = m.energy;
      if (!std::isfinite(m.positionsNorm)) {
        throwNumerical("subspace deformation: non-finite positions at iteration " + std::to_string(k));
      }
      info.iterations = k + 1;
      info.maxSubspaceResidual = std::max(info.maxSubspaceResidual, m.constraintNorm / std::max(m.positionsNorm, 1e-300));
      if (onIterate) {
        kernels->positions(j + 1, iterate);
        onIterate(k, iterate);
      }
    }
    if (!stopped) kernels->positions(count, X);
  }
  info.constraintResidual = constrained_.constraintResidual;
  for (Index v : constraints_.fixed)
    info.maxHandleDistance = std::max(info.maxHandleDistance, (X.row(v) - space_.source.vertices.row(v)).norm());
  for (const Handle& h : constraints_.handles)
    info.maxHandleDistance = std::max(info.maxHandleDistance, (X.row(h.vertex).transpose() - h.position).norm());
  return info;
}

}  // namespace plano::subspace
