#include "laser_dpslam/sim/vector_plan.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <functional>
#include <fstream>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "laser_dpslam/sim/text_words.h"

namespace laser_dpslam {

namespace {

double cross(const Eigen::Vector2d& a, const Eigen::Vector2d& b) { return a.x() * b.y() - a.y() * b.x(); }

double distanceToSegment(const Eigen::Vector2d& p, const VectorPlan::Segment& s) {
  const Eigen::Vector2d e = s.b - s.a;
  const double t = std::clamp((p - s.a).dot(e) / e.squaredNorm(), 0.0, 1.0);
  return (s.a + t * e - p).norm();
}

bool insidePolygon(const Eigen::Vector2d& p, const std::vector<Eigen::Vector2d>& poly) {
  bool inside = false;  // even-odd rule
  for (std::size_t i = 0, j = poly.size() - 1; i < poly.size(); j = i++) {
    const Eigen::Vector2d& a = poly[i];
    const Eigen::Vector2d& b = poly[j];
    if ((a.y() > p.y()) != (b.y() > p.y()) && p.x() < (b.x() - a.x()) * (p.y() - a.y()) / (b.y() - a.y()) + a.x())
      inside = !inside;
  }
  return inside;
}

std::vector<double> parseNumbers(const std::vector<std::string>& words, const std::function<void(std::string)>& fail) {
  std::vector<double> v;
  for (std::size_t i = 1; i < words.size(); ++i) {
    const char* s = words[i].c_str();
    char* end = nullptr;
    errno = 0;
    const double x = std::strtod(s, &end);
    if (end == s || *end != '\0' || errno == ERANGE || !std::isfinite(x)) fail("'" + words[i] + "' is not a number");
    v.push_back(x);
  }
  return v;
}

}  // namespace

VectorPlan VectorPlan::load(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot open the plan file (missing or unreadable)");
  return parse(in, path);
}

VectorPlan VectorPlan::parse(std::istream& in, const std::string& name) {
  VectorPlan plan;
  plan.source_ = name;
  std::string line;
  int line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    const std::vector<std::string> words = lineWords(line);
    if (words.empty()) continue;
    const std::function<void(std::string)> fail = [&](const std::string& why) {
      throw std::runtime_error(name + ":" + std::to_string(line_no) + ": " + why +
                               " (expected `wall X1 Y1 X2 Y2 ...`, `polygon X1 Y1 X2 Y2 X3 Y3 ...` or `circle CX CY R`)");
    };
    const std::string& kind = words[0];
    if (kind != "wall" && kind != "polygon" && kind != "circle") fail("unknown shape '" + kind + "'");
    const std::vector<double> v = parseNumbers(words, fail);
    if (kind == "circle") {
      if (v.size() != 3) fail("a circle needs 3 numbers, found " + std::to_string(v.size()));
      if (!(v[2] > 0.0)) fail("a circle's radius must be > 0");
      plan.addCircle({v[0], v[1]}, v[2]);
      continue;
    }
    if (v.size() % 2 != 0) fail("odd number of coordinates (" + std::to_string(v.size()) + ")");
    std::vector<Eigen::Vector2d> pts;
    for (std::size_t i = 0; i < v.size(); i += 2) pts.emplace_back(v[i], v[i + 1]);
    const std::size_t need = kind == "wall" ? 2 : 3;
    if (pts.size() < need) fail("a " + kind + " needs at least " + std::to_string(need) + " points");
    for (std::size_t i = 0; i + 1 < pts.size(); ++i)
      if ((pts[i + 1] - pts[i]).norm() < 1e-9) fail("two consecutive points coincide");
    if (kind == "polygon") {
      plan.addPolygon(pts);
    } else {
      for (std::size_t i = 0; i + 1 < pts.size(); ++i) plan.addWall(pts[i], pts[i + 1]);
    }
  }
  if (in.bad()) throw std::runtime_error(name + ": read error");
  if (plan.empty()) throw std::runtime_error(name + ": the plan holds no wall, polygon or circle");
  return plan;
}

