// The projective shape space per backend: the batched local step, one global step
// (factorization + ADMM + polish) and one deformation iteration (local step, closest
// rigid maps, global step) on generated planar-quad grids of ~4k and ~64k faces (the
// global step also on ~1k, where the device ADMM runs in one workgroup on lavapipe).
#include <benchmark/benchmark.h>

#include <Eigen/Geometry>
#include <Eigen/IterativeLinearSolvers>
#include <chrono>
#include <cmath>
#include <random>

#include "MemoryCounters.h"
#include "VulkanBenchSupport.h"
#include "compute/Admm.h"
#include "compute/Backend.h"
#include "compute/BlockMultigrid.h"
#include "compute/vulkan/VulkanMultigrid.h"
#include "core/Error.h"
#include "mesh/Generators.h"
#include "projective/Deformation.h"
#include "projective/GlobalStep.h"
#include "projective/IdealMaps.h"
#include "projective/LocalStep.h"
#include "projective/ScaledConstraintMatrix.h"

namespace {

using plano::Index;
using plano::compute::BackendChoice;

/// A projective image of the grid: every face has a nontrivial exact fit.
plano::Positions perspectiveTarget(const plano::projective::ShapeSpace& space) {
  Eigen::Matrix4d H;
  H << 0.9, 0.2, -0.1, 0.08, -0.15, 1.1, 0.05, -0.06, 0.1, -0.05, 0.95, 0.1, 0.3, -0.2, 0.4, 1.0;
  plano::Positions q(space.vertexCount(), 3);
  for (Index v = 0; v < space.vertexCount(); ++v) {
    const Eigen::RowVector4d h = plano::projective::homogeneous(space.basePositions().row(v)) * H;
    q.row(v) = h.head<3>() / h[3];
  }
  return space.normalization().toWorld(q);
}

/// The local steps' problem: the benchmark's grid, its shape space and a projective image.
struct LocalStepProblem {
  explicit LocalStepProblem(benchmark::State& state)
      : mesh(plano::bench::quadMesh(state.range(0))), space(mesh), target(perspectiveTarget(space)) {}
  plano::PolygonMesh mesh;
  plano::projective::ShapeSpace space;
  plano::Positions target;
};

void BM_LocalStep(benchmark::State& state, BackendChoice choice) {
  plano::compute::Backend* backend = plano::bench::backendOrSkip(state, choice);
  if (!backend) return;
  plano::bench::MemoryCounters memory(state, backend);
  const LocalStepProblem p(state);
  memory.markLoopStart();
  for (auto _ : state) {
    auto result = plano::projective::fitFaceMaps(*backend, p.space, p.target);
    benchmark::DoNotOptimize(result.fits.maps.data());
  }
  plano::bench::setFaceCounters(state, p.mesh);
}

/// How the rigid local step of a deformation runs: one fused backend call, whose fits stay
/// where the backend computed them, or the fit and the ideal maps as two calls.
enum class RigidLocalStep { Fused, TwoCalls };

void BM_RigidLocalStep(benchmark::State& state, BackendChoice choice, RigidLocalStep how) {
  plano::compute::Backend* backend = plano::bench::backendOrSkip(state, choice);
  if (!backend) return;
  plano::bench::MemoryCounters memory(state, backend);
  const LocalStepProblem p(state);
  const plano::Positions normalized = p.space.normalization().toNormalized(p.target);
  memory.markLoopStart();
  for (auto _ : state) {
    std::vector<Eigen::Matrix4d> ideal;
    if (how == RigidLocalStep::Fused) {
      ideal = plano::projective::fittedIdealMaps(*backend, p.space, p.target, plano::projective::IdealMapKind::Rigid);
    } else {
      const auto fit = plano::projective::fitFaceMaps(*backend, p.space, p.target);
      ideal = plano::projective::closestIdealMaps(*backend, p.space, fit.fits.maps,
                                                  plano::projective::IdealMapKind::Rigid, &normalized);
    }
    benchmark::DoNotOptimize(ideal.data());
  }
  plano::bench::setFaceCounters(state, p.mesh);
}

/// A global step's inner-solve iterations split by what they served, from its ADMM's
/// convergence checks (AdmmSettings::onCheck): those of every ADMM solve, and of the last
/// solve's iterations at its final rho (after its last rho change: on an iterative backend
/// the stiffest, dearest solves). The step's other inner iterations are its polish's or its
/// direct equality solve's.
class InnerSolveSplit {
 public:
  void observe(const plano::compute::AdmmCheck& check) {
    // A new solve (the next eps attempt): every solve's first check comes at its
    // checkInterval-th iteration, and the counts only grow within a solve.
    if (check.iterations <= iterations_) {
      admm_ += solveLinear_;
      solveLinear_ = 0;
      iterations_ = 0;
    }
    // A check reports the rho of the iterations before it; a change happens after it.
    if (iterations_ == 0 || check.rho != finalRho_) {
      linearBeforeFinalRho_ = solveLinear_;
      finalRho_ = check.rho;
    }
    solveLinear_ = check.linearIterations;
    iterations_ = check.iterations;
  }
  long admm() const { return admm_ + solveLinear_; }
  long atFinalRho() const { return solveLinear_ - linearBeforeFinalRho_; }
  double finalRho() const { return finalRho_; }

