#pragma once
// The aggregation V-cycle of compute/BlockMultigrid.h on the device, as the preconditioner
// of the ADMM's inner PCG with K = K0 + rho K1.
//
// The levels' aggregates are fixed when the solver is built; the coarse matrices are
// Galerkin products, and since coarsening is linear, K_l = K0_l + rho K1_l with K0_l
// coarsened once on the host and K1_l on the device whenever K1 changes: with piecewise
// constant prolongation every fine entry adds into one coarse entry, so a level's values
// are a fixed gather of the finer level's (DeviceGather, built once from the patterns).
// A rho update is then device work only: K_l on every level
// (admm_assemble) and the block-Jacobi inverses of every level but the coarsest
// (block_jacobi_inverse), and the coarsest level's dense inverse (at most
// kMaxCoarsestRows rows): assembled dense from its two small matrices (mg_coarsest_assemble)
// and inverted in place by the sweep operator (symmetric Gauss-Jordan), one dispatch per
// elimination step over several workgroups (mg_coarsest_invert). Before, the host
// inverted it and uploaded the inverse at each rho update (200 kB on a 256-face
// deformation, up to 8 MiB), after downloading the coarsest K1 at each new C.
//
// One cycle: on each level, z = S r (block-Jacobi), then r_coarse = Z^T (r - K z) in one
// kernel; the coarsest z = K^-1 r; back up, z += Z z_coarse, t = r - K z, z += S t: five
// dispatches per level but the coarsest (nine before the fused kernels: each product, each
// subtraction and each smoothing update its own, with a pass over memory between them).
// The smoothed cycle (constructor's smoothProlongation) restricts with P^T and prolongs
// with P, six dispatches per level (z = S r, t = r - K z, r_c = P^T t; z += P z_c,
// t = r - K z, z += S t), its smoother damped (vk::SmoothedTransfer).
// Every dispatch is sized by
// one caller-given indirect triple (x workgroups, 1, 1), so that inside a recorded PCG the
// cycles of a converged solve cost empty dispatches; all kernels loop grid-stride, so any
// x count is correct.
#include <memory>
#include <vector>

#include "compute/BlockMultigrid.h"
#include "compute/vulkan/VulkanLinearAlgebra.h"
#include "compute/vulkan/VulkanSmoothedTransfer.h"

namespace plano::vk {

class Multigrid {
 public:
  /// The levels of `aggregation` for K0 (level 0 on the caller's pattern `pattern`, which
  /// must also hold K1's entries). `algebra` (the caller's, kept by reference) inverts the
  /// coarse levels' blocks. With `smoothProlongation`, the smoothed-aggregation cycle
  /// (BlockMultigridSettings::smoothProlongation; vk::SmoothedTransfer): its coarse levels
  /// come from level 0's K at each setRho, K0 and K1 are not coarsened.
  Multigrid(Context& context, LinearAlgebra& algebra, const compute::BlockAggregation& aggregation,
            const compute::SparseMatrix& K0, const compute::SparseMatrix& pattern, bool smoothProlongation = false);
  ~Multigrid();
  Multigrid(const Multigrid&) = delete;
  Multigrid& operator=(const Multigrid&) = delete;

  /// Largest coarsest level (rows) inverted on the device: vk::AdmmKernels::kMaxCoarsestBlocks
  /// blocks of at most 4 rows (shaders/mg_coarsest_invert.comp's shared memory).
  static constexpr std::uint32_t kMaxCoarsestRows = 1024;
  /// What setRho leaves in `failure` when the coarsest level is not positive definite.
  static constexpr std::uint32_t kCoarsestFailure = 0xFFFFFFFEu;

