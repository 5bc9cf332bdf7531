// A floor plan made of geometry (wall segments, solid polygons, round pillars), for the laser simulator:
// walls at any angle and position, not on a raster's lattice, ray-cast exactly. No ROS.
#pragma once

#include <Eigen/Core>
#include <istream>
#include <string>
#include <vector>

namespace laser_dpslam {

/// The plan file format (text, metres, map frame; `#` starts a comment; one shape per line):
///   wall X1 Y1 X2 Y2 [X3 Y3 ...]      a polyline of thin walls (seen from both sides)
///   polygon X1 Y1 X2 Y2 X3 Y3 [...]   a solid closed obstacle (furniture, a wall block); edges are walls
///   circle CX CY R                     a solid round obstacle (a pillar), R > 0
/// A thin wall blocks beams and the robot but has no inside; polygons and circles are solid, so a point
/// inside one has no clearance and a beam starting there returns 0.
class VectorPlan {
 public:
  struct Segment {
    Eigen::Vector2d a, b;
  };
  struct Circle {
    Eigen::Vector2d centre;
    double radius;
  };

  /// Reads a plan file. Throws std::runtime_error naming the file and line for a malformed line (unknown
  /// keyword, odd or too few coordinates, a non-number, a zero-length wall, R <= 0), and for a missing file
  /// or one without any shape.
  static VectorPlan load(const std::string& path);
  /// As load(), from a stream; `name` is used in the messages.
  static VectorPlan parse(std::istream& in, const std::string& name);

  void addWall(const Eigen::Vector2d& a, const Eigen::Vector2d& b);
  void addPolygon(const std::vector<Eigen::Vector2d>& vertices);  ///< ≥ 3 vertices, closed implicitly
  void addCircle(const Eigen::Vector2d& centre, double radius);

  const std::vector<Segment>& segments() const { return segments_; }  ///< walls and polygon edges
  const std::vector<Circle>& circles() const { return circles_; }
  bool empty() const { return segments_.empty() && circles_.empty(); }
  const std::string& source() const { return source_; }

  /// Whether `p` lies inside a solid shape (a polygon or a circle).
  bool insideSolid(const Eigen::Vector2d& p) const;

  /// Distance [m] from `p` to the nearest wall, polygon or circle, searched up to `max_radius` (returns
  /// max_radius when nothing is that close); 0 inside a solid shape.
  double clearance(const Eigen::Vector2d& p, double max_radius) const;

  /// Distance [m] along the ray from `from` at heading `angle` [rad] to the first shape it meets, or +inf
  /// when none lies within `max_range`; 0 when `from` is inside a solid shape. `cos_incidence` (optional)
  /// receives |cos| of the angle between the beam and the surface normal where it hit (1 when nothing hit).
  double raycast(const Eigen::Vector2d& from, double angle, double max_range, double* cos_incidence = nullptr) const;

  /// The shapes that come within `radius` of `p` (for fast ray casting from around p: the scan simulator
  /// casts ~700 beams from one point).
  VectorPlan near(const Eigen::Vector2d& p, double radius) const;

 private:
  std::vector<Segment> segments_;
  std::vector<std::vector<Eigen::Vector2d>> polygons_;
  std::vector<Circle> circles_;
  std::string source_;
};

}  // namespace laser_dpslam
