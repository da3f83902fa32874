// Global-step linear algebra per backend on shifted mesh Laplacians (#V ~ #F): sparse
// matrix times three columns (device-resident vectors on Vulkan: the kernel alone), and
// SPD solves with three right-hand sides (CHOLMOD, prefactored, vs device Jacobi PCG
// from a zero start to 1e-8).
#include "MemoryCounters.h"
#include "VulkanBenchSupport.h"
#include "compute/vulkan/VulkanBackend.h"
#include "compute/vulkan/VulkanLinearAlgebra.h"

namespace {

using plano::compute::BackendChoice;

void BM_Spmv(benchmark::State& state, BackendChoice choice) {
  plano::compute::Backend* backend = plano::bench::backendOrSkip(state, choice);
  if (!backend) return;
  const plano::bench::MemoryCounters memory(state, backend);
  const plano::PolygonMesh mesh = plano::bench::quadMesh(state.range(0));
  const plano::compute::SparseMatrix A = plano::bench::shiftedLaplacian(mesh, 1.0);
  const Eigen::MatrixXd X = mesh.vertices;
  if (choice == BackendChoice::Cpu) {
    Eigen::MatrixXd Y(X.rows(), 3);
    for (auto _ : state) {
      Y.noalias() = A * X;
      benchmark::DoNotOptimize(Y.data());
    }
  } else {
    plano::vk::Context& context = static_cast<plano::compute::VulkanBackend*>(backend)->context();
    plano::vk::LinearAlgebra algebra(context);
    plano::vk::DeviceCsrMatrix deviceA(context, A);
    plano::vk::DeviceVectors x(context, static_cast<std::uint32_t>(X.rows()), 3, "x");
    plano::vk::DeviceVectors y(context, static_cast<std::uint32_t>(X.rows()), 3, "y");
    x.upload(X);
    plano::vk::Sequence sequence(context);
    sequence.begin();
    algebra.spmv(sequence, deviceA, x, y);
    sequence.end();
    plano::bench::timeSequence(state, sequence);
  }
  state.counters["rows"] = static_cast<double>(A.rows());
  state.counters["nonzeros"] = static_cast<double>(A.nonZeros());
  plano::bench::setThroughput(state, static_cast<double>(A.rows()), "rows_per_s");
}

void BM_SpdSolve(benchmark::State& state, BackendChoice choice) {
  plano::compute::Backend* backend = plano::bench::backendOrSkip(state, choice);
  if (!backend) return;
  const plano::PolygonMesh mesh = plano::bench::quadMesh(state.range(0));
  const plano::compute::SparseMatrix A = plano::bench::shiftedLaplacian(mesh, 1.0);
  Eigen::MatrixXd B = mesh.vertices;
  B.col(2) += mesh.vertices.col(0).array().sin().matrix();
  const plano::bench::MemoryCounters memory(state, backend);  // the solver's: its factor, its device copy of A
  plano::compute::LinearSolverSettings settings;
  settings.relativeTolerance = 1e-8;
  std::unique_ptr<plano::compute::SpdSolver> solver;
  try {
    solver = backend->createSpdSolver(A, settings);
  } catch (const std::exception& e) {
    state.SkipWithError(e.what());
    return;
  }
  Eigen::MatrixXd X;
  plano::compute::LinearSolveInfo info;
  for (auto _ : state) {
    X = Eigen::MatrixXd::Zero(B.rows(), B.cols());
    info = solver->solve(B, X);
    benchmark::DoNotOptimize(X.data());
  }
  state.counters["iterations"] = info.iterations;
  state.counters["relative_residual"] = info.relativeResidual;
  // A direct solver's estimate of its factorization's peak, beside the measured host_peak_MiB.
  if (solver->factorBytes() > 0.0) state.counters["factor_estimate_MiB"] = solver->factorBytes() / (1 << 20);
  state.counters["rows"] = static_cast<double>(A.rows());
  plano::bench::setThroughput(state, static_cast<double>(A.rows()), "rows_per_s");
}

BENCHMARK_CAPTURE(BM_Spmv, cpu, BackendChoice::Cpu)->Apply(plano::bench::standardSizes);
BENCHMARK_CAPTURE(BM_Spmv, cpu, BackendChoice::Cpu)->Apply(plano::bench::largeSizes);
BENCHMARK_CAPTURE(BM_Spmv, vulkan, BackendChoice::Vulkan)->Apply(plano::bench::standardSizes);
BENCHMARK_CAPTURE(BM_Spmv, vulkan, BackendChoice::Vulkan)->Apply(plano::bench::largeSizes);
BENCHMARK_CAPTURE(BM_SpdSolve, cpu, BackendChoice::Cpu)->Apply(plano::bench::standardSizes);
BENCHMARK_CAPTURE(BM_SpdSolve, cpu, BackendChoice::Cpu)->Apply(plano::bench::largeSizes);
BENCHMARK_CAPTURE(BM_SpdSolve, vulkan, BackendChoice::Vulkan)->Apply(plano::bench::standardSizes);
BENCHMARK_CAPTURE(BM_SpdSolve, vulkan, BackendChoice::Vulkan)->Apply(plano::bench::largeSizes);

}  // namespace
