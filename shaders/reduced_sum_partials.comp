#version 450
// R = the sum of the split-K chunks' partial copies of R (shaders/reduced_gemm.comp), added
// in chunk order so that a result never depends on scheduling.
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"

layout(local_size_x = PLANO_GROUP_SIZE) in;

layout(std430, binding = 0) readonly buffer Partials { double partials[]; };  // chunks x count
layout(std430, binding = 1) writeonly buffer Sum { double sum[]; };          // count

layout(push_constant) uniform Push {
  uint count;   // entries of R
  uint chunks;
} pc;

void main() {
  GRID_STRIDE_LOOP(e, pc.count) {
    precise double total = 0.0;
    for (uint c = 0; c < pc.chunks; ++c) total += partials[c * pc.count + e];
    sum[e] = total;
  }
}
