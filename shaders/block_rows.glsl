// Entry i of blockdiag(M) X for m columns of n entries stored column after column, M's
// n / b dense b x b blocks row-major, block j acting on rows j b .. j b + b - 1 (included
// after common.glsl by kernels that declare blocks[], x[] and push constants n, b).
double blockRowTimes(uint i) {
  const uint row = i % pc.n;
  const uint first = row - row % pc.b;  // first row of the block, in this column
  const uint base = i - (row - first);
  const uint entries = (row / pc.b) * pc.b * pc.b + (row - first) * pc.b;
  double sum = 0.0;
  for (uint t = 0; t < pc.b; ++t) sum += blocks[entries + t] * x[base + t];
  return sum;
}
