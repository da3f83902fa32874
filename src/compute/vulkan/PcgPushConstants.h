#pragma once
// Push constants of the PCG kernels (pcg_step, pcg_spmv_dot, pcg_direction), shared by
// the stand-alone SPD solver and the ADMM's inner solve. Layouts mirror the shaders' Push blocks.
#include <cstdint>

namespace plano::vk {

struct PcgStepPush {
  std::uint32_t n, m, slotRz, slotPq;
  std::uint32_t block;  ///< Preconditioner block size (1: Jacobi).
  std::uint32_t residualNorms = 0;  ///< 1: also r.r's partial sums (needs 2m columns of partials).
};
struct PcgSpmvDotPush {
  std::uint32_t n, m;
};
struct PcgDirectionPush {
  std::uint32_t n, m, slotNew, slotOld;
};

}  // namespace plano::vk
