#version 450
// First pass of column-wise inf-norms of V = A + b B + c C (n x m each; `terms` of A, B,
// C are used): every workgroup writes the max |v| over its grid-stride share of one column
// to partial[column * groups + group]; la_reduce_max finishes. NaN is sticky, so that a
// non-finite iterate shows in its norm (GLSL's max() would drop it).
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"

layout(local_size_x = PLANO_GROUP_SIZE) in;

layout(std430, binding = 0) readonly buffer A { double a[]; };
layout(std430, binding = 1) readonly buffer B { double b[]; };
layout(std430, binding = 2) readonly buffer C { double c[]; };
layout(std430, binding = 3) writeonly buffer Partial { double partial[]; };

layout(push_constant) uniform Push {
  uint n;
  uint terms;  // 1, 2 or 3
  double cb;
  double cc;
} pc;

shared double maxima[PLANO_GROUP_SIZE];

double stickyMax(double m, double v) { return (v > m || isnan(v)) && !isnan(m) ? v : m; }

void main() {
  const uint column = gl_WorkGroupID.y;
  const uint base = column * pc.n;
  double m = 0.0;
  GRID_STRIDE_LOOP(i, pc.n) {
    precise double v = a[base + i];
    if (pc.terms > 1) v = v + pc.cb * b[base + i];
    if (pc.terms > 2) v = v + pc.cc * c[base + i];
    m = stickyMax(m, abs(v));
  }
  const uint lane = gl_LocalInvocationID.x;
  maxima[lane] = m;
  barrier();
  for (uint width = PLANO_GROUP_SIZE / 2; width > 0; width /= 2) {
    if (lane < width) maxima[lane] = stickyMax(maxima[lane], maxima[lane + width]);
    barrier();
  }
  if (lane == 0) partial[column * gl_NumWorkGroups.x + gl_WorkGroupID.x] = maxima[0];
}
