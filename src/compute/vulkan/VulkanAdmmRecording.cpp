// The device ADMM's recorded iterations (AdmmKernels, VulkanAdmm.h): the start, the
// right-hand side, the inner PCG sized by pcg_control, and the blocks between two checks in
// either recording (multi-dispatch or one workgroup).
#include <algorithm>

#include "compute/vulkan/LinearAlgebraPushConstants.h"
#include "compute/vulkan/PcgPushConstants.h"
#include "compute/vulkan/VulkanAdmm.h"
#include "compute/vulkan/VulkanAdmmWorkspace.h"
#include "core/Cancellation.h"
#include "core/Error.h"

namespace plano::vk {

using namespace admm;

void AdmmKernels::recordStart(Sequence& s, StartX xStart, bool zeroY, bool relaxedBounds) {
  Workspace& w = *workspace_;
  LinearAlgebra& la = algebra_;
  const auto bytes = [](const DeviceVectors& v) { return std::size_t{v.n()} * v.m() * sizeof(double); };
  // x = -q as 0 - q: nothing of x's last contents (possibly non-finite) enters.
  if (xStart != StartX::Uploaded) s.zero(w.x.data(), bytes(w.x));
  if (zeroY) s.zero(w.y.data(), bytes(w.y));
  if (xStart != StartX::Uploaded || zeroY) s.barrier();
  if (xStart == StartX::NegatedQ) la.axpby(s, -1.0, w.q, 1.0, w.x);
  if (relaxedBounds) {
    const std::uint32_t count = m_ * w.k;
    s.dispatch(relaxedBounds_, {w.centre.data(), w.relaxed, w.state, w.lower.data(), w.upper.data()},
               RelaxedBoundsPush{std::max<std::uint32_t>(m_, 1), count, kStateEpsilon}, groupsFor(context_, count));
    s.barrier();
  }
  la.spmv(s, devC_, w.x, w.zTilde);
  la.clamp(s, w.zTilde, w.lower, w.upper, w.z);
  la.copy(s, w.x, w.xTilde);
  la.copy(s, w.y, w.yPrevious);
}

void AdmmKernels::recordRightHandSide(Sequence& s) {
  Workspace& w = *workspace_;
  const std::uint32_t mk = m_ * w.k;
  const std::uint32_t nk = n_ * w.k;
  // rhs = sigma x - q + C^T (rho z - y)
  s.dispatch(rhs_, {w.z.data(), w.y.data(), rhoRows_, w.w.data()}, RhsPush{m_, mk, 0, 0, settings_.sigma},
             groupsFor(context_, mk));
  s.barrier();
  algebra_.spmv(s, devCt_, w.w, w.Ctw);
  s.dispatch(rhs_, {w.x.data(), w.q.data(), w.Ctw.data(), w.rhs.data()}, RhsPush{n_, nk, 1, 0, settings_.sigma},
             groupsFor(context_, nk));
  s.barrier();
}

void AdmmKernels::recordPcgStart(Sequence& s, SolveTarget target) {
  Workspace& w = *workspace_;
  LinearAlgebra& la = algebra_;
  // PCG start from xTilde: r = rhs - K xTilde, preconditioned = M^-1 r, p = it, r.z, r.r, b.z.
  la.spmv(s, devK_, w.xTilde, w.Kp);
  la.copy(s, w.rhs, w.r);
  la.axpby(s, -1.0, w.Kp, 1.0, w.r);
  if (multigrid_) {
    multigrid_->record(s, *w.cycleResidual, nullptr, 0);
  } else {
    la.applyBlockDiagonal(s, inverseBlocks_, block_, w.r, w.preconditioned);
  }
  la.copy(s, w.preconditioned, w.p);
  la.dot(s, w.r, w.preconditioned, w.pcg, kPcgRzEven);
  la.dot(s, w.r, w.r, w.pcg, kPcgRrEven);
  if (target == SolveTarget::WarmStart) la.dot(s, w.r, w.preconditioned, w.pcg, kPcgBz);
  if (multigrid_) {  // Kp as scratch for M^-1 b
    multigrid_->record(s, *w.cycleRhs, nullptr, 0);
  } else {
    la.applyBlockDiagonal(s, inverseBlocks_, block_, w.rhs, w.Kp);
  }
  la.dot(s, w.rhs, w.Kp, w.pcg, target == SolveTarget::RightHandSide ? kPcgBz : kPcgRhsBz);
}

void AdmmKernels::recordInnerSolve(Sequence& s, int innerIterations, SolveTarget target, double tolerance, bool firstOdd,
                                   bool countLargest, BlockPosition position) {
  Workspace& w = *workspace_;
  const std::uint32_t k = w.k;
  const std::uint32_t nk = n_ * k;

  // A continuation's first iterate is the one the last run's capped solve reached: in the
  // slot that run's parity (its recorded count, `firstOdd`) left its r.z in.
  const bool continuation = target == SolveTarget::Continuation;
  const int parity = continuation && firstOdd ? 1 : 0;
  if (!continuation) recordPcgStart(s, target);

  const std::uint32_t groups = w.pcg.groups();
  // The direction update's and the V-cycle's sweeps (vk::Multigrid::record).
  const std::uint32_t directionGroups = sweepGroupsFor(context_, nk);
  const double tolerance2 = tolerance * tolerance;
  // The polish's solves (tol ||r0||) stop at the rounding floor of ||b|| too.
  const std::uint32_t floorSlot = target == SolveTarget::RightHandSide ? kNoFloor : kPcgRhsBz;
  const double floor2 = kPolishRoundingFloor * kPolishRoundingFloor;
  auto control = [&](std::uint32_t mode, std::uint32_t slotRz) {
    const bool first = mode == 0 && position.first;
    const bool abandon = mode == 0 && position.abandonAfterCap;
    s.dispatch(control_, *w.controlSet,
               ControlPush{k, slotRz, kPcgBz, mode, groups, directionGroups, floorSlot, countLargest ? 1u : 0u,
                           tolerance2, floor2, first ? 1u : 0u, abandon ? 1u : 0u},
               1);
    s.barrier();
  };
  control(continuation ? 1 : 0, parity == 0 ? kPcgRzEven : kPcgRzOdd);
  for (int j = 0; j < innerIterations; ++j) {
    // The iteration of vk::PcgSolver; r.z alternates between two slots.
    const std::uint32_t current = (j + parity) % 2 == 0 ? kPcgRzEven : kPcgRzOdd;
    const std::uint32_t next = (j + parity) % 2 == 0 ? kPcgRzOdd : kPcgRzEven;
    s.dispatchIndirect(spmvDot_, *w.spmvDotSet, PcgSpmvDotPush{n_, k}, w.arguments, kProductArguments);
    s.barrier();
    s.dispatchIndirect(reduce_, *w.reduceSet, ReducePush{groups, k, kPcgPq}, w.arguments, kReduceArguments);
    s.barrier();
    s.dispatchIndirect(step_, *w.stepSet, PcgStepPush{n_, k, current, kPcgPq, block_, 1}, w.arguments,
                       kFusedArguments);
    s.barrier();
    if (multigrid_) {
      // The step's z = blockdiag^-1 r and its r.z are replaced: z = M r, then r.z's partial
      // sums (r.r's, from the step, stay), all sized by the control's triples.
      multigrid_->record(s, *w.cycleResidual, &w.arguments, kDirectionArguments);
      s.dispatchIndirect(dot_, *w.rzSet, DotPush{n_}, w.arguments, kFusedArguments);
      s.barrier();
    }
    s.dispatchIndirect(reduce_, *w.reduceSet, ReducePush{groups, k, next}, w.arguments, kPairReduceArguments);
    s.barrier();
    s.dispatchIndirect(direction_, *w.directionSet, PcgDirectionPush{n_, k, next, current}, w.arguments,
                       kDirectionArguments);
    s.barrier();
    control(j + 1 == innerIterations ? 2 : 1, next);
  }
}

void AdmmKernels::recordIteration(Sequence& s, bool saveDual, int innerIterations, bool countLargest,
                                  BlockPosition position) {
  Workspace& w = *workspace_;
  LinearAlgebra& la = algebra_;
  const std::uint32_t mk = m_ * w.k;

  recordRightHandSide(s);
  recordInnerSolve(s, innerIterations, SolveTarget::RightHandSide, settings_.linearSolver.relativeTolerance, false,
                   countLargest, position);

  // zTilde = C xTilde, x = alpha xTilde + (1 - alpha) x, then the z and y updates.
  const double alpha = relaxation_;
  la.spmv(s, devC_, w.xTilde, w.zTilde);
  la.axpby(s, alpha, w.xTilde, 1.0 - alpha, w.x);
  s.dispatch(update_,
             {w.zTilde.data(), w.z.data(), w.y.data(), w.yPrevious.data(), w.lower.data(), w.upper.data(), rhoRows_},
             UpdatePush{m_, mk, saveDual ? 1u : 0u, 0, alpha}, groupsFor(context_, mk));
  s.barrier();
}

void AdmmKernels::recordSingleWorkgroup(Sequence& s, int count, int dispatches, bool begin) {
  Workspace& w = *workspace_;
  const double tolerance = settings_.linearSolver.relativeTolerance;
  const auto cap = static_cast<std::uint32_t>(withinSolverLimit(kMaxInnerIterations));
  const DescriptorSet& set = *w.singleWorkgroupSet;
  for (int d = 0; d < dispatches; ++d) {
    const SingleWorkgroupPush push{n_,
                                   m_,
                                   w.k,
                                   static_cast<std::uint32_t>(count),
                                   cap,
                                   w.budget,
                                   begin && d == 0 ? 1u : 0u,
                                   block_,
                                   multigrid_ ? 1u : 0u,
                                   0u,
                                   settings_.sigma,
                                   relaxation_,
                                   tolerance * tolerance};
    s.dispatch(singleWorkgroup_, set, push, 1);
    s.barrier();
  }
}

void AdmmKernels::iterateSingleWorkgroup(int count) {
  Workspace& w = *workspace_;
  // Dispatches for the expected work (each solve: a start, its PCG iterations, the
  // updates), rounded up to a power of two so that few recordings are kept. A dispatch
  // after the block is done returns at once; a block that needs more resumes below.
  const double units = count * (w.expectedInnerIterations + 2.0);
  int dispatches = 1;
  while (dispatches < 4096 && dispatches * static_cast<double>(w.budget) < units) dispatches *= 2;
  recordedOnce(w.blocks[{relaxation_, count * 8192 + dispatches}], context_, [&](Sequence& s) {
    recordSingleWorkgroup(s, count, dispatches, true);
  }).run();
  // One read-back per run: the position tells whether the block is done.
  double state[kStateSize];
  w.state.download(state);
  while (state[kRemaining] > 0.0) {
    throwIfCancelled("the ADMM iteration");
    recordedOnce(w.resumes[{relaxation_, dispatches}], context_, [&](Sequence& s) {
      recordSingleWorkgroup(s, count, dispatches, false);
    }).run();
    w.state.download(state);
  }
  w.expectedInnerIterations = std::max(1.0, (state[kInnerIterations] - w.innerIterationsSeen) / count);
  w.innerIterationsSeen = state[kInnerIterations];
}

Sequence& AdmmKernels::block(int count, bool longFirstSolve) {
  Workspace& w = *workspace_;
  auto& slot = w.blocks[{relaxation_, 2 * count + (longFirstSolve ? 1 : 0)}];
  return recordedOnce(slot, context_, [&](Sequence& s) {
    const int largest = withinSolverLimit(kMaxInnerIterations);
    // A capped solve makes measure() run this block again, from the iteration of that solve,
    // when its cap is below the largest (and the multi-dispatch recording's); the solves
    // after it are then skipped, and the iterations after it no longer save their start.
    const bool abandonAfterCap = !w.singleWorkgroup && innerIterations_ < largest;
    const std::uint32_t nk = n_ * w.k, mk = m_ * w.k;
    // Every solve counts into kLargestSolve but a long first one, whose poor warm start says
    // nothing about the ones that follow.
    for (int i = 0; i < count; ++i) {
      if (i == 0 || abandonAfterCap) {
        s.dispatch(saveIterate_,
                   {w.state, w.x.data(), w.xTilde.data(), w.y.data(), w.z.data(), w.xSaved.data(),
                    w.xTildeSaved.data(), w.ySaved.data(), w.zSaved.data()},
                   SaveIteratePush{nk, mk, static_cast<std::uint32_t>(i), i == 0 ? 1u : 0u},
                   groupsFor(context_, std::max(nk, mk)));
        s.barrier();
      }
      const bool longSolve = i == 0 && longFirstSolve;
      recordIteration(s, i == count - 1, longSolve ? largest : innerIterations_, !longSolve,
                      BlockPosition{i == 0, i > 0 && abandonAfterCap});
    }
  });
}


}  // namespace plano::vk
