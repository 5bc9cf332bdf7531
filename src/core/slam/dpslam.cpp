#include "laser_dpslam/slam/dpslam.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "laser_dpslam/common/worker_pool.h"
#include "laser_dpslam/scan/wall_direction.h"
#include "laser_dpslam/slam/motion_covariance.h"
#include "laser_dpslam/slam/trajectory_smoother.h"

namespace laser_dpslam {

bool travelThresholdReached(const Pose2D& motion, double distance, double angle) {
  // A threshold of 0 is off: with a distance alone the robot's turns in place do not count, and the other
  // way round (gmapping's linearUpdate / angularUpdate, each effective on its own).
  if (distance <= 0.0 && angle <= 0.0) return true;
  return (distance > 0.0 && std::hypot(motion.x, motion.y) >= distance) ||
         (angle > 0.0 && std::abs(motion.theta) >= angle);
}

double freeSpaceWriteFrom(long beam, int step, double increment, double resolution) {
  if (step <= 1 || !(std::abs(increment) > 0.0)) return 0.0;
  // The beam's level: the largest power of two dividing its index (capped at step). The beams of the
  // levels above lie 2·level increments apart, more than a cell from resolution / (2·level·increment) on.
  const unsigned long u = static_cast<unsigned long>(beam < 0 ? -beam : beam);
  const unsigned long level = u == 0 ? static_cast<unsigned long>(step) : (u & (~u + 1));
  if (level >= static_cast<unsigned long>(step)) return 0.0;
  return resolution / (2.0 * static_cast<double>(level) * std::abs(increment));
}

namespace {
void require(bool ok, const char* what) {
  if (!ok) throw std::invalid_argument(std::string("DpSlamConfig: ") + what);
}
}  // namespace

void DpSlamConfig::validate() const {
  // ≤ 3P − 1 ancestry nodes during an update; their IDs must fit the map's 16-bit owners.
  require(particles >= 1 && particles <= 10000, "particles must be in [1, 10000]");
  require(oversampling >= 1, "oversampling must be >= 1");
  require(cull_window > 0.0, "cull_window must be > 0");
  require(resample_threshold >= 0.0 && resample_threshold <= 1.0, "resample_threshold must be in [0, 1]");
  require(proposal.covariance_scale >= 0.0, "proposal_covariance_scale must be >= 0");
  require(proposal.min_sigma_xy >= 0.0 && proposal.min_sigma_theta >= 0.0, "proposal minimum sigmas must be >= 0");
  require(proposal.sigma_xy_per_m >= 0.0 && proposal.sigma_theta_per_rad >= 0.0, "proposal sigma rates must be >= 0");
  require(explore_noise_scale > 0.0 && explore_noise_scale <= 1.0, "explore_noise_scale must be in (0, 1]");
  require(revisit_radius > 0.0, "revisit_radius must be > 0");
  require(revisit_min_travel >= 0.0, "revisit_min_travel must be >= 0");
  require(min_travel_distance >= 0.0 && min_travel_angle >= 0.0, "minimum travel must be >= 0");
  require(map_resolution > 0.0, "map_resolution must be > 0");
  require(map_wall_min_strength >= 0.0 && map_wall_min_strength <= 1.0, "map_wall_min_strength must be in [0, 1]");
  require(trace_max_range > map_resolution, "trace_max_range must exceed map_resolution");
  require(no_return_range > 0.0, "no_return_range must be > 0");
  require(entry_prior_cells > 0.0, "entry_prior_cells must be > 0");
  require(update_beam_step >= 1 && score_beam_step >= 1 && cull_beam_step >= 1, "beam steps must be >= 1");
  require(free_space_beam_step >= 1 && (free_space_beam_step & (free_space_beam_step - 1)) == 0,
          "free_space_beam_step must be a power of two");
  require(free_saturation_distance >= 0.0, "free_saturation_distance must be >= 0");
  require(surface_depth >= 0.0, "surface_depth must be >= 0");
  require(surface_min_cos > 0.0 && surface_min_cos <= 1.0, "surface_min_cos must be in (0, 1]");
  require(cell_normal_min_cos >= 0.0 && cell_normal_min_cos <= 1.0, "cell_normal_min_cos must be in [0, 1]");
  require(map_update_distance >= 0.0 && map_update_angle >= 0.0, "map update thresholds must be >= 0");
  require(beam.sigma > 0.0, "beam_sigma must be > 0");
  require(likelihood_weight > 0.0 && likelihood_weight <= 1.0, "likelihood_weight must be in (0, 1]");
  require(beam.window > 0.0, "beam_window must be > 0");
  require(beam.log_floor < 0.0, "beam_log_floor must be < 0");
  require(beam.unknown_mean_free_path > 0.0, "unknown_mean_free_path must be > 0");
  require(min_points >= 1, "slam_min_points must be >= 1");
  require(occupancy_stop_length > 0.0, "occupancy_stop_length must be > 0");
  require(trajectory_smoothing >= 0.0 && std::isfinite(trajectory_smoothing), "trajectory_smoothing must be >= 0");
  require(threads >= 1, "threads must be >= 1");
}

DpSlam::DpSlam(const DpSlamConfig& config)
    : config_(config), rng_(config.seed), map_(config.map_resolution, config.entry_prior_cells) {
  config_.validate();
  map_.setSurfaceDepth(config_.surface_depth);
  map_.setCellNormals(config_.cell_normal_min_cos);
  map_.setSurfaceOffsets(config_.cell_surface_offsets);
  map_.setFreeSaturation(config_.free_saturation_distance);
  RevisitDetectorConfig rc;
  rc.radius = config_.revisit_radius;
  rc.min_travel = config_.revisit_min_travel;
  revisit_ = RevisitDetector(rc);
  pool_.reset(new WorkerPool(config_.threads));
  caches_.resize(static_cast<std::size_t>(config_.threads));
}

DpSlam::~DpSlam() = default;

void DpSlam::reset() {
  tree_.clear();
  map_.clear();
  rng_.seed(config_.seed);
  initialized_ = false;
  generation_ = 0;
  poses_.clear();
  leaves_.clear();
  logw_.clear();
  best_ = 0;
  last_neff_ = 0.0;
  pending_ = Pose2D();
  pending_cov_.setZero();
  pending_scans_ = 0;
  pending_held_ = HeldMotion();
  holding_ = false;
  held_speed_error_.clear();
  motion_ = Pose2D();
  motion_path_.clear();
  since_map_update_ = Pose2D();
  force_map_update_ = false;
  revisit_.reset();
  last_revisit_ = false;
}

void DpSlam::makeBeams(const PreprocessedScan& scan, const LaserMount& mount) {
  beam_origin_ = mount.t;
  const double no_return_range = std::min(config_.no_return_range, scan.range_max > 0.0 ? scan.range_max : config_.no_return_range);
  std::vector<BaseBeam> all;
  all.reserve(scan.points.size() + scan.no_return_angles.size());
  SurfaceFits fits;
  if (config_.surface_depth > 0.0 || config_.cell_normal_min_cos > 0.0) {
    SurfaceIncidenceConfig ic;
    ic.min_cos = config_.surface_min_cos;
    fits = fitSurfaces(scan, ic);
  }
  // Returns and no-returns in beam-angle order, so that "every k-th beam" spreads over the whole scan.
  std::size_t i = 0, j = 0;
  while (i < scan.points.size() || j < scan.no_return_angles.size()) {
    const bool take_return =
        j >= scan.no_return_angles.size() || (i < scan.points.size() && scan.angles[i] <= scan.no_return_angles[j]);
    const double a = take_return ? scan.angles[i] : scan.no_return_angles[j];
    const Eigen::Vector2d d = mount.A * Eigen::Vector2d(std::cos(a), std::sin(a));
    const double n = d.norm();
    BaseBeam b{d.x() / n, d.y() / n, 0.0, !take_return, 1.0};
    const long index = take_return ? scan.beams[i]
                                   : (scan.angle_increment != 0.0 ? std::lround((a - scan.angle_min) / scan.angle_increment) : 0);
    b.write_from = freeSpaceWriteFrom(index, config_.free_space_beam_step, scan.angle_increment, config_.map_resolution);
    if (take_return) {
      if (!fits.incidence.empty()) {
        if (config_.surface_depth > 0.0) b.incidence = fits.incidence[i];
        const Eigen::Vector2d nb = mount.A * fits.normals[i];
        if (nb.x() != 0.0 || nb.y() != 0.0) b.normal_angle = std::atan2(nb.y(), nb.x());
      }
      b.range = scan.ranges[i++];
    } else {
      b.range = no_return_range;
      ++j;
      if (!config_.score_no_return) b.range = -1.0;  // marker: written, not scored
    }
    all.push_back(b);
  }
  score_beams_.clear();
  cull_beams_.clear();
  update_beams_.clear();
  for (std::size_t k = 0; k < all.size(); ++k) {
    BaseBeam b = all[k];
    const bool scored_out = b.range < 0.0;
    if (scored_out) b.range = no_return_range;
    if (k % static_cast<std::size_t>(config_.update_beam_step) == 0) update_beams_.push_back(b);
    if (!scored_out && k % static_cast<std::size_t>(config_.score_beam_step) == 0) score_beams_.push_back(b);
    if (!scored_out && k % static_cast<std::size_t>(config_.cull_beam_step) == 0) cull_beams_.push_back(b);
  }
}

MapBeam DpSlam::toMap(const PoseFrame& f, const BaseBeam& b) const {
  const double c = f.c, s = f.s;
  const Pose2D& pose = f.pose;
  MapBeam m;
  m.ox = pose.x + c * beam_origin_.x() - s * beam_origin_.y();
  m.oy = pose.y + s * beam_origin_.x() + c * beam_origin_.y();
  m.dx = c * b.dx - s * b.dy;
  m.dy = s * b.dx + c * b.dy;
  m.range = b.range;
  m.no_return = b.no_return;
  m.incidence = b.incidence;
  m.normal_angle = b.normal_angle + pose.theta;  // NaN stays NaN
  m.write_from = b.write_from;
  return m;
}

double DpSlam::score(const Pose2D& pose, int slot, LookupCache& cache) const {
  const PoseFrame f(pose);
  double sum = 0.0;
  for (const BaseBeam& b : score_beams_) {
    sum += map_.beamLogLikelihood(toMap(f, b), config_.trace_max_range, slot, cache, config_.beam);
  }
  return sum;
}

template <class F>
void DpSlam::forEachBeamByBlock(std::size_t n, const std::vector<BaseBeam>& beams, F&& f) {
  // Several blocks per worker when there are workers: the machine may be shared, so balance the load.
  const std::size_t workers = static_cast<std::size_t>(pool_->threads());
  const std::size_t blocks = std::min(n, workers == 1 ? std::size_t{1} : 4 * workers);
  if (blocks == 0) return;
  const std::size_t per = (n + blocks - 1) / blocks;
  pool_->run(blocks, [&](std::size_t block, int w) {
    const std::size_t first = block * per, last = std::min(n, first + per);
    for (const BaseBeam& b : beams) {
      for (std::size_t i = first; i < last; ++i) f(i, b, caches_[w]);
    }
  });
}

void DpSlam::scoreAll(const std::vector<Pose2D>& chosen, std::vector<double>& ll) {
  std::vector<PoseFrame> frames(chosen.begin(), chosen.end());
  std::fill(ll.begin(), ll.end(), 0.0);
  forEachBeamByBlock(chosen.size(), score_beams_, [&](std::size_t i, const BaseBeam& b, LookupCache& cache) {
    ll[i] += map_.beamLogLikelihood(toMap(frames[i], b), config_.trace_max_range, static_cast<int>(i), cache, config_.beam);
  });
}

void DpSlam::cheapScoreAll(const std::vector<Pose2D>& candidates, int per_slot, std::vector<double>& cheap) {
  std::vector<PoseFrame> frames(candidates.begin(), candidates.end());
  std::fill(cheap.begin(), cheap.end(), 0.0);
  forEachBeamByBlock(candidates.size(), cull_beams_, [&](std::size_t n, const BaseBeam& b, LookupCache& cache) {
    if (b.no_return || b.range >= config_.trace_max_range) return;
    cheap[n] += map_.beamEndpointLogLikelihood(toMap(frames[n], b), config_.cull_window, static_cast<int>(n) / per_slot,
                                               cache, config_.beam);
  });
}

void DpSlam::planWrites(const std::vector<int>& who, const std::vector<Pose2D>& at) {
  writes_.resize(std::max(writes_.size(), at.size()));
  std::vector<PoseFrame> frames;
  frames.reserve(who.size());
  for (int i : who) {
    writes_[i].clear();
    frames.emplace_back(at[i]);
  }
  const bool only_unknown = config_.revisit_freeze_map && last_revisit_;
  forEachBeamByBlock(who.size(), update_beams_, [&](std::size_t k, const BaseBeam& b, LookupCache& cache) {
    const int i = who[k];
    map_.planBeam(toMap(frames[k], b), config_.trace_max_range, i, cache, writes_[i], only_unknown);
  });
}

void DpSlam::applyWrites(const std::vector<int>& who, const std::vector<int>& nodes) {
  update_cache_.begin(tree_, nodes, true);  // every particle descends from a writer's node
  for (std::size_t s = 0; s < who.size(); ++s) {
    auto& w = writes_[who[s]];
    map_.applyWrites(w, static_cast<int>(s), nodes[s], update_cache_);
    // A scan into unmapped space plans ten times the usual writes: no particle keeps a buffer that large.
    if (w.capacity() > kKeptWrites) std::vector<DpSlamMap::CellWrite>().swap(w);
  }
}

void DpSlam::record(double stamp) {
  motion_path_.push_back({stamp, motion_});
  for (std::size_t j = 0; j < poses_.size(); ++j) {
    StampedPose sp;
    sp.stamp = stamp;
    sp.pose = poses_[j] * pending_;
    tree_.node(leaves_[j]).path.push_back(sp);
  }
}

DpSlamUpdate DpSlam::process(double stamp, const PreprocessedScan& scan, const LaserMount& mount, const Pose2D& delta,
                             const Eigen::Matrix3d& delta_cov, const HeldMotion& held) {
  DpSlamUpdate u;
  u.stamp = stamp;
  if (!scan.ok()) {
    u.skip_reason = "malformed_scan";
  } else if (static_cast<int>(scan.points.size()) < config_.min_points) {
    u.skip_reason = "too_few_points";
  }
  const bool usable = u.skip_reason.empty();

  if (!initialized_) {
    if (!usable) {
      fill(u);
      return u;
    }
    makeBeams(scan, mount);
    const int P = config_.particles;
    // The first pose defines the map frame; turned by the walls' angle, the grid's rows run along them. The
    // angle must be good to a tenth of a degree, not the chords' ~1°: the particles' headings drift toward
    // the grid's axes, and a 1° pull bends a 30 m corridor by 0.5 m (doc/experiments.md, "The map's grid
    // turned to the walls by the projections").
    Pose2D first;
    if (config_.map_align_to_walls) {
      const std::vector<Eigen::Vector2d> points = mount.apply(scan.points);
      const WallDirection w = dominantWallDirection(points);
      if (w.strength >= config_.map_wall_min_strength) first = Pose2D(0.0, 0.0, -refineWallAngle(points, w.angle));
    }
    const int root = tree_.createRoot(0);
    map_.setRoot(root);
    poses_.assign(P, first);
    logw_.assign(P, 0.0);
    leaves_ = {root};
    poses_.resize(1);
    record(stamp);
    for (auto& c : caches_) c.begin(tree_, leaves_);
    planWrites({0}, poses_);
    applyWrites({0}, {root});
    leaves_ = tree_.advance({root}, std::vector<int>(P, 0), ++generation_, map_);
    poses_.assign(P, first);
    held_speed_error_.assign(P, 0.0);
    best_ = 0;
    last_neff_ = P;
    initialized_ = true;
    u.ok = true;
    u.map_updated = true;
    fill(u);
    return u;
  }

  if (held.active()) {
    // Expressed in the frame pending_ starts from; the first held scan's direction stands for the rest.
    if (!pending_held_.active()) {
      pending_held_.direction = Pose2D(0.0, 0.0, pending_.theta).rotation() * held.direction.normalized();
      pending_held_.speed_sigma = held.speed_sigma;
    }
    pending_held_.dt += held.dt;
  }
  composeMotion(pending_, pending_cov_, delta, delta_cov);
  ++pending_scans_;
  motion_ = motion_ * delta;
  const bool moved_enough = travelThresholdReached(pending_, config_.min_travel_distance, config_.min_travel_angle);
  if (!usable || !moved_enough) {
    // Not weighted: the particles carry the motion forward (and its uncertainty) until a usable scan.
    record(stamp);
    u.ok = usable;
    fill(u);
    return u;
  }
  makeBeams(scan, mount);
  filterStep(stamp, pending_, pending_cov_, u);
  u.ok = true;
  fill(u);
  return u;
}

void DpSlam::filterStep(double stamp, const Pose2D& delta, const Eigen::Matrix3d& cov, DpSlamUpdate& u) {
  const int P = config_.particles;
  std::vector<Pose2D> chosen(P);
  std::vector<double> ll(P);
  propose(delta, cov, chosen, ll);
  // Tempering: beams are not independent, so the product of their likelihoods is over-confident and
  // depletes the particles; an exponent < 1 keeps more hypotheses alive until a loop closes.
  for (int i = 0; i < P; ++i) {
    ll[i] *= config_.likelihood_weight;
    logw_[i] += ll[i];
  }
  u.score_spread = *std::max_element(ll.begin(), ll.end()) - *std::min_element(ll.begin(), ll.end());
  const NormalizedWeights nw = normalizeLogWeights(logw_);
  // 4. Neff-gated low-variance resampling.
  std::vector<int> parents(P);
  const bool resample = nw.neff < config_.resample_threshold * P || config_.resample_threshold >= 1.0;
  if (resample) {
    parents = lowVarianceResample(nw.w, P, rng_.uniform());
  } else {
    for (int i = 0; i < P; ++i) parents[i] = i;
  }
  updateMapAndTree(delta, parents, chosen, u);
  adoptSurvivors(parents, chosen, nw.best, resample);
  last_neff_ = resample ? P : nw.neff;
  pending_ = Pose2D();
  pending_cov_.setZero();
  pending_scans_ = 0;
  pending_held_ = HeldMotion();
  record(stamp);
  u.filter_updated = true;
  u.resampled = resample;
}

void DpSlam::propose(const Pose2D& delta, const Eigen::Matrix3d& cov, std::vector<Pose2D>& chosen,
                     std::vector<double>& ll) {
  // 1. Proposal: each particle moves by the delta plus noise, in its own frame. Draws in a fixed order.
  const Pose2D ahead = poses_[best_] * delta;
  last_revisit_ = revisit_.update(Eigen::Vector2d(ahead.x, ahead.y), std::hypot(delta.x, delta.y));
  Eigen::Matrix3d L = proposalFactor(delta, startHeldMotion(cov), config_.proposal, std::max(1, pending_scans_));
  // Exploring, the noise mostly random-walks the particles (their fresh maps move with them); back on old
  // ground it is what lets the filter find the older map's alignment (doc/benchmarks.md).
  if (!last_revisit_) L *= config_.explore_noise_scale;
  for (auto& c : caches_) c.begin(tree_, leaves_);
  proposeSampled(delta, L, chosen, ll);
}

Eigen::Matrix3d DpSlam::startHeldMotion(const Eigen::Matrix3d& cov) {
  const HeldMotion& h = pending_held_;
  const int P = config_.particles;
  if (!h.active()) {
    holding_ = false;
    held_speed_error_.assign(P, 0.0);
    return cov;
  }
  // Exploring, a speed error moves the particle's fresh map with it and nothing can tell it apart: the
  // errors are drawn as small as the proposal's noise there (explore_noise_scale), and widened when the hold
  // reaches old ground, where the older map can choose between them.
  const double scale = last_revisit_ ? 1.0 : config_.explore_noise_scale;
  if (!holding_ || scale > held_scale_) {
    const double from = holding_ ? held_scale_ : 0.0;
    const double sigma = h.speed_sigma * std::sqrt(scale * scale - from * from);
    for (int i = 0; i < P; ++i) held_speed_error_[i] = (holding_ ? held_speed_error_[i] : 0.0) + sigma * rng_.normal();
    holding_ = true;
    held_scale_ = scale;
  }
  // Along the held direction the match measured nothing: its variance there is replaced by the speed errors.
  Eigen::Matrix3d A = Eigen::Matrix3d::Identity();
  A.topLeftCorner<2, 2>() -= h.direction * h.direction.transpose();
  return A * cov * A.transpose();
}

void DpSlam::proposeSampled(const Pose2D& delta, const Eigen::Matrix3d& L, std::vector<Pose2D>& chosen,
                            std::vector<double>& ll) {
  const int P = config_.particles;
  const int K = config_.oversampling;
  std::vector<Pose2D> candidates(static_cast<std::size_t>(P) * K);
  for (int i = 0; i < P; ++i) {
    Pose2D d = delta;
    if (holding_) {
      const double along = held_speed_error_[i] * pending_held_.dt;
      d.x += along * pending_held_.direction.x();
      d.y += along * pending_held_.direction.y();
    }
    for (int k = 0; k < K; ++k) candidates[static_cast<std::size_t>(i) * K + k] = poses_[i] * sampleMotion(d, L, rng_);
  }
  // 2. Over-sampling: keep each particle's best candidate by the cheap endpoint score.
  if (K > 1) {
    std::vector<double> cheap(candidates.size());
    cheapScoreAll(candidates, K, cheap);
    for (int i = 0; i < P; ++i) {
      int best = 0;
      for (int k = 1; k < K; ++k) {
        if (cheap[static_cast<std::size_t>(i) * K + k] > cheap[static_cast<std::size_t>(i) * K + best]) best = k;
      }
      chosen[i] = candidates[static_cast<std::size_t>(i) * K + best];
    }
  } else {
    chosen = candidates;
  }
  // 3. Weights: the full observation model, one result per particle (independent of scheduling).
  scoreAll(chosen, ll);
}

void DpSlam::updateMapAndTree(const Pose2D& delta, const std::vector<int>& parents, const std::vector<Pose2D>& chosen,
                              DpSlamUpdate& u) {
  // 5. Map update, planned now (the scoring caches still describe the old particles): each surviving
  //    lineage writes the scan once, from its pose, into the node it will own alone after the ancestry
  //    update. Its descendants (all at that pose) see exactly what they would see had each written its own
  //    copy, without the copies.
  const int P = config_.particles;
  since_map_update_ = since_map_update_ * delta;
  const bool due = travelThresholdReached(since_map_update_, config_.map_update_distance, config_.map_update_angle);
  std::vector<int> survivors;
  for (int i = 0; i < P; ++i) {
    if (std::find(parents.begin(), parents.end(), i) != parents.end()) survivors.push_back(i);
  }
  if (due) planWrites(survivors, chosen);
  // 6. Ancestry maintenance, new generation.
  std::vector<int> lineage;
  leaves_ = tree_.advance(leaves_, parents, ++generation_, map_, &lineage);
  if (due) {
    std::vector<int> nodes;
    for (int i : survivors) {
      nodes.push_back(lineage[i]);
      u.map_writes += writes_[i].size();
    }
    applyWrites(survivors, nodes);
    since_map_update_ = Pose2D();
    u.map_updated = true;
  }
}

void DpSlam::adoptSurvivors(const std::vector<int>& parents, const std::vector<Pose2D>& chosen, int best_parent,
                            bool resampled) {
  const int P = config_.particles;
  std::vector<double> new_logw(P);
  const double max_logw = logw_[best_parent];
  best_ = 0;
  for (int j = 0; j < P; ++j) {
    poses_[j] = chosen[parents[j]];
    new_logw[j] = resampled ? 0.0 : logw_[parents[j]] - max_logw;
  }
  if (resampled && holding_) held_speed_error_ = inheritHeldSpeedErrors(parents, held_speed_error_, rng_);
  for (int j = 0; j < P; ++j) {
    if (parents[j] == best_parent) {
      best_ = j;
      break;
    }
  }
  logw_ = new_logw;
}

void DpSlam::fill(DpSlamUpdate& u) const {
  if (initialized_) {
    u.pose = bestPose();
    std::vector<double> w = normalizeLogWeights(logw_).w;
    std::vector<Pose2D> poses = particlePoses();
    u.covariance = weightedPoseCovariance(poses, w);
  }
  u.neff = last_neff_;
  u.revisit = last_revisit_;
  u.tree_nodes = tree_.size();
  u.map_entries = map_.entryCount();
  u.memory_bytes = memoryBytes();
}

Pose2D DpSlam::bestPose() const { return initialized_ ? poses_[best_] * pending_ : Pose2D(); }

std::vector<StampedPose> DpSlam::bestLineagePath() const {
  return initialized_ ? tree_.fullPath(leaves_[best_]) : std::vector<StampedPose>();
}

std::vector<StampedPose> DpSlam::bestTrajectory() const {
  return smoothTrajectory(bestLineagePath(), motion_path_, config_.trajectory_smoothing);
}

OccupancyGridData DpSlam::bestMap() const {
  if (!initialized_) {
    OccupancyGridData g;
    g.resolution = config_.map_resolution;
    return g;
  }
  return occupancyFromMap(map_, tree_, leaves_[best_], config_.occupancy_stop_length);
}

std::vector<Pose2D> DpSlam::particlePoses() const {
  std::vector<Pose2D> out(poses_.size());
  for (std::size_t i = 0; i < poses_.size(); ++i) out[i] = poses_[i] * pending_;
  return out;
}

std::size_t DpSlam::memoryBytes() const {
  std::size_t b = map_.memoryBytes() + update_cache_.memoryBytes();
  for (const auto& c : caches_) b += c.memoryBytes();
  return b;
}

}  // namespace laser_dpslam
