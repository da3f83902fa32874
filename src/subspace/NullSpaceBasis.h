#pragma once
// An orthonormal basis of null(B) (linear-spaces paper, §4 "Implementation details": a
// sparse QR decomposition gives N; then every member of the space is N W).
#include <cstdint>

#include "subspace/ConstraintMatrix.h"
#include "subspace/SubspaceBasis.h"

namespace plano::subspace {

enum class BasisMethod {
  Auto,      ///< Dense SVD up to `denseLimit` unknowns, sparse QR above.
  DenseSvd,  ///< Jacobi SVD of the dense B: reliable rank decisions, O(n^3); small meshes only.
  SparseQr,  ///< SuiteSparseQR of B^T with column pivoting: rank-revealing in practice.
};

struct BasisSettings {
  BasisMethod method = BasisMethod::Auto;
  /// Rank tolerance: a singular value (SVD) or a pivot column norm (QR) of B below
  /// rankTolerance * (largest one) counts as zero. B has orthonormal rows per face, so
  /// its scale is 1 and this is also an absolute tolerance.
  double rankTolerance = 1e-9;
  /// Faces of real meshes are planar only up to their file's precision (single-precision
  /// OBJ: ~1e-7), which perturbs B by as much: the tolerance used is
  /// max(rankTolerance, noiseFactor * B.maxNonPlanarity). 0 disables the adaptation.
  double noiseFactor = 10.0;
  /// Unknowns (#V when separable, else 3 #V) up to which Auto uses the dense SVD.
  Index denseLimit = 400;
  /// Memory the dense basis may take while it is formed (bytes; 0: what the system has
  /// available). The basis is #unknowns x dim null(B) doubles, formed from a selector of
  /// the same size: on a large mesh it outgrows the machine (a 1M-quad grid's affine space,
  /// ~2 000 scalar columns, would need ~32 GiB), and is refused with OutOfMemory before
  /// anything that size is allocated: by buildLinearSpace before the sparse QR when the
  /// topological lower bound's columns cannot fit, else once the QR has given the dimension.
  std::uint64_t memoryLimitBytes = 0;
};

struct BasisInfo {
  BasisMethod method = BasisMethod::Auto;  ///< The method that ran.
  Index unknowns = 0;                      ///< Columns of the stored B.
  Index rank = 0;                          ///< Numerical rank of the stored B.
  double rankTolerance = 0.0;              ///< The relative tolerance used (after noise adaptation).
  Index dimension = 0;                     ///< dim null(B) of the full space.
  double residual = 0.0;                   ///< max |B N| entry: how exactly the basis lies in null(B).
  // N's orthogonality is not measured here: max |N^T N - I| costs #V d^2, minutes on a
  // space of ten thousand dimensions (SubspaceBasis::orthogonalityError, for tests).
};

/// Throws OutOfMemory when a dense basis of `unknowns` x `dimension` stored columns,
/// formed from a selector of its size, exceeds `limit` (0: the memory available).
/// `atLeast`: `dimension` is a lower bound (checked before the factorization that gives it).
void requireBasisMemory(Index unknowns, Index dimension, bool atLeast, std::uint64_t limit);

/// Orthonormal basis of null(B). Throws Error(Numerical) when the factorization fails.
SubspaceBasis computeNullSpaceBasis(const ConstraintMatrix& B, const BasisSettings& settings = {},
                                    BasisInfo* info = nullptr);

}  // namespace plano::subspace
