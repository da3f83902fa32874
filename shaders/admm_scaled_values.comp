#version 450
// C's values from its scales: value[e] = coefficient[e] / scale[scaleOf[e]] over C's
// stored entries (the projective global steps' C, each entry a base coordinate over a
// corner's reciprocal scale factor: compute::ConstraintScaling). One scale per corner
// crosses to the device per step instead of C's eight or so values per row.
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"

layout(local_size_x = PLANO_GROUP_SIZE) in;

layout(std430, binding = 0) readonly buffer Coefficients { double coefficients[]; };
layout(std430, binding = 1) readonly buffer ScaleOf { int scaleOf[]; };
layout(std430, binding = 2) readonly buffer Scales { double scales[]; };
layout(std430, binding = 3) writeonly buffer Values { double values[]; };

layout(push_constant) uniform Push {
  uint count;
} pc;

void main() {
  GRID_STRIDE_LOOP(e, pc.count) { values[e] = coefficients[e] / scales[scaleOf[e]]; }
}
