#version 450
// A whole block of ADMM iterations (the work between two convergence checks) in as few
// dispatches as possible of ONE workgroup: right-hand side, the inner block-Jacobi PCG solve
// with its tolerance test, the x, z and y updates, all looped inside the kernel. The same
// iteration as the multi-dispatch path (admm_rhs, pcg_*, admm_update; see VulkanAdmm.h),
// for problems small enough that one workgroup sweeps them quickly: there, a dispatch
// costs more than the arithmetic it carries (lavapipe: ~10 us each, six per PCG
// iteration), and this kernel replaces thousands of them by a few.
//
// The kernel is resumable: it runs at most `budget` units of work (one unit: the start of
// a solve, one PCG iteration, or the final updates), then saves where it stopped in
// `state` and returns; the next dispatch goes on from there, and one whose block is done
// returns at once. A budget is needed because llvmpipe (lavapipe) silently ends every loop
// of an invocation once all its loops together took 65535 back-edges; the host sizes the
// budget below that (and for GPUs, to keep one dispatch short).
//
// The unknowns come in preconditioner blocks of b rows; every n-sized vector entry (row i,
// column c) is owned by invocation (i / b) % GROUP: it is the only one that writes it, so
// block-local updates need no synchronization. Only the
// vectors read across rows (p in K p, xTilde in C xTilde, z and y in C^T (rho z - y))
// need a buffer barrier after they are written. Dot products reduce in shared memory.
// Vectors are column-major (n x k or m x k).
//
// The preconditioner is either the blocks' dense b x b inverses (block-Jacobi) or, with
// `dense` set, K's whole dense n x n inverse (the automatic choice on the smallest K, where
// it makes every solve about one PCG iteration: vk::AdmmKernels::kMaxWholeInverseBlocks).
// Its product reads r across rows, which then needs a barrier between forming r and
// preconditioning it; the right-hand side of a solve's start is kept in kp for the same
// reason (kp is free until the solve's first K p).
#extension GL_GOOGLE_include_directive : require
#include "common.glsl"

// The workgroup size is chosen by the host (a multiple of MAX_COLUMNS): small on CPU
// devices, where every invocation pays for every barrier, large on GPUs.
layout(local_size_x_id = 0) in;
#define GROUP gl_WorkGroupSize.x
#define MAX_COLUMNS 4
#define PARTS (GROUP / MAX_COLUMNS)
#define MAX_BLOCK 4

layout(std430, binding = 0) readonly buffer KRows { int kRows[]; };
layout(std430, binding = 1) readonly buffer KColumns { int kColumns[]; };
layout(std430, binding = 2) readonly buffer KValues { double kValues[]; };
// n / b dense b x b inverse blocks of K (row-major): the block-Jacobi preconditioner; with
// `dense`, K's whole inverse (n x n, row-major).
layout(std430, binding = 3) readonly buffer InverseBlocks { double inverseBlocks[]; };
layout(std430, binding = 4) readonly buffer CRows { int cRows[]; };
layout(std430, binding = 5) readonly buffer CColumns { int cColumns[]; };
layout(std430, binding = 6) readonly buffer CValues { double cValues[]; };
layout(std430, binding = 7) readonly buffer CtRows { int ctRows[]; };
layout(std430, binding = 8) readonly buffer CtColumns { int ctColumns[]; };
layout(std430, binding = 9) readonly buffer CtValues { double ctValues[]; };
layout(std430, binding = 10) readonly buffer Q { double q[]; };
layout(std430, binding = 11) buffer X { double x[]; };
layout(std430, binding = 12) coherent buffer XTilde { double xTilde[]; };
layout(std430, binding = 13) coherent buffer R { double r[]; };
layout(std430, binding = 14) buffer Zp { double zp[]; };  // preconditioned residual
layout(std430, binding = 15) coherent buffer P { double p[]; };
layout(std430, binding = 16) coherent buffer Kp { double kp[]; };
layout(std430, binding = 17) readonly buffer Lower { double lower[]; };
layout(std430, binding = 18) readonly buffer Upper { double upper[]; };
layout(std430, binding = 19) coherent buffer Y { double y[]; };
layout(std430, binding = 20) writeonly buffer YPrevious { double yPrevious[]; };
layout(std430, binding = 21) coherent buffer Z { double z[]; };
layout(std430, binding = 22) readonly buffer Rho { double rho[]; };
// [1] inner iterations run, [2] solves stopped by the cap, [3] the squared tolerance on
// ||r|| set by the host (as pcg_control's state), then the resumable position: ADMM
// iterations left in the block, phase (0: next unit starts a solve, 1: inside the PCG),
// PCG iterations of the current solve, r.z, b.z and r.r per column.
layout(std430, binding = 23) buffer State { double state[]; };
#define STATE_INNER 1
#define STATE_CAPPED 2
#define STATE_TOLERANCE2 3
#define STATE_REMAINING 4
#define STATE_PHASE 5
#define STATE_SOLVE_ITERATIONS 6
#define STATE_RZ 7
#define STATE_BZ (STATE_RZ + MAX_COLUMNS)
#define STATE_RR (STATE_BZ + MAX_COLUMNS)

