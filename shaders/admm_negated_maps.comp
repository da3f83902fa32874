#version 450
// The projective global step's linear term q = -T from its target maps where a kernel left
// them on the device (vk::ResidentFaceMaps): q(4 f + r, c) = -M_f(r, c) for the first
// `columns` columns of each map. Maps are 16 doubles a face, column-major; q is n x columns,
// column-major, n = 4 #F. Negation is exact: q equals the host's -T bit for bit.
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"

layout(local_size_x = PLANO_GROUP_SIZE) in;

layout(std430, binding = 0) readonly buffer Maps { double maps[]; };
layout(std430, binding = 1) writeonly buffer Q { double q[]; };

layout(push_constant) uniform Push {
  uint faceCount;
  uint columns;
} pc;

void main() {
  const uint n = 4u * pc.faceCount;
  GRID_STRIDE_LOOP(i, n * pc.columns) {
    const uint c = i / n;
    const uint row = i - c * n;
    q[i] = -maps[16u * (row / 4u) + 4u * c + row % 4u];
  }
}
