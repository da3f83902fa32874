#version 450
// K1 = C^T D C on K's sparsity pattern from C's values, with no host data: entry e of K1
// is the sum over its terms t of C[a_t] D[row of a_t] C[b_t], where a_t and b_t are two
// entries of one row of C (the pairs are listed per entry of K once, when the solver is
// built; D = 1 on inequality rows, equalityRhoScale on equality rows).
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"

layout(local_size_x = PLANO_GROUP_SIZE) in;

layout(std430, binding = 0) readonly buffer TermOffsets { int termOffsets[]; };
layout(std430, binding = 1) readonly buffer TermA { int termA[]; };
layout(std430, binding = 2) readonly buffer TermB { int termB[]; };
layout(std430, binding = 3) readonly buffer CValues { double c[]; };
layout(std430, binding = 4) readonly buffer EntryRows { int entryRows[]; };
layout(std430, binding = 5) readonly buffer RowScales { double rowScales[]; };
layout(std430, binding = 6) writeonly buffer K1 { double k1[]; };

layout(push_constant) uniform Push {
  uint nonZeros;
} pc;

void main() {
  GRID_STRIDE_LOOP(e, pc.nonZeros) {
    precise double sum = 0.0;
    for (int t = termOffsets[e]; t < termOffsets[e + 1]; ++t) {
      const int a = termA[t];
      sum += c[a] * rowScales[entryRows[a]] * c[termB[t]];
    }
    k1[e] = sum;
  }
}
