#version 450
// Y = diag(d) X for m columns of n entries (d has n entries): the Jacobi preconditioner.
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"

layout(local_size_x = PLANO_GROUP_SIZE) in;

layout(std430, binding = 0) readonly buffer D { double d[]; };
layout(std430, binding = 1) readonly buffer X { double x[]; };
layout(std430, binding = 2) writeonly buffer Y { double y[]; };

layout(push_constant) uniform Push {
  uint n;
  uint m;
} pc;

void main() {
  GRID_STRIDE_LOOP(i, pc.n * pc.m) { y[i] = d[i % pc.n] * x[i]; }
}
