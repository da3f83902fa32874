#include "compute/vulkan/VulkanReducedArap.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "core/Error.h"

namespace plano::vk {
namespace {

struct LocalStepPush {
  std::uint32_t faceCount, mode, asap;
};
struct RotationsPush {
  std::uint32_t count;
};

/// A dense matrix as CSR for the device's SpMV (exact zeros dropped).
compute::SparseMatrix csr(const Eigen::MatrixXd& dense) { return dense.sparseView(0.0, 0.0); }

/// S (3 #V x 3 #corners): row 3 v + c sums coordinate c of every corner of vertex v.
compute::SparseMatrix cornerGather(const FaceList& faces, Index vertexCount) {
  std::vector<Eigen::Triplet<double>> entries;
  entries.reserve(3 * static_cast<std::size_t>(faces.cornerCount()));
  const auto& indices = faces.indices();
  for (Index i = 0; i < faces.cornerCount(); ++i)
    for (Index c = 0; c < 3; ++c) entries.emplace_back(3 * indices[i] + c, 3 * i + c, 1.0);
  compute::SparseMatrix S(3 * vertexCount, 3 * faces.cornerCount());
  S.setFromTriplets(entries.begin(), entries.end());
  S.makeCompressed();
  return S;
}

std::vector<std::int32_t> toInt32(const std::vector<Index>& values) {
  return std::vector<std::int32_t>(values.begin(), values.end());
}

/// A space of dimension 0 (every vertex pinned) still gets one zero coefficient, and a
/// mesh without constraint rows one zero row: the device has no empty buffers.
compute::SparseMatrix nonEmpty(compute::SparseMatrix A) {
  if (A.rows() == 0 || A.cols() == 0) A.resize(std::max<Eigen::Index>(A.rows(), 1), std::max<Eigen::Index>(A.cols(), 1));
  if (A.nonZeros() == 0) A.coeffRef(0, 0) = 0.0;
  A.makeCompressed();
  return A;
}

const compute::ReducedArapProblem& checked(const compute::ReducedArapProblem& p) {
  const Eigen::Index n = 3 * p.source.rows();
  const Eigen::Index d = p.basis.cols();
  if (p.faces.size() == 0 || p.source.rows() == 0) throwUsage("subspace deformation: an empty mesh");
  if (p.basis.rows() != n || p.gain.rows() != d || p.gain.cols() != d || p.offset.size() != n ||
      p.constraints.cols() != n) {
    throwUsage("subspace deformation: the global step's matrices do not match the mesh's " +
               std::to_string(p.source.rows()) + " vertices");
  }
  return p;
}

}  // namespace

ReducedArapKernels::ReducedArapKernels(Context& context, const compute::ReducedArapProblem& problem)
    : context_(context),
      vertices_(elementCount(3 * checked(problem).source.rows(), "the coordinate count") / 3),
      faces_(elementCount(9 * problem.faces.size(), "the face covariances' entry count") / 9),
      asap_(problem.asap),
      algebra_(context),
      localStep_(context, "arap_local_step", 9, sizeof(LocalStepPush)),
      rotations_(context, "closest_rotations", 3, sizeof(RotationsPush)),
      faceOffsets_(context, problem.faces.offsets().size(), MemoryClass::Device, "face offsets"),
      faceIndices_(context, problem.faces.indices().size(), MemoryClass::Device, "face indices"),
      source_(context, 3 * vertices_, 1, "rest positions"),
      x_(context, 3 * vertices_, 1, "positions"),
      covariances_(context, 9 * faces_, 1, "face covariances"),
      rotationMatrices_(context, 9 * faces_, 1, "face rotations"),
      singular_(context, 3 * faces_, 1, "face singular values"),
      cornerTargets_(context, elementCount(3 * problem.faces.cornerCount(), "the corner coordinate count"), 1,
                     "corner targets"),
      faceEnergy_(context, faces_, 1, "face energies"),
      ones_(context, faces_, 1, "ones"),
      vertexTargets_(context, 3 * vertices_, 1, "vertex targets"),
      coefficients_(context, elementCount(std::max<Eigen::Index>(problem.basis.cols(), 1), "the dimension"), 1,
                    "subspace coefficients"),
      gained_(context, coefficients_.n(), 1, "constrained coefficients"),
      offset_(context, 3 * vertices_, 1, "global step offset"),
      Bx_(context, elementCount(std::max<Eigen::Index>(problem.constraints.rows(), 1), "the constraint row count"), 1,
          "constraint values"),
      gather_(context, cornerGather(problem.faces, vertices_)),
      basis_(context, nonEmpty(problem.basis)),
      basisTransposed_(context, nonEmpty(problem.basis.transpose())),
      gain_(context, nonEmpty(csr(problem.gain))),
      constraints_(context, nonEmpty(problem.constraints)),
      measures_(context, 3 * kBlock, 1, std::max({3 * vertices_, faces_, static_cast<std::uint32_t>(Bx_.n())})) {
  faceOffsets_.upload(toInt32(problem.faces.offsets()));
  faceIndices_.upload(toInt32(problem.faces.indices()));
  source_.upload(Eigen::Map<const Eigen::VectorXd>(problem.source.data(), problem.source.size()));
  offset_.upload(problem.offset);
  ones_.upload(Eigen::VectorXd::Ones(faces_));
  for (int i = 0; i < kBlock; ++i) before_.emplace_back(context, 3 * vertices_, 1, "positions before a global step");
  localSet_ = std::make_unique<DescriptorSet>(
      context, localStep_,
      std::initializer_list<BufferRange>{faceOffsets_, faceIndices_, x_.data(), source_.data(), covariances_.data(),
                                         rotationMatrices_.data(), singular_.data(), cornerTargets_.data(),
                                         faceEnergy_.data()});
  rotationSet_ = std::make_unique<DescriptorSet>(
      context, rotations_,
      std::initializer_list<BufferRange>{covariances_.data(), rotationMatrices_.data(), singular_.data()});
  blocks_.resize(kBlock + 1);
}

ReducedArapKernels::~ReducedArapKernels() = default;

void ReducedArapKernels::start(const Positions& X) {
  if (X.rows() != static_cast<Eigen::Index>(vertices_)) throwUsage("subspace deformation: the start has the wrong size");
  x_.upload(Eigen::Map<const Eigen::VectorXd>(X.data(), X.size()));
  lastCount_ = 0;
}

Sequence& ReducedArapKernels::block(int count) {
  auto& slot = blocks_[count];
  if (slot) return *slot;
  slot = std::make_unique<Sequence>(context_);
  Sequence& s = *slot;
  LinearAlgebra& la = algebra_;
  const std::uint32_t faceGroups = groupsFor(context_, faces_);
  s.begin();
  for (int j = 0; j < count; ++j) {
    const std::uint32_t slotBase = 3 * static_cast<std::uint32_t>(j);
    // Local step: covariances, rotations, targets and energies.
    s.dispatch(localStep_, *localSet_, LocalStepPush{faces_, 0, asap_ ? 1u : 0u}, faceGroups);
    s.barrier();
    s.dispatch(rotations_, *rotationSet_, RotationsPush{faces_}, faceGroups);
    s.barrier();
    s.dispatch(localStep_, *localSet_, LocalStepPush{faces_, 1, asap_ ? 1u : 0u}, faceGroups);
    s.barrier();
    la.dot(s, faceEnergy_, ones_, measures_, slotBase);
    la.copy(s, x_, before_[j]);
    // Global step: x = offset + N (G (N^T (S t))).
    la.spmv(s, gather_, cornerTargets_, vertexTargets_);
    la.spmv(s, basisTransposed_, vertexTargets_, coefficients_);
    la.spmv(s, gain_, coefficients_, gained_);
    la.spmv(s, basis_, gained_, x_);
    la.axpby(s, 1.0, offset_, 1.0, x_);
    la.spmv(s, constraints_, x_, Bx_);
    la.dot(s, Bx_, Bx_, measures_, slotBase + 1);
    la.dot(s, x_, x_, measures_, slotBase + 2);
  }
  s.end();
  return s;
}

std::vector<compute::ReducedArapMeasures> ReducedArapKernels::iterate(int count) {
  if (count < 1 || count > kBlock) throwUsage("subspace deformation: blocks of 1 to " + std::to_string(kBlock) + " iterations");
  block(count).run();
  lastCount_ = count;
  const std::vector<double> all = measures_.read();
  std::vector<compute::ReducedArapMeasures> measures(count);
  for (int j = 0; j < count; ++j) {
    measures[j].energy = measures_.at(all, 3 * j, 0);
    measures[j].constraintNorm = std::sqrt(measures_.at(all, 3 * j + 1, 0));
    measures[j].positionsNorm = std::sqrt(measures_.at(all, 3 * j + 2, 0));
  }
  return measures;
}

void ReducedArapKernels::positions(int index, Positions& X) {
  if (index < 0 || index > lastCount_) throwUsage("subspace deformation: no positions " + std::to_string(index) + " in the last block");
  Eigen::MatrixXd values;
  (index < lastCount_ ? before_[index] : x_).download(values);
  X.resize(vertices_, 3);
  Eigen::Map<Eigen::VectorXd>(X.data(), X.size()) = values.col(0);
}

}  // namespace plano::vk