 private:
  long admm_ = 0;
  long solveLinear_ = 0;
  long linearBeforeFinalRho_ = 0;
  int iterations_ = 0;
  double finalRho_ = 0.0;
};

/// Rigid targets that disagree (a rotation on every other face) with the row v = 0 fixed:
/// a global step that needs real ADMM work.
/// `equalitySolve` Admm: the exact step by the ADMM and its polish (until 2026-12-07 the
/// device's way from zero multipliers) instead of the polish alone.
void BM_GlobalStep(benchmark::State& state, BackendChoice choice,
                   plano::compute::AdmmPreconditioner preconditioner = plano::compute::AdmmPreconditioner::Automatic,
                   plano::projective::EqualitySolve equalitySolve = plano::projective::EqualitySolve::Automatic) {
  plano::compute::Backend* backend = plano::bench::backendOrSkip(state, choice);
  if (!backend) return;
  plano::bench::MemoryCounters memory(state, backend);
  const plano::PolygonMesh mesh = plano::bench::quadMesh(state.range(0));
  const plano::projective::ShapeSpace space(mesh);
  const auto side = static_cast<Index>(std::lround(std::sqrt(static_cast<double>(mesh.faceCount()))));
  std::vector<Index> fixed;
  for (Index i = 0; i <= side; ++i) fixed.push_back(i * (side + 1));
  plano::Positions at(fixed.size(), 3);
  for (std::size_t i = 0; i < fixed.size(); ++i) at.row(i) = mesh.vertices.row(fixed[i]);
  std::vector<Eigen::Matrix4d> targets(space.faceCount(), Eigen::Matrix4d::Identity());
  const Eigen::Matrix3d R = Eigen::AngleAxisd(0.2, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  for (Index f = 0; f < space.faceCount(); f += 2) targets[f].topLeftCorner<3, 3>() = R;
  plano::projective::GlobalStepSettings settings;
  settings.epsilonStart = plano::projective::EpsilonStart::ExactFirst;
  settings.qp.preconditioner = preconditioner;
  settings.qp.equalitySolve = equalitySolve;
  // Every repetition solves the identical step: warm-started from the last one's solution
  // (BoxQpSettings::warmStartEqualities, the global step's default) the device's exact
  // step would start solved and take no ADMM iteration.
  settings.qp.warmStartEqualities = false;
  InnerSolveSplit split;
  settings.qp.onCheck = [&split](const plano::compute::AdmmCheck& check) { split.observe(check); };
  plano::projective::GlobalStepInfo info;
  try {
    plano::projective::GlobalStep global(*backend, space, fixed, settings);
    plano::projective::FaceMaps result;
    memory.markLoopStart();
    for (auto _ : state) {
      split = InnerSolveSplit();
      info = global.solve(targets, at, result);
      benchmark::DoNotOptimize(result.maps.data());
    }
  } catch (const plano::Error& e) {  // e.g. a buffer past lavapipe's 128 MiB binding range
    state.SkipWithError(e.what());
    return;
  }
  plano::bench::setFaceCounters(state, mesh);
  state.counters["admm_iterations"] = info.admmIterations;
  state.counters["factorizations"] = info.factorizations;
  state.counters["linear_iterations"] = static_cast<double>(info.linearIterations);
  // Where the inner iterations went (InnerSolveSplit): the ADMM's, those of its last solve
  // at its final rho (admm_final_rho, of the inequality rows; equality rows take 1e3 times
  // it), and the polish's (or the direct equality solve's).
  state.counters["admm_linear_iterations"] = static_cast<double>(split.admm());
  state.counters["final_rho_linear_iterations"] = static_cast<double>(split.atFinalRho());
  state.counters["admm_final_rho"] = split.finalRho();
  state.counters["polish_linear_iterations"] = static_cast<double>(info.linearIterations - split.admm());
}

/// Which iterations of a deformation BM_DeformationIteration times.
enum class DeformationTiming {
  /// Each from the base mesh, the first timed one with the solvers' set-up (at the large
  /// sizes the only one that runs); zero multipliers as in Steady.
  First,
  /// Each from the base mesh again, after one untimed iteration, so that the timed ones
  /// find their solvers made (matrices uploaded, the factorization's analysis done), with
  /// the solver state (rho) the last one left; their exact steps start from zero
  /// multipliers (from the last one's, the identical problem's, they would start solved).
  Steady,
  /// Iterations 2 .. 9 of one deformation (fixed count): each continues from the mesh the
  /// last one left, as a drag's next frames, its exact step started from the last one's
  /// multipliers (GlobalStepSettings::qp, BoxQpSettings::warmStartEqualities).
  Continued,
};

/// One as-rigid-as-possible iteration: fixed row, corner handle lifted.
void BM_DeformationIteration(benchmark::State& state, BackendChoice choice, DeformationTiming timing) {
  plano::compute::Backend* backend = plano::bench::backendOrSkip(state, choice);
  if (!backend) return;
  plano::bench::MemoryCounters memory(state, backend);
  const plano::PolygonMesh mesh = plano::bench::quadMesh(state.range(0));
  const auto side = static_cast<Index>(std::lround(std::sqrt(static_cast<double>(mesh.faceCount()))));
  plano::PositionalConstraints constraints;
  for (Index i = 0; i <= side; ++i) constraints.fixed.push_back(i * (side + 1));
  const Index corner = mesh.vertexCount() - 1;
  constraints.handles.push_back({corner, mesh.vertices.row(corner).transpose() + Eigen::Vector3d(0.1, 0.1, 0.3)});
  plano::projective::DeformationSettings settings;
  settings.maxIterations = 1;
  settings.maxProjectionIterations = 0;
  settings.global.qp.warmStartEqualities = timing == DeformationTiming::Continued;
  plano::Positions handles(1, 3);
  handles.row(0) = constraints.handles[0].position.transpose();
  int admm = 0;
  long linear = 0;
  try {
    plano::projective::Deformation deformation(*backend, mesh, constraints, settings);
    plano::Positions positions = mesh.vertices;
    if (timing != DeformationTiming::First) deformation.solve(handles, positions);
    memory.markLoopStart();
    for (auto _ : state) {
      if (timing != DeformationTiming::Continued) positions = mesh.vertices;
      const auto info = deformation.solve(handles, positions);
      admm = info.history.empty() ? 0 : info.history.back().admmIterations;
      linear = info.history.empty() ? 0 : info.history.back().linearIterations;
      benchmark::DoNotOptimize(positions.data());
    }
  } catch (const plano::Error& e) {  // e.g. a buffer past lavapipe's 128 MiB binding range
    state.SkipWithError(e.what());
    return;
  }
  plano::bench::setFaceCounters(state, mesh);
  // The last timed iteration's: ADMM iterations (0 where the exact step is solved directly)
  // and the iterations of their solves with K (PCG iterations on a device).
  state.counters["admm_iterations"] = admm;
  state.counters["linear_iterations"] = static_cast<double>(linear);
}

/// Reciprocal scale factors in [0.8, 1.2], one per corner.
std::vector<double> randomScales(const plano::projective::ShapeSpace& space, unsigned seed) {
  std::mt19937 random(seed);
  std::uniform_real_distribution<double> scale(0.8, 1.2);
  std::vector<double> shat(space.cornerCount());
  for (double& value : shat) value = scale(random);
  return shat;
}

/// The global step's constraint matrix on a grid (one row per pair of a vertex's first and
/// another corner, as GlobalStep builds it) with reciprocal scale factors drawn in
/// [0.8, 1.2]: the values one local step gives.
plano::compute::SparseMatrix compatibilityMatrix(const plano::projective::ShapeSpace& space, unsigned seed) {
  const std::vector<double> shat = randomScales(space, seed);
  std::vector<Eigen::Triplet<double>> entries;
  Eigen::Index row = 0;
  const auto& offsets = space.vertexCornerOffsets();
  const auto& corners = space.cornersOfVertex();
  for (Index v = 0; v < space.vertexCount(); ++v) {
    const Eigen::RowVector4d p = plano::projective::homogeneous(space.basePositions().row(v));
    for (Index k = offsets[v] + 1; k < offsets[v + 1]; ++k, ++row) {
      const Index a = corners[offsets[v]], b = corners[k];
      for (int j = 0; j < 4; ++j) {
        entries.emplace_back(row, 4 * space.cornerFace(a) + j, p[j] / shat[a]);
        entries.emplace_back(row, 4 * space.cornerFace(b) + j, -p[j] / shat[b]);
      }
    }
  }
  plano::compute::SparseMatrix C(row, 4 * space.faceCount());
  C.setFromTriplets(entries.begin(), entries.end());
  return C;
}

/// One aggregation V-cycle (compute/BlockMultigrid.h, the global step's preconditioner
/// above 64 faces; plain, or smoothed: BlockMultigridSettings::smoothProlongation) for three
/// right-hand sides on the exact step's matrix
/// K = I + sigma I + rho C^T C of a grid (every row an equality row; rho = 1e3, between the
/// 0.1 x 1e3 the ADMM's equality rows start at and the few 1e3 they reach): the host reference, one column after the other, or
/// the device's recorded cycle (vk::Multigrid) with K's levels and block inverses in place.
/// The device cycle's cost is its dispatches (lavapipe) or its memory traffic (a GPU).
/// The exact step's K = K0 + rho K1 of a grid, K0 = (1 + sigma) I and K1 = C^T C on one
/// pattern, at rho = 1e3.
struct ExactStepMatrices {
  static constexpr double rho = 1e3;
  plano::compute::SparseMatrix K0, K1, K;
  explicit ExactStepMatrices(const plano::projective::ShapeSpace& space) {
    const plano::compute::SparseMatrix C = compatibilityMatrix(space, 1);
    const double sigma = plano::compute::AdmmSettings{}.sigma;
    K1 = C.transpose() * C;
    plano::compute::SparseMatrix identity(K1.rows(), K1.cols());
    identity.setIdentity();
    K0 = identity * (1.0 + sigma) + K1 * 0.0;
    K0.makeCompressed();
    K1 = K1 + K0 * 0.0;  // on K0's pattern
    K1.makeCompressed();
    K = K0 + K1 * rho;
    K.makeCompressed();
  }
};

void BM_MultigridCycle(benchmark::State& state, BackendChoice choice, bool smoothed) {
  plano::compute::Backend* backend = plano::bench::backendOrSkip(state, choice);
  if (!backend) return;
  plano::bench::MemoryCounters memory(state, backend);
  const plano::PolygonMesh mesh = plano::bench::quadMesh(state.range(0));
  const plano::projective::ShapeSpace space(mesh);
  const ExactStepMatrices matrices(space);
  const plano::compute::SparseMatrix &K0 = matrices.K0, &K1 = matrices.K1, &K = matrices.K;
  const double rho = ExactStepMatrices::rho;
  const plano::compute::BlockAggregation aggregation(K, {4});
  const Eigen::MatrixXd r = plano::bench::jittered(Eigen::MatrixXd::Zero(K.rows(), 3), 1.0);
  plano::compute::BlockMultigridSettings settings{4};
  settings.smoothProlongation = smoothed;
  if (choice == BackendChoice::Cpu) {
    const plano::compute::BlockMultigrid cycle(aggregation, K, settings);
    memory.markLoopStart();
    for (auto _ : state) {
      for (Eigen::Index j = 0; j < r.cols(); ++j) benchmark::DoNotOptimize(cycle.apply(r.col(j)).data());
    }
  } else {
    try {
      plano::vk::Context& context = static_cast<plano::compute::VulkanBackend*>(backend)->context();
      plano::vk::LinearAlgebra algebra(context);
      plano::vk::Multigrid multigrid(context, algebra, aggregation, K0, K0, smoothed);
      multigrid.setK1(K1);
      plano::vk::DeviceCsrMatrix deviceK(context, K);
      plano::vk::Array<double> inverses(context, static_cast<std::size_t>(K.rows()) * 4,
                                        plano::vk::MemoryClass::Device, "block inverses");
      plano::vk::Array<std::uint32_t> failure(context, 1, plano::vk::MemoryClass::Host, "failure");
      const std::uint32_t none = ~0u;
      failure.upload({&none, 1});
      plano::vk::DeviceVectors input(context, static_cast<std::uint32_t>(r.rows()), 3, "r");
      plano::vk::DeviceVectors output(context, input.n(), 3, "z");
      input.upload(r);
      plano::vk::Sequence setup(context);
      setup.begin();
      algebra.invertDiagonalBlocks(setup, deviceK, 4, inverses, failure);
      multigrid.setRho(setup, rho, deviceK, inverses, failure);
      setup.end();
      setup.run();
      const auto binding = multigrid.bind(deviceK, inverses, input, output);
      plano::vk::Sequence cycle(context);
      cycle.begin();
      multigrid.record(cycle, *binding, nullptr, 0);
      cycle.end();
      plano::bench::timeSequence(state, cycle, [&] { memory.markLoopStart(); });
    } catch (const plano::Error& e) {  // e.g. larger than lavapipe's 2 GiB heap
      state.SkipWithError(e.what());
      return;
    }
  }
  plano::bench::setFaceCounters(state, mesh);
  state.counters["levels"] = aggregation.levelCount();
  state.counters["rows"] = static_cast<double>(K.rows());
  state.counters["nonzeros"] = static_cast<double>(K.nonZeros());
}

/// One rho update of the device cycle (vk::Multigrid::setRho) on the exact step's K of a
/// grid: the plain cycle assembles K0_l + rho K1_l and inverts blocks; the smoothed one
/// forms every level's P and P^T K P from K (vk::SmoothedTransfer), the price of its fewer
/// PCG iterations, paid at each rho update and each new K1.
void BM_MultigridUpdate(benchmark::State& state, bool smoothed) {
  plano::compute::Backend* backend = plano::bench::backendOrSkip(state, BackendChoice::Vulkan);
  if (!backend) return;
  plano::bench::MemoryCounters memory(state, backend);
  const plano::PolygonMesh mesh = plano::bench::quadMesh(state.range(0));
  const plano::projective::ShapeSpace space(mesh);
  const ExactStepMatrices matrices(space);
  const plano::compute::BlockAggregation aggregation(matrices.K, {4});
  try {
    plano::vk::Context& context = static_cast<plano::compute::VulkanBackend*>(backend)->context();
    plano::vk::LinearAlgebra algebra(context);
    plano::vk::Multigrid multigrid(context, algebra, aggregation, matrices.K0, matrices.K0, smoothed);
    multigrid.setK1(matrices.K1);
    plano::vk::DeviceCsrMatrix deviceK(context, matrices.K);
    plano::vk::Array<double> inverses(context, static_cast<std::size_t>(matrices.K.rows()) * 4,
                                      plano::vk::MemoryClass::Device, "block inverses");
    plano::vk::Array<std::uint32_t> failure(context, 1, plano::vk::MemoryClass::Host, "failure");
    const std::uint32_t none = ~0u;
    failure.upload({&none, 1});
    plano::vk::Sequence update(context);
    update.begin();
    algebra.invertDiagonalBlocks(update, deviceK, 4, inverses, failure);
    multigrid.setRho(update, ExactStepMatrices::rho, deviceK, inverses, failure);
    update.end();
    plano::bench::timeSequence(state, update, [&] { memory.markLoopStart(); });
    std::uint32_t failed = 0;
    failure.download({&failed, 1});
    if (failed != none) state.SkipWithError("a level was not positive definite");
  } catch (const plano::Error& e) {  // e.g. larger than lavapipe's 2 GiB heap
    state.SkipWithError(e.what());
    return;
  }
  plano::bench::setFaceCounters(state, mesh);
  state.counters["levels"] = aggregation.levelCount();
}

/// Eigen's ConjugateGradient preconditioner that applies one V-cycle (set after compute()).
class VCyclePreconditioner {
 public:
  template <typename Matrix>
  VCyclePreconditioner& analyzePattern(const Matrix&) { return *this; }
  template <typename Matrix>
  VCyclePreconditioner& factorize(const Matrix&) { return *this; }
  template <typename Matrix>
  VCyclePreconditioner& compute(const Matrix&) { return *this; }
  template <typename Rhs>
  Eigen::VectorXd solve(const Rhs& r) const { return cycle->apply(r); }
  Eigen::ComputationInfo info() const { return Eigen::Success; }
  const plano::compute::BlockMultigrid* cycle = nullptr;
};

/// The host PCG solve of the exact step's K (rho 1e3) to 1e-10 from zero, preconditioned
/// by the plain or the smoothed-aggregation V-cycle (BlockMultigridSettings::smoothProlongation):
/// whether the smoothed cycle's fewer iterations pay for its denser levels. Counters: PCG
/// iterations, the cycle's operator complexity, its setup in ms (outside the timed loop).
void BM_MultigridPcg(benchmark::State& state, bool smoothProlongation) {
  const plano::PolygonMesh mesh = plano::bench::quadMesh(state.range(0));
  const plano::projective::ShapeSpace space(mesh);
  const ExactStepMatrices matrices(space);
  const Eigen::SparseMatrix<double> K(matrices.K);
  plano::compute::BlockMultigridSettings settings;
  settings.smoothProlongation = smoothProlongation;
  const auto setupStart = std::chrono::steady_clock::now();
  const plano::compute::BlockMultigrid cycle(matrices.K, settings);
  const std::chrono::duration<double, std::milli> setup = std::chrono::steady_clock::now() - setupStart;
  Eigen::ConjugateGradient<Eigen::SparseMatrix<double>, Eigen::Lower | Eigen::Upper, VCyclePreconditioner> pcg;
  pcg.setTolerance(1e-10);
  pcg.compute(K);
  pcg.preconditioner().cycle = &cycle;
  std::mt19937 random(1);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  const Eigen::VectorXd b = Eigen::VectorXd::NullaryExpr(K.rows(), [&] { return uniform(random); });
  for (auto _ : state) benchmark::DoNotOptimize(pcg.solve(b).eval().data());
  if (pcg.info() != Eigen::Success) state.SkipWithError("PCG did not converge");
  double entries = 0.0;
  for (int l = 0; l < cycle.levelCount(); ++l) entries += static_cast<double>(cycle.nonZeros(l));
  plano::bench::setFaceCounters(state, mesh);
  state.counters["pcg_iterations"] = static_cast<double>(pcg.iterations());
  state.counters["operator_complexity"] = entries / static_cast<double>(cycle.nonZeros(0));
  state.counters["setup_ms"] = setup.count();
}

/// One rho update of a K small enough to be preconditioned by its whole inverse (at most
/// vk::AdmmKernels::kMaxWholeInverseBlocks faces): K = K0 + rho K1 assembled dense and
/// inverted on the device (shaders/mg_coarsest_assemble.comp, mg_coarsest_invert.comp),
/// twice per step of a small mesh's deformation (the ADMM's K and the polish's K_A).
void BM_WholeInverse(benchmark::State& state) {
  plano::compute::Backend* backend = plano::bench::backendOrSkip(state, BackendChoice::Vulkan);
  if (!backend) return;
  const plano::PolygonMesh mesh = plano::bench::quadMesh(state.range(0));
  const plano::projective::ShapeSpace space(mesh);
  const plano::compute::SparseMatrix C = compatibilityMatrix(space, 1);
  plano::compute::SparseMatrix K1 = C.transpose() * C;
  plano::compute::SparseMatrix identity(K1.rows(), K1.cols());
  identity.setIdentity();
  plano::compute::SparseMatrix K0 = identity * (1.0 + plano::compute::AdmmSettings{}.sigma) + K1 * 0.0;
  K0.makeCompressed();
  K1 = K1 + K0 * 0.0;  // on K0's pattern
  K1.makeCompressed();
  plano::compute::BlockMultigridSettings settings{4};
  settings.coarsestBlocks = static_cast<int>(K0.rows() / 4);  // one level: K itself, inverted whole
  const plano::compute::BlockAggregation aggregation(plano::compute::SparseMatrix(K0 + K1), settings);
  try {
    plano::vk::Context& context = static_cast<plano::compute::VulkanBackend*>(backend)->context();
    plano::vk::LinearAlgebra algebra(context);
    plano::vk::Multigrid multigrid(context, algebra, aggregation, K0, K0);
    multigrid.setK1(K1);
    plano::vk::Array<std::uint32_t> failure(context, 1, plano::vk::MemoryClass::Host, "failure");
    const std::uint32_t none = ~0u;
    failure.upload({&none, 1});
    plano::vk::Sequence update(context);
    update.begin();
    multigrid.setRho(update, 1e3, failure);
    update.end();
    plano::bench::timeSequence(state, update);
    std::uint32_t failed = 0;
    failure.download({&failed, 1});
    if (failed != none) state.SkipWithError("K was not positive definite");
  } catch (const plano::Error& e) {
    state.SkipWithError(e.what());
    return;
  }
  plano::bench::setFaceCounters(state, mesh);
  state.counters["levels"] = aggregation.levelCount();
  state.counters["rows"] = static_cast<double>(K0.rows());
}

/// The same matrix as a ScaledConstraintMatrix (its pattern once, values per step).
plano::projective::ScaledConstraintMatrix scaledCompatibilityMatrix(const plano::projective::ShapeSpace& space) {
  std::vector<plano::projective::ScaledConstraintMatrix::Term> terms;
  const auto& offsets = space.vertexCornerOffsets();
  const auto& corners = space.cornersOfVertex();
  Index rows = 0;
  for (Index v = 0; v < space.vertexCount(); ++v) {
    const Eigen::RowVector4d p = plano::projective::homogeneous(space.basePositions().row(v));
    for (Index k = offsets[v] + 1; k < offsets[v + 1]; ++k, ++rows) {
      terms.push_back({rows, space.cornerFace(corners[offsets[v]]), p, corners[offsets[v]]});
      terms.push_back({rows, space.cornerFace(corners[k]), -p, corners[k]});
    }
  }
  return {rows, space.faceCount(), space.cornerCount(), terms};
}

/// Host work of a global step's constraint matrix per step: assembled from triplets (what
/// the steps did before) or its values filled into the pattern built once
/// (ScaledConstraintMatrix, what they do now).
void BM_GlobalStepConstraints(benchmark::State& state, bool fill) {
  const plano::PolygonMesh mesh = plano::bench::quadMesh(state.range(0));
  const plano::projective::ShapeSpace space(mesh);
  plano::projective::ScaledConstraintMatrix matrix = scaledCompatibilityMatrix(space);
  const std::vector<double> shat = randomScales(space, 1);
  unsigned seed = 0;
  for (auto _ : state) {
    if (fill) {
      benchmark::DoNotOptimize(matrix.fill(shat).valuePtr());
    } else {
      const plano::compute::SparseMatrix C = compatibilityMatrix(space, ++seed);
      benchmark::DoNotOptimize(C.valuePtr());
    }
  }
  plano::bench::setFaceCounters(state, mesh);
}

/// What a projective global step pays before its first ADMM iteration, with a new ADMM
/// solver per step (`new_solver`: buffers, pipelines, K's pattern, the multigrid's
/// aggregates and coarse patterns) or with the solver kept from the previous step and
/// given C's new values (`kept_solver`) or new scales of its entries, one per corner, from
/// which the backend forms the values (`kept_scales`, what GlobalStep does). All then form
/// K on the first solve (rho update) and load the problem; the ADMM iterations are
/// excluded (cap 0).
enum class SolverReuse { New, KeptValues, KeptScales };

void BM_AdmmSetup(benchmark::State& state, BackendChoice choice, SolverReuse reuse) {
  plano::compute::Backend* backend = plano::bench::backendOrSkip(state, choice);
  if (!backend) return;
  const plano::PolygonMesh mesh = plano::bench::quadMesh(state.range(0));
  const plano::projective::ShapeSpace space(mesh);
  const plano::compute::SparseMatrix C[2] = {compatibilityMatrix(space, 1), compatibilityMatrix(space, 2)};
  plano::compute::SparseMatrix P(C[0].cols(), C[0].cols());
  P.setIdentity();
  plano::compute::AdmmSettings settings;
  settings.preconditionerBlock = 4;
  settings.preconditioner = plano::compute::AdmmPreconditioner::Automatic;
  settings.maxIterations = 0;
  const Eigen::MatrixXd q = Eigen::MatrixXd::Ones(P.rows(), 3);
  const Eigen::MatrixXd bounds = Eigen::MatrixXd::Zero(C[0].rows(), 3);
  std::unique_ptr<plano::compute::AdmmSolver> solver = backend->createAdmmSolver(P, C[0], settings);
  const std::vector<double> scales[2] = {randomScales(space, 1), randomScales(space, 2)};
  if (reuse == SolverReuse::KeptScales) solver->setConstraintScaling(scaledCompatibilityMatrix(space).scaling());
  int step = 0;
  for (auto _ : state) {
    const int which = ++step % 2;
    switch (reuse) {
      case SolverReuse::New: solver = backend->createAdmmSolver(P, C[which], settings); break;
      case SolverReuse::KeptValues: solver->setConstraintValues(C[which]); break;
      case SolverReuse::KeptScales: solver->setConstraintScales(scales[which]); break;
    }
    Eigen::MatrixXd x, y, z;
    solver->solve(q, bounds, bounds, x, y, z);
    benchmark::DoNotOptimize(x.data());
  }
  plano::bench::setFaceCounters(state, mesh);
}

BENCHMARK_CAPTURE(BM_LocalStep, cpu, BackendChoice::Cpu)
    ->Arg(4096)->Arg(65536)->Arg(262144)->Arg(1 << 20)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_LocalStep, vulkan, BackendChoice::Vulkan)
    ->Arg(4096)->Arg(65536)->Arg(262144)->Arg(1 << 20)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_RigidLocalStep, cpu_fused, BackendChoice::Cpu, RigidLocalStep::Fused)
    ->Arg(4096)->Arg(65536)->Arg(262144)->Arg(1 << 20)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_RigidLocalStep, vulkan_fused, BackendChoice::Vulkan, RigidLocalStep::Fused)
    ->Arg(4096)->Arg(65536)->Arg(262144)->Arg(1 << 20)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_RigidLocalStep, vulkan_two_calls, BackendChoice::Vulkan, RigidLocalStep::TwoCalls)
    ->Arg(4096)->Arg(65536)->Arg(262144)->Arg(1 << 20)->Unit(benchmark::kMillisecond);
