#pragma once
// As-similar/as-rigid-as-possible local/global iterations inside a linear space of meshes
// (linear-spaces paper, handle-based deformation), split like the ADMM (compute/Admm.h):
// the control logic (stopping test, bookkeeping) is the algorithm's, written once in
// subspace/SubspaceDeformation.cpp; the iterations themselves are a backend's kernels. The
// host kernels there run the Eigen loop; the Vulkan kernels keep the positions, the
// per-face rotations and the global step on the device and record several iterations per
// submit, so that only a few scalars per iteration come back.
//
// For a backend, the global step is an affine map of the local step's per-vertex targets
// g (vec, rows 3 v + c):  x = offset + N (G (N^T g)), with N the space's basis (3 #V x d,
// sparse where the space is separable) and G (d x d) the constrained solve. This holds
// every constraint and the space's structure, so the kernels need no knowledge of either,
// and it costs O(#V d + d^2) memory (a product N G N^T would be O(#V d) dense twice over).
#include <Eigen/Core>
#include <functional>
#include <memory>
#include <vector>

#include "compute/Backend.h"

namespace plano::compute {

struct ReducedArapProblem {
  FaceList faces;
  Positions source;            ///< The rest shape Y (#V x 3).
  bool asap = true;            ///< Per-face scale (similarity) or 1 (rigid).
  SparseMatrix basis;          ///< N, 3 #V x d.
  Eigen::MatrixXd gain;        ///< G, d x d.
  Eigen::VectorXd offset;      ///< 3 #V.
  SparseMatrix constraints;    ///< B (rows x 3 #V): every iterate's ||B x|| is measured.
};

/// What one iteration measured; all the control logic needs.
struct ReducedArapMeasures {
  double energy = 0.0;             ///< sum_f ||C X_f - s_f C Y_f R_f^T||^2 at the positions before the global step.
  double constraintNorm = 0.0;     ///< ||B x|| after the global step.
  double positionsNorm = 0.0;      ///< ||x|| after the global step (non-finite: the iteration broke down).
};

class ReducedArapKernels {
 public:
  virtual ~ReducedArapKernels() = default;
  /// Iterations per block the kernels run best (1 on the host; several on a device, where
  /// a block is one submit). The control may waste up to this many minus one iterations
  /// after the stopping test holds: their results are discarded.
  virtual int preferredBlock() const = 0;
  /// Load the positions (#V x 3) to iterate from.
  virtual void start(const Positions& X) = 0;
  /// Run `count` local/global iterations; one measure per iteration.
  virtual std::vector<ReducedArapMeasures> iterate(int count) = 0;
  /// The positions before global step `index` of the last block (0 <= index < count), or
  /// after its last one (index == count).
  virtual void positions(int index, Positions& X) = 0;
};

}  // namespace plano::compute
