#include "laser_dpslam/slam/dpslam_parameters.h"

#include <stdexcept>
#include <string>

namespace laser_dpslam {

namespace {
using S = DpSlamNodeSettings;
constexpr ParameterLevel kUser = ParameterLevel::kUser;
constexpr ParameterLevel kAdvanced = ParameterLevel::kAdvanced;
// The member a key reads into, as the registry's function pointer.
#define FIELD(member) +[](S& s) -> auto& { return s.member; }

std::vector<Parameter<S>> nodeAndScanEntries() {
  return {
      // --- Frames, TF and publishing (the node's own) ---
      {"map_frame", "frames and TF", FIELD(map_frame), "frame", anyValue(), "fixed frame of the map and the pose",
       kUser},
      {"odom_frame", "frames and TF", FIELD(odom_frame), "frame", anyValue(),
       "the odometry's frame (map -> odom is published)", kUser},
      {"base_frame", "frames and TF", FIELD(base_frame), "frame", anyValue(),
       "robot frame (base_footprint on a Create if you prefer)", kUser},
      {"transform_timeout", "frames and TF", FIELD(transform_timeout), "s", atLeast(0),
       "wait for the odom -> base TF at a scan's stamp", kAdvanced},
      {"map_update_interval", "publishing", FIELD(map_update_interval), "s", atLeast(0),
       "data time between map / map_metadata / trajectory publications", kUser},
      {"publish_particles", "publishing", FIELD(publish_particles), "bool", anyValue(),
       "publish the particles as a PoseArray on `particles`", kUser},

      // --- Scan ---
      {"min_range", "scan", FIELD(preprocessing.min_range), "m", atLeast(0),
       "beams shorter than max(this, the scan's range_min) are dropped", kUser},
      {"max_range", "scan", FIELD(preprocessing.max_range), "m", atLeast(0),
       "beams longer than this are dropped; 0 = the scan's range_max", kUser},
      {"slam_min_points", "scan", FIELD(slam.min_points), "points", atLeast(1),
       "a scan with fewer valid returns is not used (particles still move)", kAdvanced},
  };
}

std::vector<Parameter<S>> filterEntries() {
  return {
      // --- Particle filter ---
      {"particles", "particle filter", FIELD(slam.particles), "particles", closedInterval(1, 10000),
       "P: accuracy and loop closing against CPU; the ancestry tree holds at most 2P-1 nodes between updates "
       "(3P-1 during one; node IDs fit 16 bits)",
       kUser},
      {"oversampling", "particle filter", FIELD(slam.oversampling), "candidates/particle", atLeast(1),
       "poses drawn per particle, the best by the cheap score kept (4: no lost loop in the loop building, +30-45 % "
       "CPU); 1 = off",
       kUser},
      {"min_travel_distance", "particle filter", FIELD(slam.min_travel_distance), "m", atLeast(0),
       "the filter updates once the robot moved this far since its last update ...", kUser},
      {"min_travel_angle", "particle filter", FIELD(slam.min_travel_angle), "rad", atLeast(0),
       "... or turned this much (each 0 = off; both 0 = at every scan)", kUser},
      {"cull_window", "particle filter", FIELD(slam.cull_window), "m", above(0),
       "half-width around each measured range traced by the cheap (culling) score", kAdvanced},
      {"resample_threshold", "particle filter", FIELD(slam.resample_threshold), "-", closedInterval(0, 1),
       "resample when Neff < this x P (1 = at every update)", kAdvanced},
      {"proposal_covariance_scale", "particle filter", FIELD(slam.proposal.covariance_scale), "-", atLeast(0),
       "multiplies the scan matcher's delta covariance before sampling the proposal", kAdvanced},
      {"proposal_min_sigma_xy", "particle filter", FIELD(slam.proposal.min_sigma_xy), "m", atLeast(0),
       "standard deviation always added to the delta's x and y", kAdvanced},
      {"proposal_min_sigma_theta", "particle filter", FIELD(slam.proposal.min_sigma_theta), "rad", atLeast(0),
       "standard deviation always added to the delta's rotation", kAdvanced},
      {"proposal_sigma_xy_per_m", "particle filter", FIELD(slam.proposal.sigma_xy_per_m), "m/m", atLeast(0),
       "translation standard deviation added per metre travelled", kAdvanced},
      {"proposal_sigma_theta_per_rad", "particle filter", FIELD(slam.proposal.sigma_theta_per_rad), "rad/rad",
       atLeast(0), "rotation standard deviation added per radian turned", kAdvanced},
      {"proposal_max_sigma_xy", "particle filter", FIELD(slam.proposal.max_sigma_xy), "m", above(0),
       "cap of the scan matcher's translation standard deviation (failed matches)", kAdvanced},
      {"proposal_max_sigma_theta", "particle filter", FIELD(slam.proposal.max_sigma_theta), "rad", above(0),
       "cap of the scan matcher's rotation standard deviation", kAdvanced},
      {"use_wheel_odometry", "particle filter", FIELD(slam.proposal.bounded_by_wheels), "bool", anyValue(),
       "the laser odometry fuses the wheels (its own use_wheel_odometry): the particles then never spread beyond "
       "the wheels' error, floors included (dpslam_offline --wheel-odom TOPIC sets it)",
       kUser},
      {"explore_noise_scale", "particle filter", FIELD(slam.explore_noise_scale), "-", leftOpenInterval(0, 1),
       "proposal noise multiplier while exploring (no old path of the filter within revisit_radius); 1 = off",
       kAdvanced},
      {"revisit_radius", "particle filter", FIELD(slam.revisit_radius), "m", above(0),
       "the robot is on old ground when its path passed within this ...", kAdvanced},
      {"revisit_min_travel", "particle filter", FIELD(slam.revisit_min_travel), "m", atLeast(0),
       "... at least this much travel ago", kAdvanced},
      {"revisit_freeze_map", "particle filter", FIELD(slam.revisit_freeze_map), "bool", anyValue(),
       "on old ground scans write only cells the particle has no entry for: a particle arriving off the old map "
       "cannot overwrite it with its offset view, which made the filter turn instead of closing (jittered loop "
       "building: 1 loop of 12 lost instead of 5); false = update everywhere, as DP-SLAM does",
       kAdvanced},
  };
}

std::vector<Parameter<S>> mapEntries() {
  return {
      // --- Map (DP-SLAM 2.0 laser-penetration grid, shared by all particles) ---
      {"map_resolution", "map", FIELD(slam.map_resolution), "m", above(0), "cell size (the original used 0.0286)",
       kUser},
      {"align_to_walls", "map", FIELD(slam.map_align_to_walls), "bool", anyValue(),
       "the map frame's axes run along the first scan's dominant wall direction (modulo 90 deg; the odometry's "
       "estimate, sharpened to about 0.1 deg by the points' projections) instead of the first heading: the map "
       "comes out square to the building; the first pose is then (0, 0, -that angle). The same key as the "
       "odometry's: one choice for the building",
       kUser},
      {"no_return_range", "map", FIELD(slam.no_return_range), "m", above(0),
       "a no-return beam (+inf) is free space up to min(this, the scan's range_max)", kUser},
      {"map_wall_min_strength", "map", FIELD(slam.map_wall_min_strength), "-", closedInterval(0, 1),
       "align_to_walls only when the first scan's chords agree at least this much", kAdvanced},
      {"trace_max_range", "map", FIELD(slam.trace_max_range), "m", above(0),
       "beams are traced this far at most; longer returns count as free space up to it; must exceed "
       "map_resolution",
       kAdvanced},
      {"entry_prior_cells", "map", FIELD(slam.entry_prior_cells), "cells", above(0),
       "distance a new cell entry starts with, as if already crossed without a stop", kAdvanced},
      {"update_beam_step", "map", FIELD(slam.update_beam_step), "beams", atLeast(1),
       "every k-th beam is written into the map", kAdvanced},
      {"free_space_beam_step", "map", FIELD(slam.free_space_beam_step), "beams", atLeast(1),
       "a power of two k: every k-th beam writes its whole path, the others only where the beams kept lie more "
       "than a cell apart (and their last two cells); 1 = every beam writes its whole path", kAdvanced},
      {"free_saturation_distance", "map", FIELD(slam.free_saturation_distance), "m", atLeast(0),
       "a free cell already crossed this far without a stop is not rewritten; 0 = off", kAdvanced},
      {"map_update_distance", "map", FIELD(slam.map_update_distance), "m", atLeast(0),
       "travel since the last map update before the next one ...", kAdvanced},
      {"map_update_angle", "map", FIELD(slam.map_update_angle), "rad", atLeast(0),
       "... or rotation (each 0 = off; both 0 = at every filter update)", kAdvanced},
      {"surface_depth", "map", FIELD(slam.surface_depth), "m", atLeast(0),
       "within this distance of a return, distance through a cell counts along the surface normal (writes and "
       "scores); 0 = off",
       kAdvanced},
      {"surface_min_cos", "map", FIELD(slam.surface_min_cos), "-", leftOpenInterval(0, 1),
       "lower bound of that projection, |cos| of the beam's incidence on the surface", kAdvanced},
      {"cell_normal_min_cos", "map", FIELD(slam.cell_normal_min_cos), "-", closedInterval(0, 1),
       "a cell a beam stopped in keeps (per particle lineage) that surface's normal; distance through it counts "
       "along that normal for every beam, |cos| bounded below by this; 0 = off (see "
       "doc/benchmarks.md)",
       kAdvanced},
      {"cell_surface_offsets", "map", FIELD(slam.cell_surface_offsets), "bool", anyValue(),
       "with cell normals: a cell also keeps where along its normal its surface lies (the mean of its stops), and "
       "a stop there is scored where the beam crosses that line instead of at the middle of its chord: walls are "
       "seen to a fraction of a cell (see doc/benchmarks.md)",
       kAdvanced},
  };
}

std::vector<Parameter<S>> observationAndOutputEntries() {
  return {
      // --- Observation model (laser penetration, DP-SLAM) ---
      {"beam_sigma", "observation model", FIELD(slam.beam.sigma), "m", above(0),
       "standard deviation of a range error (DP-SLAM: sqrt(0.017))", kAdvanced},
      {"beam_window", "observation model", FIELD(slam.beam.window), "m", above(0),
       "a stop farther than this from the measured range explains nothing", kAdvanced},
      {"beam_log_floor", "observation model", FIELD(slam.beam.log_floor), "log-likelihood", below(0),
       "floor of one beam (outliers); DP-SLAM's exp(-24/LOW_VARIANCE)", kAdvanced},
      {"unknown_mean_free_path", "observation model", FIELD(slam.beam.unknown_mean_free_path), "m", above(0),
       "an unobserved cell stops beams with density 1/this", kAdvanced},
      {"score_beam_step", "observation model", FIELD(slam.score_beam_step), "beams", atLeast(1),
       "every k-th beam is scored (tempering and speed)", kAdvanced},
      {"cull_beam_step", "observation model", FIELD(slam.cull_beam_step), "beams", atLeast(1),
       "every k-th beam enters the cheap score that picks each particle's candidate (oversampling)", kAdvanced},
      {"likelihood_weight", "observation model", FIELD(slam.likelihood_weight), "-", leftOpenInterval(0, 1),
       "exponent of a scan's likelihood in the particle weights (tempering)", kAdvanced},
      {"score_no_return", "observation model", FIELD(slam.score_no_return), "bool", anyValue(),
       "no-return beams are scored (free space up to no_return_range)", kAdvanced},

      // --- Output and execution ---
      {"seed", "output and execution", FIELD(slam.seed), "-", atLeast(0),
       "random seed; the same seed and input give the same output", kUser},
      {"threads", "output and execution", FIELD(slam.threads), "threads", atLeast(1),
       "workers for scoring and map planning; results do not depend on it", kUser},
      {"occupancy_stop_length", "output and execution", FIELD(slam.occupancy_stop_length), "m", above(0),
       "exported occupancy = 1 - exp(-density x this), 0..100", kAdvanced},
      {"trajectory_smoothing", "output and execution", FIELD(slam.trajectory_smoothing), "s", atLeast(0),
       "sigma of a Gaussian window in time: each pose of the output path (`trajectory.tum`, the `trajectory` "
       "topic) is the weighted mean of its neighbours' SLAM poses carried to its time by the odometry (takes out "
       "a lineage's per-scan jitter, keeps the SLAM's corrections); 0 = the best particle's raw path. The live "
       "pose and map -> odom are not smoothed",
       kAdvanced},
      {"refine_trajectory", "output and execution", FIELD(slam.refine_trajectory), "bool", anyValue(),
       "`dpslam_offline` only: `trajectory.tum` is refined at the end by a pose graph over keyframes every 0.2 m "
       "(the filter's relative poses plus NDT matches with predecessors and with another pass within 1.5 m; "
       "`trajectory_refiner.h`); the filter's path goes to `trajectory_filter.tum`. The map, the live pose and the "
       "node are not changed by it. Costs ~10 MB per 180 m and a few seconds at the end (loop building 177 m: 7 s; "
       "CSAIL: 4 s); false = no refinement",
       kAdvanced},
      {"work_multiplier", "output and execution", FIELD(work_multiplier), "-", atLeast(1),
       "dpslam_node only, to benchmark a slower CPU: after each scan the node busy-waits (this - 1) x the CPU "
       "time that scan's processing took, as a CPU this many times slower would (scripts/benchmark_lag.sh); "
       "1 = off. Not for normal use",
       kAdvanced},
  };
}

#undef FIELD

std::vector<Parameter<S>> makeRegistry() {
  std::vector<Parameter<S>> all;
  for (auto part : {nodeAndScanEntries, filterEntries, mapEntries, observationAndOutputEntries}) {
    for (const Parameter<S>& p : part()) all.push_back(p);
  }
  return all;
}
}  // namespace

const std::vector<Parameter<S>>& dpslamParameters() {
  static const std::vector<Parameter<S>> registry = makeRegistry();
  return registry;
}

void readDpSlamNodeParameters(const ParameterSource& source, DpSlamNodeSettings& settings) {
  readParameters(source, dpslamParameters(), settings);
  const DpSlamConfig& c = settings.slam;
  if (c.trace_max_range <= c.map_resolution) {
    throw std::invalid_argument("parameter 'trace_max_range' = " + formatParameterNumber(c.trace_max_range) +
                                " must exceed 'map_resolution' = " + formatParameterNumber(c.map_resolution));
  }
}

void readDpSlamParameters(const ParameterSource& source, DpSlamConfig& config) {
  DpSlamNodeSettings settings;
  settings.slam = config;
  readDpSlamNodeParameters(source, settings);
  config = settings.slam;
}

}  // namespace laser_dpslam
