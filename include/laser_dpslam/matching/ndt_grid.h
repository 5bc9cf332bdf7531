// Normal Distributions Transform of a 2D point set (Biber & Straßer, IROS 2003): four overlapping
// L×L grids shifted by L/2, a Gaussian per cell with ≥ min_points points, and the score h with its
// analytic gradient and Hessian (doc/algorithms.md §2).
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstddef>
#include <vector>

#include "laser_dpslam/common/pose2d.h"

namespace laser_dpslam {

struct NdtGridConfig {
  double cell_size = 0.5;      ///< m, side L of a cell
  int min_points = 3;          ///< a cell needs this many points to get a Gaussian (thesis: 3)
  double eigen_ratio = 0.001;  ///< smallest covariance eigenvalue is raised to this × the largest
  double min_eigen = 1e-5;     ///< m², absolute floor of the eigenvalues (a perfectly straight wall)
  double point_sigma = 0.0;    ///< m, noise of a matched point; each cell's term is scaled so that such a point at
                               ///< its true place scores the same on average in a thin (wall) and a fat (corner)
                               ///< cell; 0 = off (the plain Biber score)
};

/// Where the reference's points were seen from: the laser's position and its maximum range. A wall's
/// returns end where the range ends, not where the wall does; a cell that reaches past every view's range
/// holds only part of its wall (see NdtGrid::build).
struct NdtView {
  Eigen::Vector2d origin = Eigen::Vector2d::Zero();
  double range = 0.0;  ///< m
};

/// One Gaussian of the NDT. The inverse covariance is precomputed: it is what the score needs.
struct NdtCell {
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  Eigen::Matrix2d covariance = Eigen::Matrix2d::Zero();
  Eigen::Matrix2d information = Eigen::Matrix2d::Zero();
  double weight = 1.0;  ///< scale of this cell's exp() term (NdtGridConfig::point_sigma)
  int count = 0;
  bool valid = false;
  bool truncated = false;  ///< a line cell cut by the views' range: no information along its line
};

/// Score of a moved point set. h is minimised (h = −Σ_i Σ_grids exp(−½ qᵀΣ⁻¹q)).
struct NdtScore {
  double h = 0.0;
  Eigen::Vector3d gradient = Eigen::Vector3d::Zero();
  Eigen::Matrix3d hessian = Eigen::Matrix3d::Zero();
  int matched = 0;  ///< points with at least one cell within 3σ (Mahalanobis² < 9)
};

/// The score's terms at one pose: h, and per scan point the Gaussians within reach with what their
/// derivatives need. The Newton polish rejects two in five of the steps it tries (a step that overshoots,
/// or crosses cell borders where h jumps), so it takes h first and the derivatives only where it moves.
struct NdtTerms {
  struct Term {
    // Built in place (emplace_back): a Term assembled on the stack and copied stalled the loop on store
    // forwarding (the copy's 16-byte loads span the fields' separate stores).
    Term(const NdtCell* c, double e_, double x, double y, int p) : cell(c), e(e_), iqx(x), iqy(y), point(p) {}
    const NdtCell* cell;
    double e;         ///< weight · exp(−½ qᵀΣ⁻¹q)
    double iqx, iqy;  ///< Σ⁻¹q
    int point;        ///< index into the scan's points
  };
  Pose2D pose;
  double h = 0.0;
  int matched = 0;
  std::vector<Term> terms;  ///< in point order, then layer order
};

class NdtGrid {
 public:
  NdtGrid() = default;
  NdtGrid(const std::vector<Eigen::Vector2d>& points, const NdtGridConfig& config,
          const std::vector<NdtView>& views = {}) {
    build(points, config, views);
  }

  /// Rebuilds the four grids over the bounding box of `points`. With `views`, a line-like cell that no
  /// view saw whole (a corner of the cell beyond every view's range) keeps its Gaussian across the line
  /// only: its points end where the range did, so their mean is not the wall's, and a scan seen from
  /// farther along would be pulled back towards it (along a corridor, a few mm per scan).
  void build(const std::vector<Eigen::Vector2d>& points, const NdtGridConfig& config,
             const std::vector<NdtView>& views = {});

  /// h at `pose` for `points` given in the moving frame; gradient and Hessian w.r.t. (x, y, θ) when
  /// `derivatives` is set (Jacobian at the scan-frame point, doc/algorithms.md §2).
  NdtScore score(const Pose2D& pose, const std::vector<Eigen::Vector2d>& points, bool derivatives) const;

  /// The two halves of score(): h at `pose` with the terms kept (their storage is reused), then the
  /// gradient and Hessian from them. Together they give exactly what score() gives.
  void evaluate(const Pose2D& pose, const std::vector<Eigen::Vector2d>& points, NdtTerms* terms) const;
  NdtScore derivatives(const std::vector<Eigen::Vector2d>& points, const NdtTerms& terms) const;

  /// Σ over the four grids of exp(−½ qᵀΣ⁻¹q) for one point in the grid's frame (0 … 4).
  double density(const Eigen::Vector2d& p) const;

  double cellSize() const { return config_.cell_size; }
  std::size_t validCells() const { return valid_cells_; }
  bool empty() const { return valid_cells_ == 0; }

  /// Layer k (0..3) is shifted by (k&1, k>>1)·L/2. For tests and the score raster.
  struct Layer {
    Eigen::Vector2d origin = Eigen::Vector2d::Zero();  ///< corner of cell (0, 0)
    int nx = 0, ny = 0;
    std::vector<NdtCell> cells;                        ///< row-major, index = iy·nx + ix
    const NdtCell* cellAt(const Eigen::Vector2d& p, double inv_size) const;
  };
  const std::array<Layer, 4>& layers() const { return layers_; }

 private:
  NdtGridConfig config_;
  std::array<Layer, 4> layers_;
  std::size_t valid_cells_ = 0;
};

inline const NdtCell* NdtGrid::Layer::cellAt(const Eigen::Vector2d& p, double inv_size) const {
  const double fx = (p.x() - origin.x()) * inv_size;
  const double fy = (p.y() - origin.y()) * inv_size;
  if (!(fx >= 0.0 && fy >= 0.0)) return nullptr;  // also rejects NaN
  const int ix = static_cast<int>(fx), iy = static_cast<int>(fy);
  if (ix >= nx || iy >= ny) return nullptr;
  const NdtCell& c = cells[static_cast<std::size_t>(iy) * nx + ix];
  return c.valid ? &c : nullptr;
}

}  // namespace laser_dpslam
