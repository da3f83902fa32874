#version 450
// Vertex positions of face maps (projective/ShapeSpace::normalizedPositions): each vertex
// the mean of its dehomogenized corner images over the faces that share it, an isolated
// vertex its base position; with each vertex's distance to its previous position (the
// loop's displacement). A corner image is (p, 1) A_f: its first three coordinates from the
// map's first three columns, its weight (p, 1) . a4 the corner's reciprocal scale
// (shaders/induced_scales.comp) when the maps are projective, 1 when they are affine
// (fourth columns (0, 0, 0, 1): pc.weighted = 0, the weights' binding unread).
// One invocation per vertex; the corner images are summed in the host's order.
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"

layout(local_size_x = PLANO_GROUP_SIZE) in;

layout(std430, binding = 0) readonly buffer Columns { double columns[]; };     // 4 #F x 3, column-major
layout(std430, binding = 1) readonly buffer Base { double base[]; };           // #V x 3, row-major
layout(std430, binding = 2) readonly buffer Offsets { int offsets[]; };        // #V + 1: corners of each vertex
layout(std430, binding = 3) readonly buffer Corners { int corners[]; };        // corner indices
layout(std430, binding = 4) readonly buffer CornerFace { int cornerFace[]; };  // per corner, its face
layout(std430, binding = 5) readonly buffer Previous { double previous[]; };   // #V x 3, row-major
layout(std430, binding = 6) writeonly buffer Positions { double positions[]; };  // #V x 3, row-major
layout(std430, binding = 7) writeonly buffer Distance { double distance[]; };    // #V
layout(std430, binding = 8) readonly buffer Weights { double weights[]; };       // per corner

layout(push_constant) uniform Push {
  uint vertexCount;
  uint rows;  // 4 #F: the columns' stride
  uint weighted;
} pc;

void main() {
  GRID_STRIDE_LOOP(v, pc.vertexCount) {
    const dvec4 p = dvec4(base[3 * v], base[3 * v + 1], base[3 * v + 2], 1.0LF);
    const int begin = offsets[v];
    const int end = offsets[v + 1];
    dvec3 result = p.xyz;
    if (end > begin) {
      precise dvec3 sum = dvec3(0.0LF);
      for (int k = begin; k < end; ++k) {
        const int corner = corners[k];
        const uint row = 4u * uint(cornerFace[corner]);
        precise dvec3 image;
        for (uint c = 0u; c < 3u; ++c) {
          const uint at = c * pc.rows + row;
          image[c] = (p.x * columns[at] + p.y * columns[at + 1u]) + (p.z * columns[at + 2u] + p.w * columns[at + 3u]);
        }
        if (pc.weighted != 0u) image /= weights[corner];
        sum += image;
      }
      precise dvec3 mean = sum / double(end - begin);
      result = mean;
    }
    positions[3 * v] = result.x;
    positions[3 * v + 1] = result.y;
    positions[3 * v + 2] = result.z;
    const dvec3 before = dvec3(previous[3 * v], previous[3 * v + 1], previous[3 * v + 2]);
    distance[v] = norm3(result - before);
  }
}
