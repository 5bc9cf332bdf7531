#include "laser_dpslam/odometry/odometry_parameters.h"

#include <stdexcept>
#include <string>

namespace laser_dpslam {

namespace {
using S = OdometryNodeSettings;
constexpr ParameterLevel kUser = ParameterLevel::kUser;
constexpr ParameterLevel kAdvanced = ParameterLevel::kAdvanced;
// The member a key reads into, as the registry's function pointer.
#define FIELD(member) +[](S& s) -> auto& { return s.member; }

ChoiceField<S> resamplingField() {
  return {[](const S& s) { return std::string(resamplingMethodName(s.odometry.resampling)); },
          [](S& s, const std::string& v) { s.odometry.resampling = parseResamplingMethod(v); },
          "none, every_kth, uniform, saliency"};
}

std::vector<Parameter<S>> frameScanAndLocalMapEntries() {
  return {
      // --- Frames and TF (the node's own) ---
      {"base_frame", "frames and TF", FIELD(base_frame), "frame", anyValue(),
       "robot frame the odometry moves (base_footprint on a Create if you prefer)", kUser},
      {"odom_frame", "frames and TF", FIELD(odom_frame), "frame", anyValue(),
       "parent of base_frame in the published TF and odom message", kUser},
      {"publish_tf", "frames and TF", FIELD(publish_tf), "bool", anyValue(), "broadcast odom_frame -> base_frame", kUser},
      {"transform_timeout", "frames and TF", FIELD(transform_timeout), "s", atLeast(0),
       "wait for the base -> laser TF at a scan's stamp", kAdvanced},
      {"use_wheel_odometry", "frames and TF", FIELD(use_wheel_odometry), "bool", anyValue(),
       "subscribe wheel_odom (nav_msgs/Odometry): the wheels' motion between scans replaces the constant-velocity "
       "prediction and carries the estimate where the scan sees nothing along a corridor; the scan decides where "
       "it constrains the motion (dpslam_offline --wheel-odom TOPIC does the same)",
       kUser},

      // --- Scan preprocessing (REP-117) ---
      {"min_range", "scan", FIELD(preprocessing.min_range), "m", atLeast(0),
       "beams shorter than max(this, the scan's range_min) are dropped", kUser},
      {"max_range", "scan", FIELD(preprocessing.max_range), "m", atLeast(0),
       "beams longer than min(this, the scan's range_max) are dropped; 0 = the scan's range_max", kUser},
      {"angle_min", "scan", FIELD(preprocessing.angle_min), "rad", anyValue(),
       "start of the angular window (beams outside it are ignored); -.inf = the whole scan; must be < angle_max", kUser},
      {"angle_max", "scan", FIELD(preprocessing.angle_max), "rad", anyValue(),
       "end of the angular window; .inf = the whole scan", kUser},
      {"min_points", "scan", FIELD(odometry.min_points), "points", atLeast(3),
       "fewer valid points: the scan is skipped, the pose propagated", kAdvanced},

      // --- Local map ---
      {"keyframe_distance", "local map", FIELD(odometry.keyframe_distance), "m", atLeast(0),
       "travel since the last keyframe before a new one joins the local map", kUser},
      {"local_map_keyframes", "local map", FIELD(odometry.local_map_keyframes), "keyframes", atLeast(1),
       "how many recent keyframes make the local map each scan is matched against (10 x 0.25 m; 5 drifted "
       "about twice as much on the loop building, see doc/benchmarks.md)",
       kUser},
      {"align_to_walls", "local map", FIELD(odometry.align_to_walls), "bool", anyValue(),
       "match in a frame turned to the first scan's dominant wall direction (modulo 90 deg, from chords between "
       "neighbouring points); outputs stay in the odom frame. Straight-walled buildings started off their walls "
       "gain (jittered loop building odometry ATE 0.092 against 0.187 m, demo 0.024 against 0.034 m), walls "
       "exactly on the lattice lose (0.21 against 0.095 m); the SLAM does not gain from it (jittered loop: 6 of 12 "
       "seeds lost with it, 5 without); doc/experiments.md, 2026-12-02",
       kUser},
      {"keyframe_angle", "local map", FIELD(odometry.keyframe_angle), "rad", atLeast(0),
       "rotation since the last keyframe before a new one joins", kAdvanced},
      {"keyframe_overlap_drop", "local map", FIELD(odometry.keyframe_overlap_drop), "-", atLeast(0),
       "also a new keyframe when the matched fraction fell this much since the keyframe's first match (new "
       "structure in view); 0 = off",
       kAdvanced},
      {"map_voxel", "local map", FIELD(odometry.map_voxel), "m", atLeast(0), "voxel filter of the local map's points",
       kAdvanced},
      {"wall_alignment_min_strength", "local map", FIELD(odometry.wall_alignment_min_strength), "-",
       closedInterval(0, 1),
       "align_to_walls only when the first scan's chords agree at least this much (1 = all along one direction or "
       "at 90 deg to it)",
       kAdvanced},
  };
}

std::vector<Parameter<S>> matchingEntries() {
  return {
      // --- Matching: resampling, NDT, Differential Evolution, Newton ---
      {"resampling", "matching", resamplingField(), "-", anyValue(), "how the DE search points are chosen", kUser},
      {"resampling_budget", "matching", FIELD(odometry.resampling_budget), "points", atLeast(3),
       "DE search points per scan: speed against robustness at turns", kUser},
      {"ndt_cell_sizes", "matching", FIELD(odometry.matcher.cell_sizes), "m", above(0),
       "NDT resolutions (Biber & Strasser: 4 overlapping grids each), coarse to fine; DE runs on the first", kUser},
      {"de_population", "matching", FIELD(odometry.matcher.de_population), "members", atLeast(4),
       "Differential Evolution population NP", kUser},
      {"de_generations", "matching", FIELD(odometry.matcher.de_generations), "generations", atLeast(0),
       "upper bound G of DE generations per scan", kUser},
      {"window_xy", "matching", FIELD(odometry.matcher.window_xy), "m", above(0),
       "half-width of the search window around the motion prior; a match adds at most sigma = w/sqrt(3) to the "
       "pose covariance (in translation at least degenerate_sigma; see doc/reliability.md)",
       kUser},
      {"window_theta", "matching", FIELD(odometry.matcher.window_theta), "rad", above(0),
       "half-width in heading of the search window (15 deg; bounds the heading sigma likewise, over "
       "rescue_window_theta when the rescue is on)",
       kUser},
      {"polish_budget", "matching", FIELD(odometry.polish_budget), "points", atLeast(0),
       "Newton polish points, spatially uniform; 0 = all valid points (300 is ~25 % faster but drifted 2.3 deg on "
       "the simulated loop test)",
       kAdvanced},
      {"seed", "matching", FIELD(odometry.seed), "-", atLeast(0),
       "seed of the DE random generator (same seed and input = same output)", kAdvanced},
      {"ndt_min_points", "matching", FIELD(odometry.matcher.ndt.min_points), "points", atLeast(3),
       "a cell needs this many points for a Gaussian (thesis value)", kAdvanced},
      {"ndt_eigen_ratio", "matching", FIELD(odometry.matcher.ndt.eigen_ratio), "-", above(0),
       "cell covariance eigenvalues raised to at least this x the largest (thesis value)", kAdvanced},
      {"ndt_point_sigma", "matching", FIELD(odometry.matcher.ndt.point_sigma), "m", atLeast(0),
       "a scan point's noise: each cell's term is scaled by det(I + sigma^2 Sigma^-1)^1/2 so that thin wall cells "
       "stop losing to fat corner cells (`ScanMatcher.PointSigmaRemovesTheCorridorPullTowardsCorners`); opt-in, as "
       "the running odometry does not gain yet (loop building ATE 0.093 m at 0.015 against 0.095 m); 0 = off",
       kAdvanced},
      {"use_de", "matching", FIELD(odometry.matcher.use_de), "bool", anyValue(),
       "false = Newton from the motion prior only", kAdvanced},
      {"de_CR", "matching", FIELD(odometry.matcher.de_CR), "-", closedInterval(0, 1), "DE crossover rate",
       kAdvanced},
      {"de_spread_xy", "matching", FIELD(odometry.matcher.de_spread_xy), "m", atLeast(0),
       "DE stops when the population spread is below this ...", kAdvanced},
      {"de_spread_theta", "matching", FIELD(odometry.matcher.de_spread_theta), "rad", atLeast(0), "... and this",
       kAdvanced},
      {"de_stall_generations", "matching", FIELD(odometry.matcher.de_stall_generations), "generations",
       atLeast(0), "DE stops after this many generations without improvement", kAdvanced},
      {"newton_iterations", "matching", FIELD(odometry.matcher.newton_iterations), "iterations", atLeast(0),
       "Newton polish steps per NDT resolution", kAdvanced},
      {"rescue_margin", "matching", FIELD(odometry.matcher.rescue_margin), "-", atLeast(0),
       "retry a weak match from the prior and by DE over +-rescue_window_theta; keep a retry scoring this much "
       "higher per point (turn failures, see doc/benchmarks.md); 0 = off",
       kAdvanced},
      {"rescue_window_theta", "matching", FIELD(odometry.matcher.rescue_window_theta), "rad", above(0),
       "half-width in heading of the retry's DE window (45 deg)", kAdvanced},
  };
}

std::vector<Parameter<S>> motionPriorEntries() {
  return {
      // --- Motion prior and corridors ---
      {"max_prior_gap", "motion prior", FIELD(odometry.max_prior_gap), "s", above(0),
       "a longer gap between scans resets the constant-velocity prior to zero", kAdvanced},
      {"prior_acceleration", "motion prior", FIELD(odometry.prior_acceleration), "m/s^2", atLeast(0),
       "the constant-velocity prior enters the Newton polish as a Gaussian with sigma = a dt^2/2 (holds the pose "
       "along corridors; when DE ends more than 3 sigma from the prior the polish also starts from the prior and "
       "the lower value wins); 0 = off",
       kAdvanced},
      {"degenerate_velocity_gain", "motion prior", FIELD(odometry.degenerate_velocity_gain), "-", atMost(1),
       "the prior velocity's smoothing gain (0.3 elsewhere) along the weak direction of a degenerate (corridor) "
       "match, before a match has fixed every direction (then the velocity is held); averages the NDT score's "
       "ripple over more scans so the estimate does not stall (CSAIL cut to 5.6 m: SLAM error -39 %); < 0 = 0.3",
       kAdvanced},
      {"degenerate_velocity_max_range", "motion prior", FIELD(odometry.degenerate_velocity_max_range), "m",
       atLeast(0),
       "range gate of the corridor rules (degenerate_velocity_gain, the hold of the velocity along a corridor, "
       "range_flow_gain): only for lasers whose range_max is at most this (URG-04LX 5.6 m gains, full-range CSAIL "
       "loses); 0 = any",
       kAdvanced},
      {"range_flow_gain", "motion prior", FIELD(odometry.range_flow_gain), "-", closedInterval(0, 1),
       "in a degenerate match with lines in view that face along the corridor (a niche, a door frame), the speed "
       "along it is also measured from their range changes since the previous scan (range flow, as rf2o); when "
       "two agreeing flows lie more than 3 sigma + 0.02 m/s from the velocity, it moves this fraction towards "
       "them: a stop or a start is seen (west corridor stop, seeds 1-3: 2.28, 0.78, 0.06 m off without, 0.03, "
       "0.02, 0.06 m with it; doc/tuning.md); 0 = off",
       kAdvanced},
      {"prior_release_speed", "motion prior", FIELD(odometry.prior_release_speed), "m/s", atLeast(0),
       "below this estimated speed a degenerate match held by the motion prior is polished again without it, and "
       "that pose taken when it fits clearly better (by 0.005 per point, 3 prior sigmas away): a robot starting "
       "from rest in a corridor is not left behind (loop building start: 0.6-1.2 m lost before, 0.04-0.12 m "
       "with it); 0 = off",
       kAdvanced},
  };
}

std::vector<Parameter<S>> covarianceEntries() {
  return {
      // --- Covariance ---
      {"covariance_scale", "covariance", FIELD(odometry.matcher.covariance_scale), "-", above(0),
       "alpha in Sigma = alpha H^-1 + Sigma_min", kAdvanced},
      {"min_sigma_xy", "covariance", FIELD(odometry.matcher.min_sigma_xy), "m", above(0),
       "floor of the translation standard deviation", kAdvanced},
      {"min_sigma_theta", "covariance", FIELD(odometry.matcher.min_sigma_theta), "rad", above(0),
       "floor of the rotation standard deviation", kAdvanced},
      {"degeneracy_ratio", "covariance", FIELD(odometry.matcher.degeneracy_ratio), "-", above(0),
       "a translation eigenvalue of H below this x the largest flags the match degenerate (corridor)", kAdvanced},
      {"degenerate_sigma", "covariance", FIELD(odometry.matcher.degenerate_sigma), "m", above(0),
       "standard deviation added along a degenerate direction", kAdvanced},
      {"degenerate_sigma_with_prior", "covariance", FIELD(odometry.matcher.degenerate_sigma_with_prior), "m",
       above(0),
       "the same when the soft motion prior held that direction (0.3 let the SLAM's particles random-walk along "
       "corridors)",
       kAdvanced},
      {"weak_score", "covariance", FIELD(odometry.matcher.weak_score), "-", atLeast(0),
       "score per point (0..1) below which a match is weak", kAdvanced},
      {"weak_matched_fraction", "covariance", FIELD(odometry.matcher.weak_matched_fraction), "-", atLeast(0),
       "fraction of points within 3 sigma of a cell below which a match is weak", kAdvanced},
      {"weak_inflation", "covariance", FIELD(odometry.matcher.weak_inflation), "-", above(0),
       "covariance multiplier for a weak match", kAdvanced},
  };
}

#undef FIELD

std::vector<Parameter<S>> makeRegistry() {
  std::vector<Parameter<S>> all;
  for (auto part : {frameScanAndLocalMapEntries, matchingEntries, motionPriorEntries, covarianceEntries}) {
    for (const Parameter<S>& p : part()) all.push_back(p);
  }
  return all;
}
}  // namespace

const std::vector<Parameter<S>>& odometryParameters() {
  static const std::vector<Parameter<S>> registry = makeRegistry();
  return registry;
}

void readOdometryNodeParameters(const ParameterSource& source, OdometryNodeSettings& settings) {
  readParameters(source, odometryParameters(), settings);
  const ScanPreprocessorConfig& p = settings.preprocessing;
  if (p.angle_min >= p.angle_max) {
    throw std::invalid_argument("parameter 'angle_min' = " + formatParameterNumber(p.angle_min) +
                                " must be < 'angle_max' = " + formatParameterNumber(p.angle_max));
  }
}

void readOdometryParameters(const ParameterSource& source, LaserOdometryConfig& odometry,
                            ScanPreprocessorConfig& preprocessing) {
  OdometryNodeSettings settings;
  settings.odometry = odometry;
  settings.preprocessing = preprocessing;
  readOdometryNodeParameters(source, settings);
  odometry = settings.odometry;
  preprocessing = settings.preprocessing;
}

}  // namespace laser_dpslam
