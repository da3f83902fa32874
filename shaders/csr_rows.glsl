// Products of CSR rows with up to four columns at once (included after common.glsl by
// kernels that declare the CSR buffers rowOffsets, columns, values and the input, x[] or
// the array CSR_INPUT names).
// A matrix's values and column indices are read once for all of a block's columns, not
// once per column: on the global step's K (~28 entries of 12 bytes a row, against 8 bytes a
// row and column of the output) those reads are most of a product's memory traffic.

#ifndef CSR_INPUT
#define CSR_INPUT x
#endif

// Row `row` of A times columns first .. first + width - 1 of X (width 1..4, uniform), X
// stored column after column with `stride` entries per column; unused lanes are 0.
dvec4 csrRowTimesColumns(uint row, uint first, uint width, uint stride) {
  dvec4 sum = dvec4(0.0);
  const uint b0 = first * stride, b1 = b0 + stride, b2 = b1 + stride, b3 = b2 + stride;
  const int end = rowOffsets[row + 1];
  for (int e = rowOffsets[row]; e < end; ++e) {
    const double value = values[e];
    const uint column = uint(columns[e]);
    sum.x += value * CSR_INPUT[b0 + column];
    if (width > 1) sum.y += value * CSR_INPUT[b1 + column];
    if (width > 2) sum.z += value * CSR_INPUT[b2 + column];
    if (width > 3) sum.w += value * CSR_INPUT[b3 + column];
  }
  return sum;
}
