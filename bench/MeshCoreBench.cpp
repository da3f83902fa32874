// Mesh core costs that every command pays before its algorithm runs: parsing (from
// memory, so the disk is not measured), writing, validation and topology, on generated
// planar-quad meshes from the Yas Island scale (~4k faces) to 262k faces.
#include <benchmark/benchmark.h>

#include "VulkanBenchSupport.h"
#include "mesh/Generators.h"
#include "mesh/MeshIO.h"
#include "mesh/Topology.h"
#include "mesh/Validation.h"

namespace {

using plano::bench::quadMesh;
using plano::bench::setFaceCounters;

void BM_Topology(benchmark::State& state) {
  const plano::PolygonMesh mesh = quadMesh(state.range(0));
  for (auto _ : state) {
    plano::MeshTopology topology(mesh.faces, mesh.vertexCount());
    benchmark::DoNotOptimize(topology.edgeCount());
  }
  setFaceCounters(state, mesh);
}

void BM_Validate(benchmark::State& state) {
  const plano::PolygonMesh mesh = quadMesh(state.range(0));
  for (auto _ : state) {
    const auto report = plano::validate(mesh);
    benchmark::DoNotOptimize(report.errorCount);
  }
  setFaceCounters(state, mesh);
}

void BM_Parse(benchmark::State& state, plano::MeshFormat format, bool validate) {
  const plano::PolygonMesh mesh = quadMesh(state.range(0));
  const std::string data = plano::formatMesh(mesh, format);
  plano::ReadOptions options;
  options.validate = validate;
  for (auto _ : state) {
    const plano::PolygonMesh read = plano::parseMesh(data, format, "bench", options);
    benchmark::DoNotOptimize(read.vertices.data());
  }
  setFaceCounters(state, mesh);
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations()) * static_cast<std::int64_t>(data.size()));
}

void BM_Format(benchmark::State& state, plano::MeshFormat format) {
  const plano::PolygonMesh mesh = quadMesh(state.range(0));
  for (auto _ : state) {
    const std::string data = plano::formatMesh(mesh, format);
    benchmark::DoNotOptimize(data.data());
  }
  setFaceCounters(state, mesh);
}

#define PLANO_MESH_SIZES ->Arg(4096)->Arg(65536)->Arg(262144)->Unit(benchmark::kMillisecond)
BENCHMARK(BM_Topology) PLANO_MESH_SIZES;
BENCHMARK(BM_Validate) PLANO_MESH_SIZES;
BENCHMARK_CAPTURE(BM_Parse, obj, plano::MeshFormat::Obj, false) PLANO_MESH_SIZES;
BENCHMARK_CAPTURE(BM_Parse, off, plano::MeshFormat::Off, false) PLANO_MESH_SIZES;
BENCHMARK_CAPTURE(BM_Parse, ply_binary, plano::MeshFormat::Ply, false) PLANO_MESH_SIZES;
BENCHMARK_CAPTURE(BM_Parse, obj_validated, plano::MeshFormat::Obj, true) PLANO_MESH_SIZES;
BENCHMARK_CAPTURE(BM_Format, obj, plano::MeshFormat::Obj) PLANO_MESH_SIZES;
BENCHMARK_CAPTURE(BM_Format, ply_binary, plano::MeshFormat::Ply) PLANO_MESH_SIZES;

}  // namespace
