#include "laser_dpslam/sim/scan_simulator.h"

#include <limits>
#include <stdexcept>

namespace laser_dpslam {

void ScanSimulatorConfig::validate() const {
  auto bad = [](const std::string& what) { throw std::invalid_argument("ScanSimulatorConfig: " + what); };
  auto probability = [&](double p, const char* name) {
    if (!(p >= 0.0 && p <= 1.0)) bad(std::string(name) + " must be in [0, 1]");
  };
  if (beams < 1) bad("beams must be at least 1");
  if (!std::isfinite(angle_min) || !std::isfinite(angle_max) || (beams > 1 && !(angle_max > angle_min)))
    bad("need finite angle_min < angle_max");
  if (!(range_min >= 0.0) || !(range_max > range_min) || !std::isfinite(range_max))
    bad("need 0 <= range_min < range_max < inf");
  if (!(scan_rate > 0.0) || !std::isfinite(scan_rate)) bad("scan_rate must be positive");
  if (!(time_increment >= 0.0)) bad("time_increment must be >= 0");
  if (!(noise_min_stddev >= 0.0) || !(noise_range_fraction >= 0.0)) bad("noise must be >= 0");
  probability(dropout_probability, "dropout_probability");
  probability(grazing_dropout_probability, "grazing_dropout_probability");
  probability(outlier_probability, "outlier_probability");
  if (!(grazing_angle >= 0.0)) bad("grazing_angle must be >= 0");
  if (frame_id.empty()) bad("frame_id must not be empty");
}

ScanSimulator::ScanSimulator(const FloorPlan& plan, const ScanSimulatorConfig& config, std::uint64_t seed)
    : grid_(&plan), config_(config), rng_(seed) {
  config_.validate();
}

ScanSimulator::ScanSimulator(const VectorPlan& plan, const ScanSimulatorConfig& config, std::uint64_t seed)
    : geometry_(&plan), config_(config), rng_(seed) {
  config_.validate();
}

double ScanSimulator::uniform() { return static_cast<double>(rng_() >> 11) * 0x1.0p-53; }

double ScanSimulator::gaussian() {
  const double u1 = 1.0 - uniform();  // (0, 1]
  const double u2 = uniform();
  return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * M_PI * u2);
}

LaserScan ScanSimulator::simulate(const Pose2D& pose, double stamp) {
  const ScanSimulatorConfig& c = config_;
  constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
  constexpr float kInf = std::numeric_limits<float>::infinity();

  LaserScan scan;
  scan.stamp = stamp;
  scan.frame_id = c.frame_id;
  scan.angle_min = c.angle_min;
  scan.angle_max = c.beams > 1 ? c.angle_max : c.angle_min;
  scan.angle_increment = c.angleIncrement();
  scan.time_increment = c.time_increment;
  scan.scan_time = 1.0 / c.scan_rate;
  scan.range_min = c.range_min;
  scan.range_max = c.range_max;
  scan.ranges.resize(static_cast<std::size_t>(c.beams));

  const Eigen::Vector2d origin = pose.translation();
  const double cos_grazing = std::cos(c.grazing_angle);
  // Only the shapes within range can be hit: casting against those keeps a big building cheap.
  const VectorPlan local = geometry_ ? geometry_->near(origin, c.range_max) : VectorPlan();
  for (int i = 0; i < c.beams; ++i) {
    const double angle = pose.theta + c.angle_min + i * scan.angle_increment;
    double r = 0.0;
    // Incidence: cosine of the angle between the beam and the normal of the surface it hit.
    double cos_incidence = 1.0;
    if (grid_) {
      int axis = -1;
      r = grid_->raycast(origin, angle, c.range_max, &axis);
      cos_incidence = axis == 0 ? std::abs(std::cos(angle)) : (axis == 1 ? std::abs(std::sin(angle)) : 1.0);
    } else {
      r = local.raycast(origin, angle, c.range_max, &cos_incidence);
    }

    // Fixed number of draws per beam, whatever happens to it: keeps the stream aligned.
    const double u_drop = uniform();
    const double u_graze = uniform();
    const double u_outlier = uniform();
    const double u_outlier_range = uniform();
    const double g = gaussian();

    float out;
    if (u_drop < c.dropout_probability) {
      out = kNaN;
    } else if (!std::isfinite(r)) {
      out = kInf;
    } else {
      if (cos_incidence < cos_grazing && u_graze < c.grazing_dropout_probability) {
        out = kNaN;
      } else if (u_outlier < c.outlier_probability && r > c.range_min) {
        out = static_cast<float>(c.range_min + u_outlier_range * (r - c.range_min));
      } else {
        const double sigma = std::max(c.noise_min_stddev, c.noise_range_fraction * r);
        const double noisy = r + sigma * g;
        if (noisy > c.range_max) {
          out = kInf;
        } else if (noisy < c.range_min) {
          out = -kInf;
        } else {
          out = static_cast<float>(noisy);
        }
      }
    }
    scan.ranges[static_cast<std::size_t>(i)] = out;
  }
  return scan;
}

}  // namespace laser_dpslam
