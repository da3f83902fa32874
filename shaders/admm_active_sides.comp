#version 450
// The polish's active sets at the ADMM's iterate (compute::AdmmKernels::findActiveSides,
// OSQP's rule): entry e of the m x k arrays is held at its lower bound (1) where l = u or
// z - l < -y, else at its upper bound (2) where u - z < y, else free (0); two bits per
// entry, sixteen entries per word (entry e in bits 2 (e % 16) of word e / 16), so that a
// sixteenth of a vector of doubles comes back.
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"

layout(local_size_x = PLANO_GROUP_SIZE) in;

layout(std430, binding = 0) readonly buffer Z { double z[]; };
layout(std430, binding = 1) readonly buffer Y { double y[]; };
layout(std430, binding = 2) readonly buffer L { double lower[]; };
layout(std430, binding = 3) readonly buffer U { double upper[]; };
layout(std430, binding = 4) writeonly buffer Sides { uint sides[]; };

layout(push_constant) uniform Push {
  uint count;  // m k entries
} pc;

void main() {
  const uint words = (pc.count + 15u) / 16u;
  GRID_STRIDE_LOOP(w, words) {
    uint packed = 0u;
    for (uint b = 0u; b < 16u; ++b) {
      const uint e = 16u * w + b;
      if (e >= pc.count) break;
      const double l = lower[e], u = upper[e];
      uint side = 0u;
      if (l == u || z[e] - l < -y[e]) {
        side = 1u;
      } else if (u - z[e] < y[e]) {
        side = 2u;
      }
      packed |= side << (2u * b);
    }
    sides[w] = packed;
  }
}
