// A 2D pose graph and its least-squares solution (Lu & Milios 1997; the g2o/Cartographer formulation):
// nodes are poses, each edge a measured relative pose with its information matrix; Gauss-Newton on the
// sparse normal equations, with a Huber kernel so that a few wrong matches do not bend the graph. No ROS.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "laser_dpslam/common/pose2d.h"

namespace laser_dpslam {

struct PoseGraphEdge {
  int from = 0;                 ///< node index i
  int to = 0;                   ///< node index j
  Pose2D measurement;           ///< measured pose of j in i's frame (between(x_i, x_j) when exact)
  Eigen::Matrix3d information = Eigen::Matrix3d::Identity();  ///< inverse covariance of (x, y, θ) of the measurement
  /// The Huber kernel applies (PoseGraphOptions::huber_sigmas). Not for the chain that holds the graph
  /// together (odometry): with every edge robust, bending the chain at two joints to satisfy one wrong
  /// closure costs little, and the optimum follows the wrong edge.
  bool robust = true;
};

struct PoseGraphOptions {
  int max_iterations = 30;
  double tolerance = 1e-6;  ///< stop when the largest step component is below this (m / rad)
  /// Huber threshold on an edge's Mahalanobis distance (in σ): residuals beyond it count linearly; ≤ 0 = off.
  double huber_sigmas = 3.0;
};

struct PoseGraphResult {
  int iterations = 0;
  double initial_cost = 0.0;  ///< ½ Σ robust(e_ᵀ Ω e) at the start
  double final_cost = 0.0;    ///< the same at the end
  bool converged = false;     ///< the step fell below the tolerance
  bool solved = true;         ///< false: the normal equations could not be factorised (poses unchanged)
};

/// The error of one edge at (x_i, x_j): (x, y) of measurement⁻¹ ⊕ x_i⁻¹ ⊕ x_j and its angle, wrapped.
Eigen::Vector3d poseGraphError(const Pose2D& xi, const Pose2D& xj, const Pose2D& measurement);

/// Moves `poses` (the initial guess) to the robust least-squares solution of `edges`; node `fixed` does not
/// move (the gauge). Edges with an index out of range or a non-finite measurement or information throw
/// std::invalid_argument. Nodes no edge reaches keep their pose.
PoseGraphResult optimizePoseGraph(std::vector<Pose2D>& poses, const std::vector<PoseGraphEdge>& edges,
                                  const PoseGraphOptions& options = PoseGraphOptions(), int fixed = 0);

}  // namespace laser_dpslam