layout(push_constant) uniform Push {
  uint n;
  uint m;
  uint k;           // columns, at most MAX_COLUMNS
  uint iterations;  // ADMM iterations of the block; the last saves y to yPrevious
  uint cap;         // PCG iterations per solve
  uint budget;      // units of work of this dispatch
  uint begin;       // 1: this dispatch starts the block (else it resumes from state)
  uint b;           // preconditioner block size: divides n, at most MAX_BLOCK
  uint dense;       // 1: inverseBlocks is K's whole inverse (above)
  uint unused;
  double sigma;
  double alpha;       // over-relaxation
  double tolerance2;  // relative: PCG stops when r.z <= tolerance2 * b.z (and ||r|| is small)
} pc;

shared double sums[2 * MAX_COLUMNS][GROUP];
shared double parts[2 * MAX_COLUMNS][PARTS];

// Sum every column's per-invocation values of `count` (1 or 2) quantities over the
// workgroup; all invocations get the totals. Two levels (PARTS partial sums, then every
// invocation adds those) cost two barriers instead of a tree's log2(GROUP). The next
// reduce may start at once: its writes to sums follow this one's last barrier, and its
// writes to parts its own first.
void reduce(uint count, inout double first[MAX_COLUMNS], inout double second[MAX_COLUMNS]) {
  const uint lane = gl_LocalInvocationID.x;
  for (uint c = 0; c < pc.k; ++c) {
    sums[c][lane] = first[c];
    if (count == 2) sums[MAX_COLUMNS + c][lane] = second[c];
  }
  barrier();
  const uint chunk = GROUP / PARTS;
  for (uint slot = lane; slot < PARTS * MAX_COLUMNS * count; slot += GROUP) {
    const uint row = slot / PARTS;  // quantity * MAX_COLUMNS + column
    if (row % MAX_COLUMNS >= pc.k) continue;
    const uint begin = (slot % PARTS) * chunk;
    double sum = 0.0;
    for (uint t = 0; t < chunk; ++t) sum += sums[row][begin + t];
    parts[row][slot % PARTS] = sum;
  }
  barrier();
  for (uint c = 0; c < pc.k; ++c) {
    double sum = 0.0, other = 0.0;
    for (uint t = 0; t < PARTS; ++t) sum += parts[c][t];
    if (count == 2) {
      for (uint t = 0; t < PARTS; ++t) other += parts[MAX_COLUMNS + c][t];
      second[c] = other;
    }
    first[c] = sum;
  }
}

// Make this invocation's buffer writes visible to the others, and wait for all.
void synchronize() {
  memoryBarrierBuffer();
  barrier();
}

