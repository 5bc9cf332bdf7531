// A floor plan in the map_server format (PGM + YAML), for the laser simulator: occupancy look-up and
// exact ray casting against the occupied cells. No ROS.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

namespace laser_dpslam {

/// Occupancy grid of a floor plan. Cell (ix, iy) covers
/// [origin.x + ix·res, origin.x + (ix+1)·res) × [origin.y + iy·res, origin.y + (iy+1)·res):
/// iy = 0 is the BOTTOM row (smallest y), as in nav_msgs/OccupancyGrid. In the PGM image, row 0 is the
/// TOP (largest y), as in map_server; load() and save() flip the rows.
/// Everything outside the grid is free (not occupied) and unknown.
class FloorPlan {
 public:
  enum Cell : std::uint8_t { kFree = 0, kOccupied = 1, kUnknown = 2 };

  FloorPlan() = default;

  /// Loads a map_server YAML (keys: image, resolution, origin [x, y, yaw]; optional negate (default 0),
  /// occupied_thresh (0.65), free_thresh (0.196); `mode` trinary or scale, raw is rejected) and its 8-bit
  /// grey PGM image (P5 binary or P2 ascii; a relative image path is relative to the YAML's directory).
  /// Classification is map_server's: p = (255 − v)/255 (v/255 with negate); p > occupied_thresh →
  /// occupied, p < free_thresh → free, else unknown. The origin's yaw must be 0.
  /// Throws std::runtime_error naming the file on a missing or malformed YAML or image.
  static FloorPlan load(const std::string& yaml_path);

  /// A plan from a bare occupancy array for tests: occupied[iy * width + ix] != 0 means occupied,
  /// with iy = 0 the bottom row (see the class comment); every other cell is free.
  /// Throws std::invalid_argument if the sizes do not match or resolution ≤ 0.
  static FloorPlan fromOccupancy(int width, int height, double resolution, Eigen::Vector2d origin,
                                 std::vector<std::uint8_t> occupied);

  /// Writes YAML_PATH and the PGM next to it (same stem, .pgm): occupied 0, free 254, unknown 205,
  /// negate 0, occupied_thresh 0.65, free_thresh 0.196. Throws std::runtime_error on I/O failure.
  void save(const std::string& yaml_path) const;

  int width() const { return width_; }              ///< cells
  int height() const { return height_; }            ///< cells
  double resolution() const { return resolution_; }  ///< m per cell
  const Eigen::Vector2d& origin() const { return origin_; }  ///< m, map-frame corner of cell (0, 0)
  const std::string& source() const { return source_; }      ///< YAML path it was loaded from, if any

  /// Cell state; outside the grid: kUnknown.
  Cell cell(int ix, int iy) const;
  bool cellOccupied(int ix, int iy) const { return cell(ix, iy) == kOccupied; }

  /// Whether the map-frame point (x, y) [m] lies in an occupied cell (false outside the grid).
  bool occupied(double x, double y) const;
  /// Whether (x, y) [m] lies in a free cell (false outside the grid and in unknown cells).
  bool isFree(double x, double y) const;

  /// Distance [m] from `p` to the nearest occupied cell (to its box, not its centre), searched up to
  /// `max_radius`; returns max_radius when none is that close. 0 inside an occupied cell.
  double clearance(const Eigen::Vector2d& p, double max_radius) const;

  /// Exact grid traversal (Amanatides & Woo 1987) from `from` [m, map frame] along heading `angle`
  /// [rad]: the distance [m] to the boundary of the first occupied cell the ray enters (0 if `from`
  /// lies in one), or +inf when no occupied cell is entered within `max_range` [m]. Walls are the
  /// axis-aligned cell boxes, so the distance is exact (not quantised to the resolution).
  double raycast(const Eigen::Vector2d& from, double angle, double max_range) const;

  /// As raycast(), also reporting which face was hit: hit_axis 0 = a face normal to x (vertical
  /// wall), 1 = normal to y; -1 if nothing was hit or `from` is inside an occupied cell.
  double raycast(const Eigen::Vector2d& from, double angle, double max_range, int* hit_axis) const;

 private:
  int width_ = 0;
  int height_ = 0;
  double resolution_ = 0.05;
  Eigen::Vector2d origin_ = Eigen::Vector2d::Zero();
  std::vector<std::uint8_t> cells_;  ///< Cell values, index iy * width + ix, iy = 0 at the bottom
  std::string source_;
};

}  // namespace laser_dpslam
