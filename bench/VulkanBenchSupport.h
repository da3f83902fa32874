#pragma once
// Shared pieces of the CPU-vs-Vulkan kernel benchmarks: one backend of each kind per
// process (pipelines are built and JIT-compiled once, not per benchmark), the mesh sizes
// (Yas Island scale ~4k faces up to 1M) and test matrices.
#include <benchmark/benchmark.h>

#include <cmath>
#include <functional>
#include <map>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "compute/Backend.h"
#include "compute/vulkan/VulkanSequence.h"
#include "core/ParallelFor.h"
#include "mesh/Generators.h"

namespace plano::bench {

/// Run every backend operation once on a tiny input, so that pipeline creation and the
/// driver's JIT (~0.1-10 s per pipeline on lavapipe) stay out of the timed loops.
inline void warmUp(compute::Backend& backend) {
  const PolygonMesh cube = generate::cube();
  std::vector<double> values(cube.faceCount());
  backend.facePlanarity(cube, values);
  compute::ProjectiveFits fits;
  backend.fitProjectiveMaps(cube.faces, cube.vertices, cube.vertices, fits);
  std::vector<Eigen::Matrix3d> matrices(1, Eigen::Matrix3d::Identity()), rotations(1);
  std::vector<Eigen::Vector3d> singular(1);
  backend.closestRotations(matrices, rotations, singular);
  compute::SparseMatrix identity(8, 8);
  identity.setIdentity();
  identity.makeCompressed();
  Eigen::MatrixXd X = Eigen::MatrixXd::Zero(8, 3);
  backend.createSpdSolver(identity, {})->solve(cube.vertices, X);
  (void)backend.reducedOperator(identity, Eigen::MatrixXd::Ones(8, 2), 1);
}

/// The process-wide backend of a kind (warmed up), or null with the reason in *error.
inline compute::Backend* sharedBackend(compute::BackendChoice choice, std::string* error) {
  struct Slot {
    std::unique_ptr<compute::Backend> backend;
    std::string error;
    bool tried = false;
  };
  static std::map<compute::BackendChoice, Slot> slots;
  Slot& slot = slots[choice];
  if (!slot.tried) {
    slot.tried = true;
    try {
      slot.backend = compute::createBackend(choice);
      warmUp(*slot.backend);
    } catch (const std::exception& e) {
      slot.error = e.what();
    }
  }
  if (error) *error = slot.error;
  return slot.backend.get();
}

/// Backend for a benchmark, or SkipWithError (e.g. no Vulkan device) and null. A CPU
/// benchmark reports the threads of its per-face kernels (cpu_threads: core/ParallelFor.h).
inline compute::Backend* backendOrSkip(benchmark::State& state, compute::BackendChoice choice) {
  std::string error;
  compute::Backend* backend = sharedBackend(choice, &error);
  if (!backend) state.SkipWithError(("no backend: " + error).c_str());
  if (backend && backend->kind() == compute::BackendKind::Cpu) state.counters["cpu_threads"] = cpuThreads();
  return backend;
}

/// A planar-quad translational surface with about `faces` faces.
inline PolygonMesh quadMesh(std::int64_t faces) {
  const auto side = static_cast<Index>(std::lround(std::sqrt(static_cast<double>(faces))));
  return generate::translationalSurface(side, side);
}

/// Deterministic uniform noise of the given amplitude on every coordinate.
inline Positions jittered(const Positions& vertices, double amplitude, unsigned seed = 3) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-amplitude, amplitude);
  Positions out = vertices;
  for (Eigen::Index i = 0; i < out.size(); ++i) out.data()[i] += u(rng);
  return out;
}

/// Graph Laplacian of the mesh edges plus `shift` I: the shape of a global-step matrix
/// (shift plays the role of the ADMM penalty / positional weights).
inline compute::SparseMatrix shiftedLaplacian(const PolygonMesh& mesh, double shift) {
  std::vector<Eigen::Triplet<double, int>> entries;
  for (Index f = 0; f < mesh.faceCount(); ++f) {
    const auto face = mesh.faces[f];
    for (std::size_t i = 0; i < face.size(); ++i) {
      const Index a = face[i], b = face[(i + 1) % face.size()];
      entries.emplace_back(a, b, -0.5);
      entries.emplace_back(b, a, -0.5);
      entries.emplace_back(a, a, 0.5);
      entries.emplace_back(b, b, 0.5);
    }
  }
  for (Index v = 0; v < mesh.vertexCount(); ++v) entries.emplace_back(v, v, shift);
  compute::SparseMatrix A(mesh.vertexCount(), mesh.vertexCount());
  A.setFromTriplets(entries.begin(), entries.end());
  A.makeCompressed();
  return A;
}

/// Faces (or items) per second as a rate counter.
inline void setThroughput(benchmark::State& state, double items, const char* name = "faces_per_s") {
  state.counters[name] = benchmark::Counter(items, benchmark::Counter::kIsIterationInvariantRate);
}

/// The mesh's face count, and faces per second as a rate counter.
inline void setFaceCounters(benchmark::State& state, const PolygonMesh& mesh) {
  state.counters["faces"] = static_cast<double>(mesh.faceCount());
  setThroughput(state, static_cast<double>(mesh.faceCount()));
}

/// Time a recorded device sequence: one run before the timed loop (the driver's lazy work
/// stays out of it), `beforeLoop` (e.g. MemoryCounters::markLoopStart), then one run per
/// iteration, with the device's own time (timestamp queries) as the device_ms counter.
inline void timeSequence(benchmark::State& state, vk::Sequence& sequence,
                         const std::function<void()>& beforeLoop = {}) {
  sequence.run();
  if (beforeLoop) beforeLoop();
  double deviceSeconds = 0.0;
  for (auto _ : state) {
    sequence.run();
    deviceSeconds += sequence.lastDeviceSeconds();
  }
  state.counters["device_ms"] = benchmark::Counter(1e3 * deviceSeconds, benchmark::Counter::kAvgIterations);
}

/// The standard sizes; the two large ones run once (lavapipe is a CPU JIT: slow).
inline void standardSizes(benchmark::internal::Benchmark* b) {
  b->Unit(benchmark::kMillisecond)->UseRealTime();
  for (std::int64_t faces : {4096, 65536}) b->Arg(faces);
}
inline void largeSizes(benchmark::internal::Benchmark* b) {
  b->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(1);
  for (std::int64_t faces : {262144, 1 << 20}) b->Arg(faces);
}

}  // namespace plano::bench