// Row i of K's whole inverse times column c of v (r or, at a solve's start, the
// right-hand side kept in kp): every invocation's writes of v must be visible. Four
// entries per loop pass: a row is n entries, and on lavapipe every pass counts against an
// invocation's loop limit (above; vk::AdmmKernels::singleWorkgroupBudget).
double wholeInverseRow(uint i, uint c, bool ofRightHandSide) {
  const uint n = pc.n, row = i * n, column = c * n;
  double sum = 0.0;
  uint u = 0;
  if (ofRightHandSide) {
    for (; u + 4 <= n; u += 4) {
      sum += inverseBlocks[row + u] * kp[column + u] + inverseBlocks[row + u + 1] * kp[column + u + 1] +
             inverseBlocks[row + u + 2] * kp[column + u + 2] + inverseBlocks[row + u + 3] * kp[column + u + 3];
    }
    for (; u < n; ++u) sum += inverseBlocks[row + u] * kp[column + u];
  } else {
    for (; u + 4 <= n; u += 4) {
      sum += inverseBlocks[row + u] * r[column + u] + inverseBlocks[row + u + 1] * r[column + u + 1] +
             inverseBlocks[row + u + 2] * r[column + u + 2] + inverseBlocks[row + u + 3] * r[column + u + 3];
    }
    for (; u < n; ++u) sum += inverseBlocks[row + u] * r[column + u];
  }
  return sum;
}

