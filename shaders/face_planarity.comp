#version 450
// Per-face planarity (percent) of a polygon mesh, the definition of src/mesh/Planarity.h:
// for a quad the distance between the diagonal lines over the mean diagonal length; for
// k > 4 corners the mean over the k runs of four consecutive corners; triangles are 0.
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"

layout(local_size_x = PLANO_GROUP_SIZE) in;

layout(std430, binding = 0) readonly buffer Positions { double positions[]; };  // #V x 3, row-major
layout(std430, binding = 1) readonly buffer Offsets { int offsets[]; };         // #F + 1 (CSR)
layout(std430, binding = 2) readonly buffer Indices { int indices[]; };         // corners
layout(std430, binding = 3) writeonly buffer Planarity { double planarity[]; }; // faceCount

layout(push_constant) uniform Push {
  uint firstFace;  // this dispatch handles faces firstFace .. firstFace + faceCount - 1
  uint faceCount;
} pc;

dvec3 vertex(int v) { return dvec3(positions[3 * v], positions[3 * v + 1], positions[3 * v + 2]); }

double quadPlanarity(dvec3 a, dvec3 b, dvec3 c, dvec3 d) {
  precise dvec3 d1 = c - a;
  precise dvec3 d2 = d - b;
  const double l1 = norm3(d1);
  const double l2 = norm3(d2);
  precise double meanDiagonal = 0.5 * (l1 + l2);
  if (!(meanDiagonal > 0.0)) return 0.0;
  const dvec3 n = cross3(d1, d2);
  const double nn = norm3(n);
  precise double distance;
  precise dvec3 ba = b - a;
  if (nn <= 1e-14 * l1 * l2) {
    // Parallel diagonals: the distance of b from the line ac.
    distance = l1 > 0.0 ? norm3(cross3(ba, d1)) / l1 : norm3(ba);
  } else {
    distance = abs(dot3(ba, n)) / nn;
  }
  precise double value = 100.0 * distance / meanDiagonal;
  return value;
}

void main() {
  GRID_STRIDE_LOOP(i, pc.faceCount) {
    const uint f = pc.firstFace + i;
    const int begin = offsets[f];
    const int k = offsets[f + 1] - begin;
    if (k < 4) {
      planarity[i] = 0.0;
      continue;
    }
    const int runs = k == 4 ? 1 : k;
    precise double sum = 0.0;
    for (int r = 0; r < runs; ++r) {
      sum += quadPlanarity(vertex(indices[begin + r]), vertex(indices[begin + (r + 1) % k]),
                           vertex(indices[begin + (r + 2) % k]), vertex(indices[begin + (r + 3) % k]));
    }
    planarity[i] = sum / double(runs);
  }
}