  /// Record the coarse levels' K1 from level 0's K1 values (on the caller's `pattern`,
  /// already on the device); setRho's recordings need the sequence to have run.
  void setK1(Sequence& sequence, const Array<double>& k1);
  /// The same from a host matrix on level 0's pattern (uploads it and runs; tests and
  /// callers without K1 on the device).
  void setK1(const compute::SparseMatrix& K1);
  /// Record K_l = K0_l + rho K1_l on the coarse levels, the block inverses of levels
  /// 1 .. L-2 (level 0's are the caller's) and the coarsest level's dense inverse into
  /// `sequence`. A coarse block that is not positive definite leaves its index in `failure`
  /// (set to ~0 by the caller), a coarsest level that is not, kCoarsestFailure.
  void setRho(Sequence& sequence, double rho, Array<std::uint32_t>& failure);
  /// The same given level 0's K (on the caller's pattern, for this rho) and its undamped
  /// block-Jacobi inverses, recorded earlier into `sequence`: the smoothed cycle forms its
  /// coarse levels from them (the plain one ignores them).
  void setRho(Sequence& sequence, double rho, const DeviceCsrMatrix& K, const Array<double>& inverses,
              Array<std::uint32_t>& failure);

  /// The cycle's level-0 operands: input r, output z, K and its block inverses. Descriptor
  /// sets are built once per binding; a recording refers to it. The levels' vectors are
  /// sized for r's columns: a binding for another count voids the earlier bindings.
  class Binding {
   public:
    ~Binding();
    Binding(const Binding&) = delete;
    Binding& operator=(const Binding&) = delete;

   private:
    friend class Multigrid;
    Binding();
    struct Sets;
    std::unique_ptr<Sets> sets_;
  };
  std::unique_ptr<Binding> bind(const DeviceCsrMatrix& K, const Array<double>& inverseBlocks, const DeviceVectors& r,
                                DeviceVectors& z);
  /// Record one cycle z = M r of `binding`, each dispatch indirect from `arguments` (the
  /// triple at byte offset `triple`), or direct when `arguments` is null.
  void record(Sequence& sequence, const Binding& binding, const Buffer* arguments, std::size_t triple);

  int levelCount() const { return static_cast<int>(levels_.size()); }
  /// With one level, the cycle is K's dense inverse (row-major, rows x rows, formed by
  /// setRho): the array that holds it, for kernels that apply it themselves. Null with
  /// coarse levels.
  const Array<double>* wholeInverse() const;

 private:
  struct Level;
  /// The coarsest level's dense inverse from its K0 + rho K1 (its K, rho 0, when smoothed).
  void recordCoarsestInverse(Sequence& sequence, double rho, Array<std::uint32_t>& failure);

  Context& context_;
  LinearAlgebra& algebra_;
  std::uint32_t block_;
  std::uint32_t columns_;
  compute::BlockAggregation aggregation_;
  std::vector<compute::SparseMatrix> patterns_;  ///< Level patterns (values 0), levels 1 ..
  std::vector<std::unique_ptr<Level>> levels_;   ///< Levels 0 .. L-1 (level 0 holds only temporaries).
  std::vector<std::unique_ptr<DeviceGather>> coarsenings_;  ///< Level l's values -> level l + 1's.
  std::unique_ptr<DeviceCsrMatrix> coarsestK0_;            ///< The coarsest level's K0, on its pattern.
  std::unique_ptr<Array<double>> coarsestK1Values_;        ///< On the coarsest level's pattern.
  bool k1Set_ = false;
  bool smoothed_ = false;
  std::vector<std::unique_ptr<SmoothedTransfer>> transfers_;  ///< Smoothed: level l -> l + 1.
  Pipeline spmvAdd_, spmv_, scale_, residual_, scaleAdd_, restrictResidual_, prolong_, assemble_, coarsestAssemble_,
      coarsestInvert_;
  std::unique_ptr<Array<double>> sweepSaved_;  ///< The inversion's two saved pivot columns.
  Array<double> noRows_;  ///< admm_assemble's row buffers, unused on coarse levels.
};

}  // namespace plano::vk
