#pragma once
// Planarity of polygon faces as architects and the papers measure it.
//
// Quad: distance between the two diagonal lines divided by the mean diagonal length,
// in percent. A face of k > 4 corners: the same value for each of its k runs of four
// consecutive corners; the face value is their mean (the max is reported too).
// Triangles are planar by definition (0). The plane-fit residual is the largest
// distance of a corner from the least-squares plane divided by the mean edge length.
#include <vector>

#include "mesh/PolygonMesh.h"

namespace plano {

/// Planarity (percent) of the quad a, b, c, d: distance between the lines ac and bd
/// over the mean of |ac| and |bd|.
double quadPlanarity(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                     const Eigen::Vector3d& d);

struct FacePlanarity {
  double mean = 0.0;  ///< Mean over runs of four consecutive corners (the face value).
  double max = 0.0;   ///< Max over those runs.
};

/// Planarity of face f of the mesh.
FacePlanarity facePlanarity(const Positions& vertices, std::span<const Index> face);

/// Largest corner distance to the least-squares plane over the mean edge length.
double planeFitResidual(const Positions& vertices, std::span<const Index> face);

/// Per-face planarity of every face (face values, percent).
std::vector<double> facePlanarities(const PolygonMesh& mesh);

/// Summary statistics of per-face planarity values, all in percent.
struct PlanarityStats {
  double max = 0.0;
  double mean = 0.0;
  double p95 = 0.0;             ///< 95th percentile (nearest rank).
  Index overTolerance = 0;      ///< Faces whose value exceeds `tolerance`.
  double tolerance = 1.0;       ///< Percent.
  double maxRun = 0.0;          ///< Max over all runs of four corners (equals max for quads).
  double maxPlaneFitResidual = 0.0;
};

/// Statistics of per-face values (as returned by facePlanarities or a backend kernel).
PlanarityStats summarizePlanarity(const std::vector<double>& faceValues, double tolerance = 1.0);

/// Full statistics of a mesh, including the worst run and the plane-fit residual.
PlanarityStats planarityStats(const PolygonMesh& mesh, double tolerance = 1.0);

}  // namespace plano
