#version 450
// Fused PCG product: Q = A P for m columns and, in the same pass, the first-pass partial
// sums of p.q per workgroup and column (finished by la_reduce), saving a re-read of P and
// Q. Each invocation takes a row for every column, reading A's row once per four columns
// (csr_rows.glsl): A's values and indices are most of the pass's traffic.
// Dispatch: the dot products' fixed workgroup count in x, one row of workgroups.
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"

layout(local_size_x = PLANO_GROUP_SIZE) in;

layout(std430, binding = 0) readonly buffer RowOffsets { int rowOffsets[]; };
layout(std430, binding = 1) readonly buffer Columns { int columns[]; };
layout(std430, binding = 2) readonly buffer Values { double values[]; };
layout(std430, binding = 3) readonly buffer P { double p[]; };
layout(std430, binding = 4) writeonly buffer Q { double q[]; };
layout(std430, binding = 5) writeonly buffer Partial { double partial[]; };

#define CSR_INPUT p
#include "csr_rows.glsl"

layout(push_constant) uniform Push {
  uint n;
  uint m;
} pc;

shared dvec4 sums[PLANO_GROUP_SIZE];

void main() {
  const uint lane = gl_LocalInvocationID.x;
  for (uint first = 0; first < pc.m; first += 4) {
    const uint width = min(4u, pc.m - first);
    dvec4 pq = dvec4(0.0);
    GRID_STRIDE_LOOP(r, pc.n) {
      const dvec4 product = csrRowTimesColumns(r, first, width, pc.n);
      for (uint j = 0; j < width; ++j) {
        const uint at = (first + j) * pc.n + r;
        q[at] = product[j];
        pq[j] += p[at] * product[j];
      }
    }
    sums[lane] = pq;
    barrier();
    for (uint half_ = PLANO_GROUP_SIZE / 2; half_ > 0; half_ /= 2) {
      if (lane < half_) sums[lane] += sums[lane + half_];
      barrier();
    }
    if (lane == 0) {
      for (uint j = 0; j < width; ++j) partial[(first + j) * gl_NumWorkGroups.x + gl_WorkGroupID.x] = sums[0][j];
    }
    barrier();  // sums is rewritten by the next four columns
  }
}