// On lavapipe the device global step takes 2.7 / 18.5 / 76 s on 256 / 1k / 4k faces (2026-12-07;
// vulkan_admm_first 5.8 / 47.5 / 197 s); vulkan_face_blocks is the block-Jacobi baseline.
BENCHMARK_CAPTURE(BM_GlobalStep, cpu, BackendChoice::Cpu)
    ->Arg(64)->Arg(256)->Arg(1024)->Arg(4096)->Arg(65536)->Arg(262144)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_GlobalStep, vulkan_face_blocks, BackendChoice::Vulkan,
                  plano::compute::AdmmPreconditioner::BlockJacobi)
    ->Arg(64)->Arg(256)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_GlobalStep, vulkan, BackendChoice::Vulkan)
    ->Arg(64)->Arg(256)->Arg(1024)->Arg(4096)->Arg(65536)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_GlobalStep, vulkan_admm_first, BackendChoice::Vulkan,
                  plano::compute::AdmmPreconditioner::Automatic, plano::projective::EqualitySolve::Admm)
    ->Arg(256)->Arg(1024)->Arg(4096)->Unit(benchmark::kMillisecond);
// The GPU target's sizes (one iteration each); on lavapipe their buffers pass its 128 MiB
// binding range and they skip with that error.
BENCHMARK_CAPTURE(BM_GlobalStep, vulkan, BackendChoice::Vulkan)
    ->Arg(262144)->Arg(1 << 20)->Iterations(1)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_AdmmSetup, cpu_new_solver, BackendChoice::Cpu, SolverReuse::New)
    ->Arg(4096)->Arg(65536)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_AdmmSetup, cpu_kept_solver, BackendChoice::Cpu, SolverReuse::KeptValues)
    ->Arg(4096)->Arg(65536)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_AdmmSetup, vulkan_new_solver, BackendChoice::Vulkan, SolverReuse::New)
    ->Arg(4096)->Arg(65536)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_AdmmSetup, vulkan_kept_solver, BackendChoice::Vulkan, SolverReuse::KeptValues)
    ->Arg(4096)->Arg(65536)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_AdmmSetup, vulkan_kept_scales, BackendChoice::Vulkan, SolverReuse::KeptScales)
    ->Arg(4096)->Arg(65536)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_MultigridCycle, cpu, BackendChoice::Cpu, false)->Apply(plano::bench::standardSizes);
