#include "laser_dpslam/odometry/laser_odometry.h"

#include <cmath>
#include <limits>

#include "laser_dpslam/odometry/wheel_motion.h"
#include "laser_dpslam/scan/facing_surfaces.h"
#include "laser_dpslam/scan/voxel_filter.h"
#include "laser_dpslam/scan/wall_direction.h"

namespace laser_dpslam {

const char* toString(OdometrySkipReason reason) {
  switch (reason) {
    case OdometrySkipReason::kNone: return "";
    case OdometrySkipReason::kTooFewPoints: return "too_few_points";
    case OdometrySkipReason::kMalformedScan: return "malformed_scan";
    case OdometrySkipReason::kTimeBackwards: return "time_backwards";
    case OdometrySkipReason::kDuplicateStamp: return "duplicate_stamp";
    case OdometrySkipReason::kMatchFailed: return "match_failed";
  }
  return "unknown";
}

LaserOdometry::LaserOdometry(const LaserOdometryConfig& config)
    : config_(config), matcher_(config.matcher), rng_(config.seed) {}

void LaserOdometry::reset() {
  initialized_ = false;
  pose_ = Pose2D();
  frame_angle_ = 0.0;
  pose_covariance_.setZero();
  velocity_.setZero();
  keyframes_.clear();
  rng_.seed(config_.seed);
  scan_count_ = 0;
  velocity_measured_ = false;
  held_since_ = kNoStamp;
  last_weak_.setZero();
  seen_along_.clear();
  was_blank_ = false;
  fitted_through_ = kNoStamp;
  held_speed_.reset();
}

void LaserOdometry::addKeyframe(const std::vector<Eigen::Vector2d>& base_points, const PreprocessedScan& scan,
                                const LaserMount& mount) {
  Keyframe kf;
  kf.view.origin = pose_.transform(mount.t);
  kf.view.range = scan.range_max;
  kf.pose = pose_;
  kf.covariance = pose_covariance_;
  kf.points.reserve(base_points.size());
  for (const auto& p : base_points) kf.points.push_back(pose_.transform(p));
  kf.points = voxelFilter(kf.points, config_.map_voxel);
  keyframes_.push_back(std::move(kf));
  keyframe_matched_ = -1.0;
  while (static_cast<int>(keyframes_.size()) > std::max(1, config_.local_map_keyframes)) keyframes_.pop_front();
  std::vector<Eigen::Vector2d> map;
  std::vector<NdtView> views;  // where the keyframes were taken: the cells their range cut (NdtGrid::build)
  for (const auto& k : keyframes_) {
    map.insert(map.end(), k.points.begin(), k.points.end());
    if (k.view.range > 0.0) views.push_back(k.view);
  }
  matcher_.setReference(voxelFilter(map, config_.map_voxel), views);
}

namespace {
// s: how far past the newest wheel sample its motion is extrapolated. The Create's driver publishes at its
// loop rate (10 Hz by default) and its messages can reach us after the scan they bracket.
constexpr double kWheelExtrapolation = 0.25;
// Bound on the samples kept while no scan arrives (a laser that stopped): ~2 min at 66 Hz.
constexpr std::size_t kMaxWheelSamples = 8192;

// σ of a held velocity along a corridor (m/s): kHeldSpeedSigma of the speed plus kHeldMinSpeedSigma. It was
// smoothed over the constrained matches before the hold; 1-3 % off on the simulated corridors
// (doc/experiments.md).
constexpr double kHeldSpeedSigma = 0.02;
constexpr double kHeldMinSpeedSigma = 0.005;  // m/s

// The poses of `seen` (stamped, oldest first) from the first at or after `from` to the last at or before `to`,
// and the time between them, when it spans at least 40 % of the interval.
using StampedPoses = std::deque<std::pair<double, Pose2D>>;
bool spanOf(const StampedPoses& seen, double from, double to, const Pose2D** a, const Pose2D** b, double* dt) {
  const std::pair<double, Pose2D>* first = nullptr;
  const std::pair<double, Pose2D>* last = nullptr;
  for (const auto& e : seen) {
    if (e.first >= from && !first) first = &e;
    if (e.first <= to) last = &e;
  }
  if (!first || !last || last->first - first->first < 0.4 * (to - from)) return false;
  *a = &first->second;
  *b = &last->second;
  *dt = last->first - first->first;
  return true;
}

// Least-squares slope (m/s) of the positions of `seen` since `from` along w (base frame of `frame`).
double speedFit(const StampedPoses& seen, double from, double end, const Eigen::Matrix2d& frame,
                const Eigen::Vector2d& w, double fallback) {
  double st = 0, sp = 0, stt = 0, stp = 0;
  int m = 0;
  for (const auto& e : seen) {
    if (e.first < from) continue;
    const double t = e.first - end;
    const double q = w.dot(frame.transpose() * Eigen::Vector2d(e.second.x, e.second.y));
    st += t;
    sp += q;
    stt += t * t;
    stp += t * q;
    ++m;
  }
  const double den = m * stt - st * st;
  return den > 0.0 ? (m * stp - st * sp) / den : fallback;
}

}  // namespace

bool LaserOdometry::addWheelOdometry(double stamp, const Pose2D& pose) {
  if (!std::isfinite(stamp) || !pose.vector().allFinite()) return false;
  if (!wheels_.empty() && stamp <= wheels_.back().stamp) wheels_.clear();  // a new time line (bag looped)
  wheels_.push_back({stamp, pose});
  // Keep the newest sample at or before the last scan: the next scan's motion starts there.
  while (wheels_.size() > 2 && initialized_ && wheels_[1].stamp <= last_stamp_) wheels_.pop_front();
  while (wheels_.size() > kMaxWheelSamples) wheels_.pop_front();
  return true;
}

bool LaserOdometry::wheelPoseAt(double t, Pose2D* pose) const {
  if (wheels_.size() < 2 || t < wheels_.front().stamp || t > wheels_.back().stamp + kWheelExtrapolation) return false;
  // The pair around t (the last two past the end: extrapolation at their velocity).
  std::size_t i = 1;
  while (i + 1 < wheels_.size() && wheels_[i].stamp < t) ++i;
  const WheelSample& a = wheels_[i - 1];
  const WheelSample& b = wheels_[i];
  *pose = interpolate(a.pose, b.pose, (t - a.stamp) / (b.stamp - a.stamp));
  return true;
}

bool LaserOdometry::wheelMotion(double from, double to, Pose2D* motion) const {
  Pose2D a, b;
  if (!wheelPoseAt(from, &a) || !wheelPoseAt(to, &b)) return false;
  *motion = between(a, b);
  return true;
}

Pose2D LaserOdometry::priorDelta(double stamp, bool* from_wheels) const {
  const double dt = stamp - last_stamp_;
  Pose2D d;
  *from_wheels = dt > 0.0 && wheelMotion(last_stamp_, stamp, &d);
  if (*from_wheels) return d;
  // Constant velocity; after a long gap the last velocity says nothing.
  if (dt > 0.0 && dt <= config_.max_prior_gap) return Pose2D(velocity_.x() * dt, velocity_.y() * dt, velocity_.z() * dt);
  return Pose2D();
}

OdometryUpdate LaserOdometry::process(const PreprocessedScan& scan, const LaserMount& mount) {
  OdometryUpdate u = processInFrame(scan, mount);
  if (frame_angle_ != 0.0) {  // back to the odom frame; deltas and velocities are in base frames already
    u.pose = toOdom(u.pose);
    Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
    R.topLeftCorner<2, 2>() = Pose2D(0.0, 0.0, -frame_angle_).rotation();
    u.pose_covariance = R * u.pose_covariance * R.transpose();
  }
  return u;
}

OdometryUpdate LaserOdometry::processInFrame(const PreprocessedScan& scan, const LaserMount& mount) {
  OdometryUpdate u;
  u.stamp = scan.stamp;

  if (initialized_ && scan.stamp < last_stamp_) {
    // Time went backwards (a bag looped): start over rather than match across the jump.
    reset();
    u.skip_reason = OdometrySkipReason::kTimeBackwards;
  } else if (initialized_ && scan.stamp == last_stamp_) {
    u.skip_reason = OdometrySkipReason::kDuplicateStamp;
    u.pose = pose_;
    u.pose_covariance = pose_covariance_;
    return u;
  }

  const std::vector<Eigen::Vector2d> base_points = mount.apply(scan.points);
  if (!scan.ok() || static_cast<int>(base_points.size()) < config_.min_points) {
    propagateUnmatched(scan, u);
    return u;
  }
  if (!initialized_) {
    start(scan, mount, base_points, u);
    return u;
  }

  const double dt = scan.stamp - last_stamp_;
  const Pose2D prior = pose_ * priorDelta(scan.stamp, &u.wheel_prior);
  matchToLocalMap(scan, mount, base_points, prior, dt, u);
  if (!u.match.valid) {
    u.skip_reason = OdometrySkipReason::kMatchFailed;
    pose_ = prior;
    previous_scan_ = scan;
    last_flow_ = RangeFlow();
    last_stamp_ = scan.stamp;
    u.pose = pose_;
    u.pose_covariance = pose_covariance_;
    return u;
  }

  const Pose2D previous = pose_;
  pose_ = u.match.pose;
  u.delta = between(previous, pose_);
  matchCovariances(previous, u);
  if (dt > 0.0 && dt <= config_.max_prior_gap) {
    updateVelocity(scan, mount, previous, dt, u);
    seeAlongCorridor(scan.stamp, dt, u);
    heldCovariance(previous, scan.stamp, dt, u);
  } else {
    held_since_ = kNoStamp;
    last_flow_ = RangeFlow();
    velocity_.setZero();
    velocity_measured_ = false;  // nothing measured to hold
    held_speed_.reset();
  }
  if (!u.match.degenerate && !u.match.weak) velocity_measured_ = true;
  last_stamp_ = scan.stamp;

  if (keyframeDue(u.match)) {
    addKeyframe(base_points, scan, mount);
    u.new_keyframe = true;
  }
  previous_scan_ = scan;
  u.ok = true;
  u.pose = pose_;
  u.pose_covariance = pose_covariance_;
  u.velocity = velocity_;
  return u;
}

void LaserOdometry::propagateUnmatched(const PreprocessedScan& scan, OdometryUpdate& u) {
  // Nothing to match: propagate with the velocity prior (bounded by the gap rule) and say so.
  const double dt = initialized_ ? scan.stamp - last_stamp_ : 0.0;
  if (initialized_ && dt > 0.0) {
    const Pose2D d = priorDelta(scan.stamp, &u.wheel_prior);
    if (u.wheel_prior || dt <= config_.max_prior_gap) {
      pose_ = pose_ * d;
      u.delta = d;
      last_stamp_ = scan.stamp;
    }
  }
  if (u.skip_reason == OdometrySkipReason::kNone) {
    u.skip_reason = scan.ok() ? OdometrySkipReason::kTooFewPoints : OdometrySkipReason::kMalformedScan;
  }
  u.pose = pose_;
  u.pose_covariance = pose_covariance_;
  u.velocity = velocity_;
}

void LaserOdometry::start(const PreprocessedScan& scan, const LaserMount& mount,
                          const std::vector<Eigen::Vector2d>& base_points,
                          OdometryUpdate& u) {
  initialized_ = true;
  last_stamp_ = scan.stamp;
  frame_angle_ = 0.0;
  if (config_.align_to_walls) {
    // Walls at angle a in the base frame lie along the axes of a frame in which the robot heads −a.
    const WallDirection w = dominantWallDirection(base_points);
    if (w.strength >= config_.wall_alignment_min_strength) frame_angle_ = -w.angle;
  }
  pose_ = Pose2D(0.0, 0.0, frame_angle_);
  pose_covariance_.setZero();
  velocity_.setZero();
  addKeyframe(base_points, scan, mount);
  previous_scan_ = scan;
  last_flow_ = RangeFlow();  // a flow from before a reset says nothing about this start
  u.ok = true;
  u.reset = true;
  u.new_keyframe = true;
  u.pose = pose_;
  u.delta_covariance = Eigen::Matrix3d::Zero();
  u.points_used = static_cast<int>(base_points.size());
  ++scan_count_;
}

void LaserOdometry::matchToLocalMap(const PreprocessedScan& scan, const LaserMount& mount,
                                    const std::vector<Eigen::Vector2d>& base_points, const Pose2D& prior, double dt,
                                    OdometryUpdate& u) {
  const std::vector<Eigen::Vector2d> match_points = mount.apply(
      resampleScan(scan, config_.resampling, static_cast<std::size_t>(std::max(1, config_.resampling_budget)),
                   config_.saliency, config_.seed + scan_count_));
  const std::vector<Eigen::Vector2d> polish_points =
      config_.polish_budget > 0 && static_cast<int>(scan.points.size()) > config_.polish_budget
          ? mount.apply(resampleScan(scan, ResamplingMethod::kUniform, static_cast<std::size_t>(config_.polish_budget),
                                     config_.saliency, 0))
          : base_points;
  ++scan_count_;
  u.points_used = static_cast<int>(polish_points.size());
  const double prior_sigma = config_.prior_acceleration > 0.0 && dt > 0.0 && dt <= config_.max_prior_gap
                                 ? 0.5 * config_.prior_acceleration * dt * dt
                                 : 0.0;
  // The wheels measure the motion: no release from their prior, and along a corridor the match keeps it.
  // In a blank stretch of corridor nothing measures the motion along it either (short-range lasers only: a
  // long-range one sees a corridor's ends, and its returns at range lie farther apart than facingLength fits
  // a surface over).
  const bool short_range = shortRange(scan);
  u.velocity_held_blank = short_range && !u.wheel_prior && blankAlongCorridor(base_points, prior);
  const bool hold = u.wheel_prior || u.velocity_held_blank;
  const bool may_release = !hold && config_.prior_release_speed > 0.0 &&
                           velocity_.head<2>().norm() < config_.prior_release_speed;
  // In a blank stretch the corridor's direction is unconstrained whatever the score's curvature says.
  const Eigen::Vector2d unconstrained = u.velocity_held_blank ? last_weak_ : Eigen::Vector2d::Zero();
  u.match = matcher_.match(match_points, polish_points, prior, rng_, prior_sigma, may_release, hold, unconstrained);
  if (short_range && !u.wheel_prior) limitDegenerateStep(prior, prior_sigma, u.match);
  last_weak_ = u.match.valid && u.match.degenerate ? u.match.weak_direction : Eigen::Vector2d::Zero();
}

void LaserOdometry::matchCovariances(const Pose2D& previous, OdometryUpdate& u) {
  // The match covariance is in the odom frame; the delta's lives in the previous base frame.
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  R.topLeftCorner<2, 2>() = previous.rotation();
  u.delta_covariance = R.transpose() * u.match.covariance * R;
  // Where the match hardly constrains the motion (a corridor's length, a ridge of the score in heading) it
  // kept the wheels' motion, so that component's error is theirs; where it constrains, it is the match's.
  if (u.wheel_prior) u.delta_covariance = boundedByWheels(u.delta_covariance, wheelMotionSigma(u.delta));
  // Without wheels the delta's covariance is the matcher's as it is (the SLAM's proposal follows its
  // direction even where it is huge); the pose covariance takes the bounded one. The scan was matched against the local map, not
  // the previous scan, so its error does not add up scan by scan: the pose is the newest keyframe's (whose
  // covariance was fixed when it was taken) composed with this match, Σ = Ja·Σ_kf·Jaᵀ + Σ_match (odom
  // frame). Summing every scan's match instead overstated σ about fivefold (demo: 0.51 m after 24 m, real
  // error 0.054 m).
  const Keyframe& kf = keyframes_.back();
  Eigen::Matrix3d Ja, Jb;
  composeJacobians(kf.pose, between(kf.pose, pose_), &Ja, &Jb);
  pose_covariance_ = Ja * kf.covariance * Ja.transpose() + u.match.bounded_covariance;
}

void LaserOdometry::heldCovariance(const Pose2D& previous, double stamp, double dt, OdometryUpdate& u) {
  if (!u.velocity_held || u.wheel_prior) {
    held_since_ = kNoStamp;
    return;
  }
  // A velocity error is the same at every scan of the hold, so the position's error along the corridor
  // grows linearly, σ_v·t, not as the root of the keyframes chained since. (The delta keeps the match's
  // covariance: the held velocity's σ_v·dt there made the SLAM worse on the generated buildings,
  // doc/experiments.md.)
  const Eigen::Vector2d weak = previous.rotation().transpose() * u.match.weak_direction;
  const double sigma_v = kHeldSpeedSigma * std::abs(weak.dot(velocity_.head<2>())) + kHeldMinSpeedSigma;
  const Eigen::Vector2d w = u.match.weak_direction;  // matching frame, as pose_covariance_
  const double along = w.dot(pose_covariance_.topLeftCorner<2, 2>() * w);
  if (held_since_ == kNoStamp) {
    held_since_ = stamp - dt;
    held_start_variance_ = along;
  }
  if (u.velocity_held_blank) {
    u.held_direction = weak;
    u.held_speed_sigma = sigma_v;
  }
  const double grown = held_start_variance_ + std::pow(sigma_v * (stamp - held_since_), 2);
  if (grown > along) pose_covariance_.topLeftCorner<2, 2>() += (grown - along) * w * w.transpose();
}

void LaserOdometry::updateVelocity(const PreprocessedScan& scan, const LaserMount& mount, const Pose2D& previous,
                                   double dt, OdometryUpdate& u) {
  // Translation: exponential smoothing (kVelocityGain). Taking the last motion as the velocity feeds any
  // small per-match bias along a corridor back into the prior, where it adds up twice (a lag growing with
  // the square of the scans: maps come out too short); the smoothing scales that feedback by the gain.
  // Rotation: the last motion (turns start and stop fast; the heading is well constrained anyway).
  const Eigen::Vector3d measured = Eigen::Vector3d(u.delta.x, u.delta.y, u.delta.theta) / dt;
  const double g = kVelocityGain;
  const Eigen::Vector2d before = velocity_.head<2>();
  velocity_.head<2>() = (1.0 - g) * before + g * measured.head<2>();
  const bool short_range = shortRange(scan);
  // A released prior was refuted by the scan: nothing left to hold.
  if (u.match.prior_released) velocity_measured_ = false;
  if (short_range && u.match.degenerate) velocityAlongCorridor(scan, mount, previous, dt, before, measured, u);
  if (u.match.prior_released && config_.prior_acceleration > 0.0) {
    // A released match's step also takes back the lag the prior let build up (a position correction, not a
    // speed): the velocity changes by no more than the prior's acceleration allows over dt. Taken whole, one
    // 0.2 m catch-up read as 2 m/s and the hold carried 0.68 m/s on for a robot driving 0.3 m/s.
    const Eigen::Vector2d change = velocity_.head<2>() - before;
    const double limit = config_.prior_acceleration * dt;
    if (change.norm() > limit) velocity_.head<2>() = before + change * (limit / change.norm());
  }
  velocity_.z() = measured.z();
  last_flow_ = u.range_flow;
  last_flow_direction_ = u.match.weak_direction;
}

void LaserOdometry::velocityAlongCorridor(const PreprocessedScan& scan, const LaserMount& mount,
                                          const Pose2D& previous, double dt, const Eigen::Vector2d& before,
                                          const Eigen::Vector3d& measured, OdometryUpdate& u) {
  const double g = kVelocityGain;
  const double gw = config_.degenerate_velocity_gain;
  const bool hold = velocity_measured_;
  const Eigen::Vector2d weak = previous.rotation().transpose() * u.match.weak_direction;
  if (config_.range_flow_gain > 0.0 && previous_scan_.stamp == last_stamp_) {
    u.range_flow = measureRangeFlow(previous_scan_, scan, mount, u.delta, weak, dt, config_.range_flow);
  }
  const double before_w = weak.dot(before);
  // Only two consecutive flows that agree, and together refute the velocity, move it: one scan's flow is
  // noisier than the match's smoothed velocity (an edge, something moving: one flow can be far off) and a
  // few per cent off near edges, so within 3σ of their mean (and 0.02 m/s) the velocity stays as the rules
  // below make it. A robot that stops or starts in a corridor is far outside.
  // (The last flow's direction is in the matching frame; a weak direction's sign is arbitrary.)
  const double turn = last_flow_direction_.dot(u.match.weak_direction);
  const RangeFlow& b = u.range_flow;
  const double a_speed = turn < 0.0 ? -last_flow_.speed : last_flow_.speed;
  const double mean = 0.5 * (a_speed + b.speed), sigma = 0.5 * std::hypot(last_flow_.sigma, b.sigma);
  const bool refutes = last_flow_.valid && b.valid && std::abs(turn) > 0.99 &&
                       std::abs(a_speed - b.speed) <= 3.0 * std::hypot(last_flow_.sigma, b.sigma) &&
                       std::abs(mean - before_w) > 3.0 * sigma + 0.02;
  u.range_flow_applied = refutes;
  u.velocity_held = hold && !refutes;
  if (refutes) {
    // The speed along the corridor measured against the previous scans, not the local map.
    velocity_.head<2>() += weak * (before_w + config_.range_flow_gain * (mean - before_w) - weak.dot(velocity_.head<2>()));
  } else if (gw >= 0.0 || hold) {
    velocity_.head<2>() += weak * (((hold ? 0.0 : gw) - g) * weak.dot(measured.head<2>() - before));
  }
}

bool LaserOdometry::shortRange(const PreprocessedScan& scan) const {
  return config_.degenerate_velocity_max_range <= 0.0 || scan.range_max <= config_.degenerate_velocity_max_range;
}

bool LaserOdometry::blankAlongCorridor(const std::vector<Eigen::Vector2d>& base_points, const Pose2D& prior) const {
  if (last_weak_.squaredNorm() == 0.0) return false;  // the last match constrained every direction
  const Eigen::Vector2d w = Pose2D(0.0, 0.0, prior.theta).rotation().transpose() * last_weak_;
  return facingLength(base_points, w) <= kMinFacingLength;
}

void LaserOdometry::limitDegenerateStep(const Pose2D& prior, double prior_sigma, MatchResult& m) {
  if (!m.valid || !m.degenerate || m.prior_released || !(prior_sigma > 0.0)) return;
  // Along a degenerate direction the scan cannot place the robot farther from the constant-velocity prior
  // than an acceleration within prior_acceleration explains: a longer step is a false optimum of a flat
  // score (a corridor's), and one such step taken into the velocity sends the estimate backwards. A released
  // prior is the exception: the scan fitted clearly better away from it (a start from rest).
  const Eigen::Vector2d w = m.weak_direction;
  const double d = w.dot(Eigen::Vector2d(m.pose.x - prior.x, m.pose.y - prior.y));
  const double limit = kDegenerateStepSigmas * prior_sigma;
  if (std::abs(d) > limit) {
    const double cut = d - std::copysign(limit, d);
    m.pose.x -= cut * w.x();
    m.pose.y -= cut * w.y();
  }
}

void LaserOdometry::seeAlongCorridor(double stamp, double dt, const OdometryUpdate& u) {
  // seen_along_ spans kHoldSpeedWindow s back from its newest pose, not from now: degenerate matches between
  // it and a blank stretch (a corridor's last metres before it turns blank) do not age it out.
  const double newest =
      seen_along_.empty() ? stamp : std::max(seen_along_.back().first, stamp - kHoldSpeedWindow);
  while (!seen_along_.empty() && seen_along_.front().first < newest - kHoldSpeedWindow) seen_along_.pop_front();
  // A blank stretch starts: fit the held speed, unless no match has measured the motion since the last fit
  // (the blank test flickering at a stretch's edge), in which case the speed held stands.
  const bool measured_since = seen_along_.empty() || seen_along_.back().first > fitted_through_;
  if (u.velocity_held_blank && !was_blank_ && measured_since) {
    holdSpeedFromSeenMatches(stamp, u.match.weak_direction);
    fitted_through_ = seen_along_.empty() ? stamp : seen_along_.back().first;
  }
  // Only matches that measured the motion along every direction, on the current straight run: a degenerate
  // match's position along the corridor is the prior's plus the score's ripple (it lags), and a turn ends the
  // run whose speed is fitted.
  if (!u.match.degenerate && !u.match.weak && !u.velocity_held_blank) {
    while (!seen_along_.empty() &&
           !HeldSpeed::sameRun(seen_along_.front().second.theta, pose_.theta)) {
      seen_along_.pop_front();
    }
    seen_along_.push_back({stamp, pose_});
    held_speed_.observe(pose_.theta, dt);
  }
  was_blank_ = u.velocity_held_blank;
}

void LaserOdometry::holdSpeedFromSeenMatches(double stamp, const Eigen::Vector2d& weak) {
  // A blank stretch starts: the speed it keeps along the corridor is a line fitted to the positions of the
  // constrained matches of the straight run before it (up to kHoldSpeedWindow s), rather than the last few
  // scans' smoothed velocity (a few per cent off, which a 40 m corridor turns into metres). The window
  // halves until its two halves agree (no acceleration inside it). The fit updates the run's held speed
  // by its variance (HeldSpeed): a few constrained matches inside a long blank stretch barely move it.
  const Eigen::Matrix2d frame = pose_.rotation();
  const Eigen::Vector2d w = frame.transpose() * weak;  // base frame
  const double end = seen_along_.empty() ? stamp : seen_along_.back().first;
  auto speed = [&](double from, double to, double* dt) {
    const Pose2D* a;
    const Pose2D* b;
    if (!spanOf(seen_along_, from, to, &a, &b, dt)) return std::numeric_limits<double>::quiet_NaN();
    return w.dot(frame.transpose() * Eigen::Vector2d(b->x - a->x, b->y - a->y)) / *dt;
  };
  // With no window free of acceleration: the smoothed velocity, no better known than a fit over the shortest one.
  double v = w.dot(velocity_.head<2>()), variance = HeldSpeed::fitVariance(kMinHoldSpeedWindow);
  for (double span = kHoldSpeedWindow; span >= kMinHoldSpeedWindow; span *= 0.5) {
    double covered = 0.0, half = 0.0;
    const double all = speed(end - span, end, &covered), first = speed(end - span, end - 0.5 * span, &half),
                 second = speed(end - 0.5 * span, end, &half);
    if (!std::isfinite(all) || !std::isfinite(first) || !std::isfinite(second)) continue;
    if (std::abs(first - second) > kHoldSpeedAgreement * std::abs(all) + kHoldSpeedAgreementMin) continue;
    v = speedFit(seen_along_, end - span, end, frame, w, all);
    variance = HeldSpeed::fitVariance(covered);
    break;
  }
  const double held = held_speed_.fuse(v, variance, pose_.theta, weak);
  velocity_.head<2>() += w * (held - w.dot(velocity_.head<2>()));
}

bool LaserOdometry::keyframeDue(const MatchResult& match) {
  const Pose2D from_kf = between(keyframes_.back().pose, pose_);
  if (keyframe_matched_ < 0.0) keyframe_matched_ = match.matched_fraction;
  const bool overlap_dropped = config_.keyframe_overlap_drop > 0.0 &&
                               match.matched_fraction < keyframe_matched_ - config_.keyframe_overlap_drop;
  return std::hypot(from_kf.x, from_kf.y) > config_.keyframe_distance ||
         std::abs(from_kf.theta) > config_.keyframe_angle || overlap_dropped;
}

}  // namespace laser_dpslam
