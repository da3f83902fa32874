#pragma once
// Per-face blocks B_f of the constraint matrix (linear-spaces paper, §2 "Generating
// subspaces", Eq. 3), already reduced to independent, orthonormal rows (§4: the paper
// reduces each B_f by SVD; here the reduction is built in, so every row is needed).
//
// Conventions. A face of k corners with source corners y_1..y_k (rows of Y). Centring is
// the linear map C = I - 11^T/k on the k corner values; Theorem 1 is stated for centred
// polygons, so each block acts on X_f through C. The source is taken in its best-fitting
// plane (normal n, two in-plane axes e1, e2), which makes the blocks exact even for
// faces planar only up to input precision.
#include <Eigen/Core>
#include <span>

#include "mesh/PolygonMesh.h"
#include "subspace/FaceSpace.h"

namespace plano::subspace {

/// Best-fitting plane of a face: centroid, unit normal n, in-plane axes e1, e2 (e1, e2, n
/// right-handed), and the corners' in-plane coordinates (k x 2).
struct FaceFrame {
  Eigen::Vector3d centroid;
  Eigen::Vector3d normal;
  Eigen::Vector3d axis1, axis2;
  Eigen::MatrixX2d planar;
  double flatness = 0.0;      ///< Second over first singular value of the centred corners.
  double nonPlanarity = 0.0;  ///< Third over first: 0 for an exactly planar face.
};

/// Fit the frame of face `face` (index `f` is used in messages). Throws Error(BadInput)
/// naming the face when its corners are (nearly) collinear: flatness below `degeneracy`.
FaceFrame fitFaceFrame(const Positions& Y, std::span<const Index> face, Index f, double degeneracy = 1e-9);

/// Affine (type 1) block, scalar: (k-3) x k with orthonormal rows spanning the complement
/// of span{1, u, v} (u, v the in-plane coordinates). A coordinate row x of X_f satisfies
/// it iff x C lies in the row space of Y_f C, i.e. iff X_f (Y_f^+ Y_f - I) C = 0. The
/// same block acts on x, y and z (separable case).
Eigen::MatrixXd affineFaceBlock(const FaceFrame& frame);

/// Parallel block: (k-1) x 3k, rows q_j^T (x) n^T for an orthonormal basis q_j of 1^perp:
/// n . (x_i - centroid(X_f)) = 0 for every corner, i.e. the plane keeps its normal and
/// moves by a free offset. Columns are ordered 3 i + c (corner i, coordinate c).
Eigen::MatrixXd parallelFaceBlock(const FaceFrame& frame);

/// Vertical block (type 2 with the target normal N_X = up): 2(k-2) x 3k. With
/// N = up x n (the horizontal line of the face) and Y_2 the corners' coordinates along
/// E = N x n, the block says (X_f x N) M = 0 (M spanning the complement of span{1, Y_2}):
/// every member is N z^T + w Y_2^T + t 1^T, i.e. corners slide freely along N and the
/// face turns about N. Precondition: up is not parallel to n (see isHorizontal).
Eigen::MatrixXd verticalFaceBlock(const FaceFrame& frame, const Eigen::Vector3d& up);

/// The block of any type acting on the face's 3k coordinates (the affine scalar block
/// expanded to its three coordinate copies), rows ordered 3 r + c for the affine case.
Eigen::MatrixXd faceBlock(const FaceFrame& frame, FaceSpace space, const Eigen::Vector3d& up);

/// Whether the face plane is perpendicular to `up` (|up x n| <= tolerance), where the
/// vertical relationship degenerates to the parallel one (sub-case 1 of type 2).
bool isHorizontal(const FaceFrame& frame, const Eigen::Vector3d& up, double tolerance = 1e-9);

}  // namespace plano::subspace
