#version 450
// Y = blockdiag(M) X for m columns of n entries: M holds n / b dense b x b blocks
// (row-major, block j acting on rows j b .. j b + b - 1). b = 1 is a row scaling, the
// Jacobi preconditioner; larger b the block-Jacobi one.
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"

layout(local_size_x = PLANO_GROUP_SIZE) in;

layout(std430, binding = 0) readonly buffer Blocks { double blocks[]; };
layout(std430, binding = 1) readonly buffer X { double x[]; };
layout(std430, binding = 2) writeonly buffer Y { double y[]; };

layout(push_constant) uniform Push {
  uint n;
  uint m;
  uint b;
} pc;

#include "block_rows.glsl"

void main() {
  GRID_STRIDE_LOOP(i, pc.n * pc.m) {
    y[i] = blockRowTimes(i);
  }
}
