#include "laser_dpslam/odometry/range_flow.h"

#include <algorithm>
#include <cmath>
#include <vector>

namespace laser_dpslam {

namespace {

// One beam of the previous scan: its surface (a line n·x = n·c, base frame) and direction (laser frame).
struct FlowBeam {
  Eigen::Vector2d normal, centre, laser_dir;
  double observed = 0.0;  ///< the current scan's range on the same beam
  double sigma = 0.0;     ///< m, noise of observed minus predicted
  double r0 = 0.0, d = 0.0;  ///< predicted range with no motion along the direction, and its change per reference step
};

// Range along a beam after the robot moved by `m` (previous base frame) to the line n·x = n·c; < 0: none.
double predictedRange(const FlowBeam& b, const LaserMount& mount, const Pose2D& m, double min_cos) {
  const Eigen::Vector2d origin = m.translation() + m.rotation() * mount.t;
  const Eigen::Vector2d dir = m.rotation() * (mount.A * b.laser_dir);
  const double denom = b.normal.dot(dir);
  if (std::abs(denom) < min_cos) return -1.0;  // oblique: an error in the fitted normal matters more there
  const double r = b.normal.dot(b.centre - origin) / denom;
  return r > 0.0 ? r : -1.0;
}

// The line through return i of `scan` (laser frame), from the returns within `half_window` beams and `radius`
// m of it that lie within `gate` m of it: a plain fit of them all leans towards a corner's other surface by
// several degrees. False when fewer than 5 returns remain, return i is not among them or has fewer than
// `min_side` of them on either side (a corner), or the noise leaves the normal worse than `max_normal_error` rad.
bool fitLine(const PreprocessedScan& scan, std::size_t i, int half_window, double radius, double noise, double gate,
             double max_normal_error, int min_side, Eigen::Vector2d* normal, Eigen::Vector2d* centre) {
  const std::size_t n = scan.points.size();
  const std::size_t lo = i >= static_cast<std::size_t>(half_window) ? i - half_window : 0;
  const std::size_t hi = std::min(n - 1, i + half_window);
  const Eigen::Vector2d& p = scan.points[i];
  std::vector<Eigen::Vector2d> pts;
  std::vector<int> side;  // -1 / +1: a beam before / after return i
  for (std::size_t j = lo; j <= hi; ++j) {
    if (j == i || std::abs(scan.beams[j] - scan.beams[i]) > half_window) continue;
    const Eigen::Vector2d q = scan.points[j] - p;  // relative to p: better conditioned
    if (q.squaredNorm() <= radius * radius) {
      pts.push_back(q);
      side.push_back(j < i ? -1 : 1);
    }
  }
  pts.push_back(Eigen::Vector2d::Zero());
  side.push_back(0);
  // The line through return i with the most returns within `gate` of it (candidate directions: towards each
  // neighbour at least 5 cm away), then the least-squares line of those.
  Eigen::Vector2d nrm = Eigen::Vector2d::Zero();
  std::size_t best = 0;
  for (const Eigen::Vector2d& q : pts) {
    if (q.squaredNorm() < 0.05 * 0.05) continue;
    const Eigen::Vector2d cand = Eigen::Vector2d(-q.y(), q.x()).normalized();
    std::size_t inliers = 0;
    for (const Eigen::Vector2d& r : pts) inliers += std::abs(cand.dot(r)) <= gate ? 1 : 0;
    if (inliers > best) {
      best = inliers;
      nrm = cand;
    }
  }
  if (best < 5) return false;
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  double along = 0.0;
  std::size_t count = 0;
  for (int iter = 0; iter < 2; ++iter) {
    Eigen::Vector2d sum = Eigen::Vector2d::Zero();
    Eigen::Matrix2d sum2 = Eigen::Matrix2d::Zero();
    count = 0;
    for (const Eigen::Vector2d& q : pts) {
      if (std::abs(nrm.dot(q - mean)) > gate) continue;
      sum += q;
      sum2 += q * q.transpose();
      ++count;
    }
    if (count < 5) return false;
    mean = sum / static_cast<double>(count);
    const Eigen::Matrix2d cov = sum2 / static_cast<double>(count) - mean * mean.transpose();
    const double phi = 0.5 * std::atan2(2.0 * cov(0, 1), cov(0, 0) - cov(1, 1));
    const Eigen::Vector2d axis(std::cos(phi), std::sin(phi));
    nrm = Eigen::Vector2d(-axis.y(), axis.x());
    along = std::sqrt(std::max(0.0, axis.dot(cov * axis)));
  }
  if (std::abs(nrm.dot(-mean)) > gate) return false;  // the return itself is off its line
  // Inside a stretch of that line, not at its end: at a corner the fit leans towards the other surface.
  int before = 0, after = 0;
  for (std::size_t k = 0; k < pts.size(); ++k) {
    if (std::abs(nrm.dot(pts[k] - mean)) > gate) continue;
    before += side[k] < 0 ? 1 : 0;
    after += side[k] > 0 ? 1 : 0;
  }
  if (before < min_side || after < min_side) return false;
  if (!(noise < max_normal_error * along * std::sqrt(static_cast<double>(count)))) return false;
  *normal = nrm;
  *centre = p + mean;
  return true;
}

}  // namespace

RangeFlow measureRangeFlow(const PreprocessedScan& previous, const PreprocessedScan& current, const LaserMount& mount,
                           const Pose2D& motion, const Eigen::Vector2d& direction, double dt,
                           const RangeFlowConfig& config) {
  RangeFlow out;
  if (!(dt > 0.0) || !previous.ok() || !current.ok() || previous.counts.total != current.counts.total ||
      previous.points.empty() || current.points.empty() || !(direction.norm() > 0.5) || !motion.vector().allFinite()) {
    return out;
  }
  const Eigen::Vector2d w = direction.normalized();
  // The motion with nothing along w, and with one reference step along it.
  const Eigen::Vector2d across = motion.translation() - w * w.dot(motion.translation());
  const Pose2D m0(across.x(), across.y(), motion.theta);
  const Pose2D m1(across.x() + config.reference_step * w.x(), across.y() + config.reference_step * w.y(), motion.theta);

  // The current scan's range per beam index.
  std::vector<double> range_of(current.counts.total, -1.0);
  std::vector<double> angle_of(current.counts.total, 0.0);
  for (std::size_t j = 0; j < current.points.size(); ++j) {
    const int k = current.beams[j];
    if (k < 0 || static_cast<std::size_t>(k) >= range_of.size()) return out;
    range_of[k] = current.ranges[j];
    angle_of[k] = current.angles[j];
  }
  std::vector<FlowBeam> beams;
  for (std::size_t i = 0; i < previous.points.size(); ++i) {
    const int k = previous.beams[i];
    if (k < 0 || static_cast<std::size_t>(k) >= range_of.size() || range_of[k] < 0.0) continue;
    if (std::abs(angle_of[k] - previous.angles[i]) > 1e-6) return out;  // another beam layout
    const double noise = std::max(config.range_noise, config.range_noise_fraction * previous.ranges[i]);
    Eigen::Vector2d normal, centre;
    if (!fitLine(previous, i, config.fit_half_window, config.fit_radius, noise, 2.5 * noise, config.max_normal_error,
                 config.fit_min_side, &normal, &centre)) {
      continue;
    }
    FlowBeam b;
    b.normal = mount.A * normal;
    b.centre = mount.apply(centre);
    b.laser_dir = Eigen::Vector2d(std::cos(previous.angles[i]), std::sin(previous.angles[i]));
    b.observed = range_of[k];
    const double r0 = predictedRange(b, mount, m0, config.min_cos), r1 = predictedRange(b, mount, m1, config.min_cos);
    if (r0 < 0.0 || r1 < 0.0 || std::max(r0, r1) > current.range_max) continue;
    b.r0 = r0;
    b.d = r1 - r0;
    if (std::abs(b.d) < config.min_sensitivity * config.reference_step) continue;
    // The observed range's noise; the fitted line's is smaller (several returns), counted once more in part.
    b.sigma = 1.2 * std::max(config.range_noise, config.range_noise_fraction * b.observed);
    beams.push_back(b);
  }
  // Weighted least squares of observed − r0 = s·d, then again without the beams more than 3σ off (another
  // surface came into view, an edge): s is the motion along w in reference steps.
  double s = 0.0, info = 0.0;
  int used = 0;
  for (int pass = 0; pass < 2; ++pass) {
    double num = 0.0, den = 0.0;
    int n = 0;
    for (const FlowBeam& b : beams) {
      const double e = b.observed - b.r0;
      // First pass: only what a motion between −2 and +3 reference steps could explain, plus noise.
      const bool keep = pass == 0 ? (e - 0.5 * b.d) * (e - 0.5 * b.d) <= (2.5 * b.d) * (2.5 * b.d) + 9.0 * b.sigma * b.sigma
                                  : std::abs(e - s * b.d) <= 3.0 * b.sigma;
      if (!keep) continue;
      const double wt = 1.0 / (b.sigma * b.sigma);
      num += wt * b.d * e;
      den += wt * b.d * b.d;
      ++n;
    }
    if (n < config.min_beams || !(den > 0.0)) return out;
    s = num / den;
    info = den;
    used = n;
  }
  const double sigma_s = 1.0 / std::sqrt(info);
  if (!(sigma_s <= config.max_sigma) || !std::isfinite(s)) return out;
  out.valid = true;
  out.speed = s * config.reference_step / dt;
  out.sigma = sigma_s * config.reference_step / dt;
  out.beams = used;
  return out;
}

}  // namespace laser_dpslam
