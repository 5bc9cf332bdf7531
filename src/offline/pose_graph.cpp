#include "laser_dpslam/offline/pose_graph.h"

#include <Eigen/Sparse>
#include <Eigen/SparseCholesky>
#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace laser_dpslam {

namespace {

Eigen::Matrix2d rotationTransposed(double theta) {
  const double c = std::cos(theta), s = std::sin(theta);
  Eigen::Matrix2d r;
  r << c, s, -s, c;
  return r;
}

// ½ρ(d²) of the Huber kernel on the Mahalanobis distance d, and the IRLS weight ρ'(d²).
void huber(double d2, double k, double* cost, double* weight) {
  const double d = std::sqrt(d2);
  if (k <= 0.0 || d <= k) {
    *cost = 0.5 * d2;
    *weight = 1.0;
  } else {
    *cost = k * d - 0.5 * k * k;
    *weight = k / d;
  }
}

double totalCost(const std::vector<Pose2D>& poses, const std::vector<PoseGraphEdge>& edges, double k) {
  double sum = 0.0;
  for (const auto& e : edges) {
    const Eigen::Vector3d r = poseGraphError(poses[e.from], poses[e.to], e.measurement);
    double c, w;
    huber(r.dot(e.information * r), e.robust ? k : 0.0, &c, &w);
    sum += c;
  }
  return sum;
}

}  // namespace

Eigen::Vector3d poseGraphError(const Pose2D& xi, const Pose2D& xj, const Pose2D& measurement) {
  const Eigen::Vector2d dt = rotationTransposed(xi.theta) * (xj.translation() - xi.translation());
  const Eigen::Vector2d exy = rotationTransposed(measurement.theta) * (dt - measurement.translation());
  return {exy.x(), exy.y(), normalizeAngle(xj.theta - xi.theta - measurement.theta)};
}