void VectorPlan::addWall(const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  if (!a.allFinite() || !b.allFinite() || (b - a).norm() < 1e-9)
    throw std::invalid_argument("VectorPlan::addWall: need two distinct finite points");
  segments_.push_back({a, b});
}

void VectorPlan::addPolygon(const std::vector<Eigen::Vector2d>& vertices) {
  if (vertices.size() < 3) throw std::invalid_argument("VectorPlan::addPolygon: need at least 3 vertices");
  for (std::size_t i = 0; i < vertices.size(); ++i) {
    const Eigen::Vector2d& b = vertices[(i + 1) % vertices.size()];
    if ((b - vertices[i]).norm() >= 1e-9) addWall(vertices[i], b);
  }
  polygons_.push_back(vertices);
}

void VectorPlan::addCircle(const Eigen::Vector2d& centre, double radius) {
  if (!centre.allFinite() || !(radius > 0.0) || !std::isfinite(radius))
    throw std::invalid_argument("VectorPlan::addCircle: need a finite centre and radius > 0");
  circles_.push_back({centre, radius});
}

bool VectorPlan::insideSolid(const Eigen::Vector2d& p) const {
  for (const Circle& c : circles_)
    if ((p - c.centre).norm() <= c.radius) return true;
  for (const auto& poly : polygons_)
    if (insidePolygon(p, poly)) return true;
  return false;
}

double VectorPlan::clearance(const Eigen::Vector2d& p, double max_radius) const {
  if (insideSolid(p)) return 0.0;
  double best = max_radius;
  for (const Segment& s : segments_) best = std::min(best, distanceToSegment(p, s));
  for (const Circle& c : circles_) best = std::min(best, std::max(0.0, (p - c.centre).norm() - c.radius));
  return best;
}

double VectorPlan::raycast(const Eigen::Vector2d& from, double angle, double max_range, double* cos_incidence) const {
  if (cos_incidence) *cos_incidence = 1.0;
  if (insideSolid(from)) return 0.0;
  const Eigen::Vector2d d(std::cos(angle), std::sin(angle));
  double best = std::numeric_limits<double>::infinity();
  double best_cos = 1.0;
  for (const Segment& s : segments_) {
    const Eigen::Vector2d e = s.b - s.a;
    const double denom = cross(d, e);
    if (std::abs(denom) < 1e-15) continue;  // parallel: a beam along a wall does not hit its face
    const Eigen::Vector2d f = s.a - from;
    const double t = cross(f, e) / denom;
    const double u = cross(f, d) / denom;
    if (t < 0.0 || u < 0.0 || u > 1.0 || t >= best) continue;
    best = t;
    best_cos = std::abs(denom) / e.norm();
  }
  for (const Circle& c : circles_) {
    const Eigen::Vector2d f = from - c.centre;
    const double b = f.dot(d);
    const double disc = b * b - (f.squaredNorm() - c.radius * c.radius);
    if (disc < 0.0) continue;
    const double t = -b - std::sqrt(disc);  // the near intersection; `from` is outside (checked above)
    if (t < 0.0 || t >= best) continue;
    best = t;
    best_cos = std::abs((f + t * d).dot(d)) / c.radius;
  }
  if (!(best <= max_range)) return std::numeric_limits<double>::infinity();
  if (cos_incidence) *cos_incidence = best_cos;
  return best;
}

VectorPlan VectorPlan::near(const Eigen::Vector2d& p, double radius) const {
  VectorPlan out;
  out.source_ = source_;
  for (const Segment& s : segments_)
    if (distanceToSegment(p, s) <= radius) out.segments_.push_back(s);
  for (const Circle& c : circles_)
    if ((p - c.centre).norm() - c.radius <= radius) out.circles_.push_back(c);
  // Polygons only matter for insideSolid(); their near edges are already among the segments.
  for (const auto& poly : polygons_)
    if (insidePolygon(p, poly)) out.polygons_.push_back(poly);
  return out;
}

}  // namespace laser_dpslam
