#version 450
// The reciprocal scale factors the fitted projective maps induce at the corners
// (projective/ShapeSpace::inducedReciprocalScales): corner c of face f gets (p, 1) . a4,
// p its source position and a4 the fourth column of f's map, which is the weight of the
// corner's image and the value 1 / s of its column in the scaled constraint matrix
// (projective-maps paper §4.2). With the tallies the global step checks, so that the host
// reads two numbers instead of a scale per corner: tally[0] counts the corners whose scale
// is not positive (or NaN), tally[1] = 0xffffffff - (the lowest corner whose |scale| is at
// most the limit, or NaN; such a corner's image lies at infinity), 0 when there is none.
// The host zeroes the tally before the dispatch. One invocation per face.
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"

layout(local_size_x = PLANO_GROUP_SIZE) in;

layout(std430, binding = 0) readonly buffer Source { double source[]; };  // #V x 3, row-major
layout(std430, binding = 1) readonly buffer Offsets { int offsets[]; };   // #F + 1
layout(std430, binding = 2) readonly buffer Indices { int indices[]; };   // face corners' vertices
layout(std430, binding = 3) readonly buffer Maps { double maps[]; };      // 16 per face, column-major
layout(std430, binding = 4) writeonly buffer Scales { double scales[]; }; // per corner
layout(std430, binding = 5) buffer Tally { uint tally[]; };               // 2

layout(push_constant) uniform Push {
  uint faceCount;
  uint unused;
  double vanishingScale;
} pc;

void main() {
  GRID_STRIDE_LOOP(f, pc.faceCount) {
    const uint column = 16u * f + 12u;
    const dvec4 a4 = dvec4(maps[column], maps[column + 1u], maps[column + 2u], maps[column + 3u]);
    for (int c = offsets[f]; c < offsets[f + 1]; ++c) {
      const int v = indices[c];
      precise double s = ((source[3 * v] * a4.x + source[3 * v + 1] * a4.y) + source[3 * v + 2] * a4.z) + a4.w;
      scales[c] = s;
      if (!(s > 0.0LF)) atomicAdd(tally[0], 1u);
      if (!(abs(s) > pc.vanishingScale)) atomicMax(tally[1], 0xffffffffu - uint(c));
    }
  }
}