namespace {

// Variable index of each node: the fixed one has none (the gauge).
int variableOf(int node, int fixed) { return node == fixed ? -1 : (node > fixed ? node - 1 : node); }

void checkEdges(const std::vector<PoseGraphEdge>& edges, int n) {
  for (std::size_t k = 0; k < edges.size(); ++k) {
    const auto& e = edges[k];
    if (e.from < 0 || e.to < 0 || e.from >= n || e.to >= n || e.from == e.to) {
      throw std::invalid_argument("pose graph edge " + std::to_string(k) + " joins nodes " + std::to_string(e.from) +
                                  " and " + std::to_string(e.to) + " of " + std::to_string(n));
    }
    if (!e.measurement.vector().allFinite() || !e.information.allFinite()) {
      throw std::invalid_argument("pose graph edge " + std::to_string(k) + " is not finite");
    }
  }
}

// Jacobians of the error w.r.t. x_i and x_j (the g2o SE(2) edge).
void errorJacobians(const Pose2D& xi, const Pose2D& xj, const Pose2D& measurement, Eigen::Matrix3d& A,
                    Eigen::Matrix3d& B) {
  const Eigen::Matrix2d rzt = rotationTransposed(measurement.theta);
  const Eigen::Matrix2d rit = rotationTransposed(xi.theta);
  const double ci = std::cos(xi.theta), si = std::sin(xi.theta);
  Eigen::Matrix2d drit;
  drit << -si, ci, -ci, -si;
  A = Eigen::Matrix3d::Zero();
  B = Eigen::Matrix3d::Zero();
  A.topLeftCorner<2, 2>() = -rzt * rit;
  A.topRightCorner<2, 1>() = rzt * drit * (xj.translation() - xi.translation());
  A(2, 2) = -1.0;
  B.topLeftCorner<2, 2>() = rzt * rit;
  B(2, 2) = 1.0;
}

// The Gauss-Newton normal equations H·dx = −b at `poses`, each edge weighted by its Huber IRLS weight.
Eigen::SparseMatrix<double> normalEquations(const std::vector<Pose2D>& poses, const std::vector<PoseGraphEdge>& edges,
                                            double k, int fixed, Eigen::VectorXd& b) {
  const int dim = 3 * (static_cast<int>(poses.size()) - 1);
  std::vector<Eigen::Triplet<double>> triplets;
  triplets.reserve(edges.size() * 36 + dim);
  b = Eigen::VectorXd::Zero(dim);
  for (const auto& e : edges) {
    const Pose2D& xi = poses[e.from];
    const Pose2D& xj = poses[e.to];
    const Eigen::Vector3d r = poseGraphError(xi, xj, e.measurement);
    double c, w;
    huber(r.dot(e.information * r), e.robust ? k : 0.0, &c, &w);
    Eigen::Matrix3d A, B;
    errorJacobians(xi, xj, e.measurement, A, B);
    const Eigen::Matrix3d omega = w * e.information;
    const int vi = variableOf(e.from, fixed), vj = variableOf(e.to, fixed);
    const Eigen::Matrix3d* J[2] = {&A, &B};
    const int v[2] = {vi, vj};
    for (int a = 0; a < 2; ++a) {
      if (v[a] < 0) continue;
      b.segment<3>(3 * v[a]) += J[a]->transpose() * omega * r;
      for (int bb = 0; bb < 2; ++bb) {
        if (v[bb] < 0) continue;
        const Eigen::Matrix3d block = J[a]->transpose() * omega * *J[bb];
        for (int r0 = 0; r0 < 3; ++r0)
          for (int c0 = 0; c0 < 3; ++c0) triplets.emplace_back(3 * v[a] + r0, 3 * v[bb] + c0, block(r0, c0));
      }
    }
  }
  // A whisper of damping keeps nodes no edge constrains (and gauge directions) solvable; it is far below
  // any measurement's information.
  for (int d = 0; d < dim; ++d) triplets.emplace_back(d, d, 1e-9);
  Eigen::SparseMatrix<double> H(dim, dim);
  H.setFromTriplets(triplets.begin(), triplets.end());
  return H;
}

// `before` moved by dx into `poses`, with step halving: Gauss-Newton may overshoot while the Huber weights
// change. Stops at the first scale (into *scale) whose cost is not above `cost0`; returns the last cost.
double applyStep(const std::vector<Pose2D>& before, const Eigen::VectorXd& dx, const std::vector<PoseGraphEdge>& edges,
                 double k, int fixed, double cost0, std::vector<Pose2D>& poses, double* scale) {
  const int n = static_cast<int>(poses.size());
  double cost = cost0;
  for (int h = 0; h < 6; ++h, *scale *= 0.5) {
    for (int node = 0; node < n; ++node) {
      const int vn = variableOf(node, fixed);
      if (vn < 0) continue;
      poses[node] = Pose2D(before[node].x + *scale * dx(3 * vn), before[node].y + *scale * dx(3 * vn + 1),
                           normalizeAngle(before[node].theta + *scale * dx(3 * vn + 2)));
    }
    cost = totalCost(poses, edges, k);
    if (cost <= cost0) break;
  }
  return cost;
}

}  // namespace

PoseGraphResult optimizePoseGraph(std::vector<Pose2D>& poses, const std::vector<PoseGraphEdge>& edges,
                                  const PoseGraphOptions& options, int fixed) {
  const int n = static_cast<int>(poses.size());
  checkEdges(edges, n);
  PoseGraphResult result;
  const double k = options.huber_sigmas;
  result.initial_cost = result.final_cost = totalCost(poses, edges, k);
  if (n < 2 || edges.empty()) {
    result.converged = true;
    return result;
  }
  for (int it = 0; it < options.max_iterations; ++it) {
    Eigen::VectorXd b;
    const Eigen::SparseMatrix<double> H = normalEquations(poses, edges, k, fixed, b);
    Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver(H);
    if (solver.info() != Eigen::Success) {
      result.solved = false;
      break;
    }
    const Eigen::VectorXd dx = solver.solve(-b);
    if (solver.info() != Eigen::Success || !dx.allFinite()) {
      result.solved = false;
      break;
    }
    const std::vector<Pose2D> before = poses;
    double scale = 1.0;
    const double cost = applyStep(before, dx, edges, k, fixed, result.final_cost, poses, &scale);
    result.iterations = it + 1;
    if (cost > result.final_cost) {  // no step helps: the previous poses are the minimum we can reach
      poses = before;
      result.converged = true;
      break;
    }
    result.final_cost = cost;
    if (scale * dx.cwiseAbs().maxCoeff() < options.tolerance) {
      result.converged = true;
      break;
    }
  }
  return result;
}

}  // namespace laser_dpslam
