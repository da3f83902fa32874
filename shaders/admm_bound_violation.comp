#version 450
// V = max(l - Cx, Cx - u, 0) entry by entry, NaN where Cx is NaN (its inf-norm, la_max_abs,
// is then NaN: a non-finite polish is rejected).
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"

layout(local_size_x = PLANO_GROUP_SIZE) in;

layout(std430, binding = 0) readonly buffer Cx { double cx[]; };
layout(std430, binding = 1) readonly buffer L { double lower[]; };
layout(std430, binding = 2) readonly buffer U { double upper[]; };
layout(std430, binding = 3) writeonly buffer V { double violation[]; };

layout(push_constant) uniform Push {
  uint count;
} pc;

void main() {
  GRID_STRIDE_LOOP(e, pc.count) {
    const double v = cx[e];
    violation[e] = isnan(v) ? v : max(max(lower[e] - v, v - upper[e]), 0.0);
  }
}