void main() {
  const uint lane = gl_LocalInvocationID.x;
  const uint n = pc.n;
  const uint m = pc.m;
  const uint blocks = n / pc.b;
  const bool dense = pc.dense != 0;
  uint remaining = pc.begin != 0 ? pc.iterations : uint(state[STATE_REMAINING]);
  uint phase = pc.begin != 0 ? 0 : uint(state[STATE_PHASE]);
  uint j = uint(state[STATE_SOLVE_ITERATIONS]);
  // The inner solve stops when, in every column, r.z <= tolerance2 b.z and ||r||^2 <=
  // absolute2, an absolute bound that the host derives from the ADMM's own residuals
  // (compute/Admm.h): with stiff equality rows b is far larger than the residuals.
  const double absolute2 = state[STATE_TOLERANCE2];
  double rz[MAX_COLUMNS], bz[MAX_COLUMNS], rr[MAX_COLUMNS];
  for (uint c = 0; c < MAX_COLUMNS; ++c) {
    rz[c] = state[STATE_RZ + c];
    bz[c] = state[STATE_BZ + c];
    rr[c] = state[STATE_RR + c];
  }
  barrier();  // every invocation has read the state before lane 0 may rewrite it
  uint innerIterations = 0;
  uint cappedSolves = 0;
  uint budget = pc.budget;
  while (remaining > 0 && budget > 0) {
    --budget;
    if (phase == 0) {
      // rhs = sigma x - q + C^T (rho z - y); PCG start from xTilde: r = rhs - K xTilde,
      // zp = M^-1 r, p = zp, and the dot products r.zp, rhs.M^-1 rhs and r.r.
      for (uint c = 0; c < MAX_COLUMNS; ++c) {
        rz[c] = 0.0;
        bz[c] = 0.0;
        rr[c] = 0.0;
      }
      for (uint block = lane; block < blocks; block += GROUP) {
        for (uint c = 0; c < pc.k; ++c) {
          double rhsBlock[MAX_BLOCK], residual[MAX_BLOCK];
          for (uint t = 0; t < pc.b; ++t) {
            const uint i = block * pc.b + t;
            double ctw = 0.0;
            for (int e = ctRows[i]; e < ctRows[i + 1]; ++e) {
              const uint row = uint(ctColumns[e]);
              precise double w = rho[row] * z[c * m + row] - y[c * m + row];
              ctw += ctValues[e] * w;
            }
            precise double rhs = (pc.sigma * x[c * n + i] - q[c * n + i]) + ctw;
            double product = 0.0;
            for (int e = kRows[i]; e < kRows[i + 1]; ++e) product += kValues[e] * xTilde[c * n + uint(kColumns[e])];
            rhsBlock[t] = rhs;
            residual[t] = rhs - product;
            r[c * n + i] = residual[t];
            if (dense) kp[c * n + i] = rhs;
          }
          if (dense) continue;  // preconditioned below, once r is whole
          for (uint t = 0; t < pc.b; ++t) {
            const uint i = block * pc.b + t;
            double zi = 0.0, mb = 0.0;
            for (uint u = 0; u < pc.b; ++u) {
              const double entry = inverseBlocks[(block * pc.b + t) * pc.b + u];
              zi += entry * residual[u];
              mb += entry * rhsBlock[u];
            }
            zp[c * n + i] = zi;
            p[c * n + i] = zi;
            rz[c] += residual[t] * zi;
            bz[c] += rhsBlock[t] * mb;
            rr[c] += residual[t] * residual[t];
          }
        }
      }
      if (dense) {
        synchronize();  // r and the right-hand side
        for (uint block = lane; block < blocks; block += GROUP) {
          for (uint i = block * pc.b; i < (block + 1) * pc.b; ++i) {
            for (uint c = 0; c < pc.k; ++c) {
              const double zi = wholeInverseRow(i, c, false);
              const double residual = r[c * n + i];
              zp[c * n + i] = zi;
              p[c * n + i] = zi;
              rz[c] += residual * zi;
              bz[c] += kp[c * n + i] * wholeInverseRow(i, c, true);
              rr[c] += residual * residual;
            }
          }
        }
      }
      reduce(2, rz, bz);
      double unused[MAX_COLUMNS];
      reduce(1, rr, unused);
      synchronize();  // p
      phase = 1;
      j = 0;
      continue;
    }

    bool running = false;
    for (uint c = 0; c < pc.k; ++c) {
      // NaN keeps running into the iterate.
      if (!(rz[c] <= pc.tolerance2 * bz[c]) || !(rr[c] <= absolute2)) running = true;
    }
    if (running && j < pc.cap) {
      ++j;
      ++innerIterations;
      // Kp = K p and p.Kp
      double pq[MAX_COLUMNS];
      for (uint c = 0; c < MAX_COLUMNS; ++c) pq[c] = 0.0;
      for (uint i = lane * pc.b; i < n; i += GROUP * pc.b) {
        for (uint t = i; t < i + pc.b; ++t) {
          for (uint c = 0; c < pc.k; ++c) {
            double product = 0.0;
            for (int e = kRows[t]; e < kRows[t + 1]; ++e) product += kValues[e] * p[c * n + uint(kColumns[e])];
            kp[c * n + t] = product;
            pq[c] += p[c * n + t] * product;
          }
        }
      }
      double unused[MAX_COLUMNS];
      reduce(1, pq, unused);
      // xTilde += a p, r -= a Kp, zp = M^-1 r, and the new r.zp. A converged column
      // (r = 0) gives p.Kp = 0: it stands still instead of dividing by zero.
      double rzNext[MAX_COLUMNS];
      for (uint c = 0; c < MAX_COLUMNS; ++c) {
        rzNext[c] = 0.0;
        rr[c] = 0.0;
      }
      for (uint block = lane; block < blocks; block += GROUP) {
        for (uint c = 0; c < pc.k; ++c) {
          const double a = pq[c] != 0.0 ? rz[c] / pq[c] : 0.0;
          double rhsBlock[MAX_BLOCK], residual[MAX_BLOCK];
          for (uint t = 0; t < pc.b; ++t) {
            const uint i = block * pc.b + t;
            xTilde[c * n + i] += a * p[c * n + i];
            residual[t] = r[c * n + i] - a * kp[c * n + i];
            r[c * n + i] = residual[t];
          }
          if (dense) continue;  // preconditioned below, once r is whole
          for (uint t = 0; t < pc.b; ++t) {
            double zi = 0.0;
            for (uint u = 0; u < pc.b; ++u) zi += inverseBlocks[(block * pc.b + t) * pc.b + u] * residual[u];
            zp[c * n + block * pc.b + t] = zi;
            rzNext[c] += residual[t] * zi;
            rr[c] += residual[t] * residual[t];
          }
        }
      }
      if (dense) {
        synchronize();  // r
        for (uint block = lane; block < blocks; block += GROUP) {
          for (uint i = block * pc.b; i < (block + 1) * pc.b; ++i) {
            for (uint c = 0; c < pc.k; ++c) {
              const double zi = wholeInverseRow(i, c, false);
              const double residual = r[c * n + i];
              zp[c * n + i] = zi;
              rzNext[c] += residual * zi;
              rr[c] += residual * residual;
            }
          }
        }
      }
      reduce(2, rzNext, rr);
      // Every invocation has read p across rows (K p) before the reduces' barriers, so p
      // can be overwritten now.
      for (uint i = lane * pc.b; i < n; i += GROUP * pc.b) {
        for (uint t = i; t < i + pc.b; ++t) {
          for (uint c = 0; c < pc.k; ++c) {
            const double beta = rz[c] != 0.0 ? rzNext[c] / rz[c] : 0.0;
            p[c * n + t] = zp[c * n + t] + beta * p[c * n + t];
          }
        }
      }
      for (uint c = 0; c < pc.k; ++c) rz[c] = rzNext[c];
      synchronize();  // p
      continue;
    }
    if (running) ++cappedSolves;
    synchronize();  // xTilde

    // zTilde = C xTilde (row by row, not stored), then z and y (OSQP Algorithm 1 steps
    // 4-6, rho per row) and x = alpha xTilde + (1 - alpha) x.
    const bool saveDual = remaining == 1;
    for (uint row = lane; row < m; row += GROUP) {
      for (uint c = 0; c < pc.k; ++c) {
        double zTilde = 0.0;
        for (int e = cRows[row]; e < cRows[row + 1]; ++e) zTilde += cValues[e] * xTilde[c * n + uint(cColumns[e])];
        const uint index = c * m + row;
        const double rhoRow = rho[row];
        const double yi = y[index];
        precise double zRelaxed = pc.alpha * zTilde + (1.0 - pc.alpha) * z[index];
        precise double shifted = zRelaxed + (1.0 / rhoRow) * yi;
        const double zNext = min(max(shifted, lower[index]), upper[index]);
        precise double yNext = yi + rhoRow * (zRelaxed - zNext);
        if (saveDual) yPrevious[index] = yi;
        y[index] = yNext;
        z[index] = zNext;
      }
    }
    for (uint i = lane * pc.b; i < n; i += GROUP * pc.b) {
      for (uint t = i; t < i + pc.b; ++t) {
        for (uint c = 0; c < pc.k; ++c) {
          precise double xi = pc.alpha * xTilde[c * n + t] + (1.0 - pc.alpha) * x[c * n + t];
          x[c * n + t] = xi;
        }
      }
    }
    synchronize();  // z and y
    --remaining;
    phase = 0;
  }
  if (lane == 0) {
    state[STATE_INNER] += double(innerIterations);
    state[STATE_CAPPED] += double(cappedSolves);
    state[STATE_REMAINING] = double(remaining);
    state[STATE_PHASE] = double(phase);
    state[STATE_SOLVE_ITERATIONS] = double(j);
    for (uint c = 0; c < MAX_COLUMNS; ++c) {
      state[STATE_RZ + c] = rz[c];
      state[STATE_BZ + c] = bz[c];
      state[STATE_RR + c] = rr[c];
    }
  }
}
