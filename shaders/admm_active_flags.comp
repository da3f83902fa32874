#version 450
// The polish's active flags of one column from the active sides (admm_active_sides'
// packing, entry c m + i): row i is held (K1's row scale 1) unless its side is free, so
// that a refinement with the sides found on the device uploads no per-row flags.
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"

layout(local_size_x = PLANO_GROUP_SIZE) in;

layout(std430, binding = 0) readonly buffer Sides { uint sides[]; };
layout(std430, binding = 1) writeonly buffer RowScales { double rowScales[]; };  // m

layout(push_constant) uniform Push {
  uint m;
  uint column;
} pc;

void main() {
  GRID_STRIDE_LOOP(i, pc.m) {
    const uint e = pc.column * pc.m + i;
    const uint side = (sides[e / 16u] >> (2u * (e % 16u))) & 3u;
    rowScales[i] = side != 0u ? 1.0 : 0.0;
  }
}