BENCHMARK_CAPTURE(BM_MultigridCycle, cpu, BackendChoice::Cpu, false)->Apply(plano::bench::largeSizes);
BENCHMARK_CAPTURE(BM_MultigridCycle, vulkan, BackendChoice::Vulkan, false)->Apply(plano::bench::standardSizes);
BENCHMARK_CAPTURE(BM_MultigridCycle, vulkan, BackendChoice::Vulkan, false)->Apply(plano::bench::largeSizes);
BENCHMARK_CAPTURE(BM_MultigridCycle, cpu_smoothed, BackendChoice::Cpu, true)->Apply(plano::bench::standardSizes);
BENCHMARK_CAPTURE(BM_MultigridCycle, vulkan_smoothed, BackendChoice::Vulkan, true)->Apply(plano::bench::standardSizes);
BENCHMARK_CAPTURE(BM_MultigridUpdate, plain, false)->Apply(plano::bench::standardSizes);
BENCHMARK_CAPTURE(BM_MultigridUpdate, smoothed, true)->Apply(plano::bench::standardSizes);
BENCHMARK_CAPTURE(BM_MultigridPcg, plain, false)->Apply(plano::bench::standardSizes);
BENCHMARK_CAPTURE(BM_MultigridPcg, smoothed, true)->Apply(plano::bench::standardSizes);
BENCHMARK(BM_WholeInverse)->Arg(16)->Arg(64)->Arg(128)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_GlobalStepConstraints, assembled, false)
    ->Arg(4096)->Arg(65536)->Arg(1 << 20)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_GlobalStepConstraints, filled, true)
    ->Arg(4096)->Arg(65536)->Arg(1 << 20)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_DeformationIteration, cpu, BackendChoice::Cpu, DeformationTiming::First)
    ->Arg(256)->Arg(4096)->Arg(65536)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_DeformationIteration, vulkan, BackendChoice::Vulkan, DeformationTiming::First)
    ->Arg(256)->Arg(4096)->Arg(65536)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_DeformationIteration, vulkan, BackendChoice::Vulkan, DeformationTiming::First)
    ->Arg(262144)->Arg(1 << 20)->Iterations(1)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_DeformationIteration, cpu_steady, BackendChoice::Cpu, DeformationTiming::Steady)
    ->Arg(256)->Arg(4096)->Arg(65536)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_DeformationIteration, vulkan_steady, BackendChoice::Vulkan, DeformationTiming::Steady)
    ->Arg(256)->Arg(4096)->Arg(65536)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_DeformationIteration, cpu_continued, BackendChoice::Cpu, DeformationTiming::Continued)
    ->Arg(256)->Arg(4096)->Arg(65536)->Iterations(8)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_DeformationIteration, vulkan_continued, BackendChoice::Vulkan, DeformationTiming::Continued)
    ->Arg(256)->Arg(4096)->Arg(65536)->Iterations(8)->Unit(benchmark::kMillisecond);

}  // namespace
