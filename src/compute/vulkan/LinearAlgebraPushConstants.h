#pragma once
// Push constants of the linear-algebra kernels that more than one recording dispatches
// (vk::LinearAlgebra, the device ADMM, the multigrid V-cycle). Layouts mirror the shaders'
// Push blocks.
#include <cstdint>

namespace plano::vk {

struct SpmvPush {  // la_spmv, la_residual
  std::uint32_t rows, cols, m;
};
struct DotPush {  // la_dot
  std::uint32_t n;
};
struct ReducePush {  // la_reduce
  std::uint32_t groups, m, slot;
};
struct AxpbyPush {  // la_axpby
  std::uint32_t count, pad;
  double a, b;
};
struct ScalePush {  // la_scale_rows
  std::uint32_t n, m, b;
};
struct AssemblePush {  // admm_assemble: K = K0 + rho K1 and the first `rows` row penalties
  std::uint32_t nonZeros, rows;
  double rho;
};

}  // namespace plano::vk
