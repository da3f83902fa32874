#pragma once
// The per-face math of the closest ideal maps (projective-maps paper, App. A; the batched
// operation is projective/IdealMaps.h): the linear part of a fitted projective face map,
// and the rigid or similarity map built from its closest rotation. Shared by the CPU
// backend (compute::CpuBackend::closestIdealMaps) and mirrored by shaders/ideal_maps.comp.
#include <Eigen/Core>

#include "compute/Backend.h"

namespace plano::projective {

/// A face's linearization: source centroid, its image, the 3x3 linear map whose closest
/// rotation is the ideal map's, and what the similarity scale is taken from.
struct IdealMapLinearization {
  Eigen::RowVector3d centroid = Eigen::RowVector3d::Zero();
  Eigen::RowVector3d image = Eigen::RowVector3d::Zero();
  Eigen::Matrix3d linear = Eigen::Matrix3d::Identity();
  double similarityScale = 1.0;  ///< Of the Jacobian: the mean in-plane singular value.
  double sourceSpread = 1.0;     ///< Of the corner-set Procrustes: sum |p - c|^2 (Umeyama's scale).
  compute::IdealMapMethod method = compute::IdealMapMethod::Jacobian;
};

/// Linearize the fitted map T of one face with source corners `source` (k x 3, normalized
/// coordinates). When `target` (k x 3, the corners T was fitted to) is given and T sends
/// the centroid or a corner through the plane at infinity, the face falls back to the
/// corner-set Procrustes between source and target (method CornerProcrustes); without a
/// target such a face's centroid image may not exist (method CentroidAtInfinity: the
/// linearization is then meaningless).
IdealMapLinearization linearizeFaceMap(const Eigen::Matrix<double, Eigen::Dynamic, 3>& source,
                                       const Eigen::Matrix4d& T,
                                       const Eigen::Matrix<double, Eigen::Dynamic, 3>* target);

/// The ideal map [[s R, 0], [t, 1]] (row-vector convention) of a linearization, with R
/// the closest rotation of its linear map and `singularValues` its signed singular values
/// (compute::Backend::closestRotations): s = 1 for a rigid map; for a similarity the
/// Jacobian's mean in-plane singular value, or Umeyama's scale for a corner-set Procrustes.
/// t keeps the centroid's image: x -> image + (x - centroid) s R.
Eigen::Matrix4d idealMapOf(const IdealMapLinearization& lin, const Eigen::Matrix3d& R,
                           const Eigen::Vector3d& singularValues, bool similar);

}  // namespace plano::projective
