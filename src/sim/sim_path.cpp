#include "laser_dpslam/sim/sim_path.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "laser_dpslam/sim/text_words.h"

namespace laser_dpslam {

void PathConfig::validate() const {
  auto bad = [](const std::string& what) { throw std::invalid_argument("PathConfig: " + what); };
  auto positive = [&](double v, const char* name) {
    if (!(v > 0.0) || !std::isfinite(v)) bad(std::string(name) + " must be positive and finite");
  };
  positive(cruise_speed, "cruise_speed");
  positive(max_speed, "max_speed");
  positive(turn_rate, "turn_rate");
  positive(max_turn_rate, "max_turn_rate");
  positive(linear_acceleration, "linear_acceleration");
  positive(angular_acceleration, "angular_acceleration");
  if (cruise_speed > max_speed) bad("cruise_speed exceeds max_speed");
  if (turn_rate > max_turn_rate) bad("turn_rate exceeds max_turn_rate");
  if (!(start_pause >= 0.0) || !(end_pause >= 0.0) || !std::isfinite(start_pause) || !std::isfinite(end_pause))
    bad("pauses must be >= 0 and finite");
}

namespace {

/// A trapezoidal (or triangular) profile covering `amount` ≥ 0 with peak rate ≤ `rate_limit`.
struct Profile {
  double amount = 0.0, accel = 1.0, peak = 0.0, t_acc = 0.0, t_cruise = 0.0;

  Profile() = default;
  Profile(double amount_, double rate_limit, double accel_) : amount(amount_), accel(accel_) {
    if (amount <= 0.0) return;
    if (amount >= rate_limit * rate_limit / accel) {
      peak = rate_limit;
      t_acc = peak / accel;
      t_cruise = (amount - peak * t_acc) / peak;
    } else {
      peak = std::sqrt(amount * accel);
      t_acc = peak / accel;
      t_cruise = 0.0;
    }
  }
  double duration() const { return 2.0 * t_acc + t_cruise; }
  /// Distance covered and rate at time t ∈ [0, duration()].
  void at(double t, double* s, double* rate) const {
    const double total = duration();
    t = std::min(std::max(t, 0.0), total);
    if (t < t_acc) {
      *s = 0.5 * accel * t * t;
      *rate = accel * t;
    } else if (t < t_acc + t_cruise) {
      *s = 0.5 * peak * t_acc + peak * (t - t_acc);
      *rate = peak;
    } else {
      const double tau = total - t;
      *s = amount - 0.5 * accel * tau * tau;
      *rate = accel * tau;
    }
  }
};

struct Primitive {
  enum Kind { kPause, kTurn, kDrive } kind = kPause;
  double t0 = 0.0;
  double duration = 0.0;
  Pose2D start;
  double sign = 1.0;  ///< direction of a turn
  Profile profile;

  TimedPose at(double t) const {
    TimedPose tp;
    tp.stamp = t;
    tp.pose = start;
    if (kind == kPause) return tp;
    double s = 0.0, rate = 0.0;
    profile.at(t - t0, &s, &rate);
    if (kind == kTurn) {
      tp.pose.theta = normalizeAngle(start.theta + sign * s);
      tp.w = sign * rate;
    } else {
      tp.pose.x = start.x + s * std::cos(start.theta);
      tp.pose.y = start.y + s * std::sin(start.theta);
      tp.v = rate;
    }
    return tp;
  }
};

std::vector<Waypoint> distinctWaypoints(const std::vector<Waypoint>& waypoints, const PathConfig& config) {
  std::vector<Waypoint> out;
  for (const auto& w : waypoints) {
    if (!w.position.allFinite()) throw std::invalid_argument("samplePath: waypoint with a non-finite coordinate");
    if (!(w.pause >= 0.0) || !std::isfinite(w.pause)) throw std::invalid_argument("samplePath: pause must be >= 0");
    if (!(w.speed >= 0.0) || w.speed > config.max_speed)
      throw std::invalid_argument("samplePath: waypoint speed must be in (0, max_speed], or 0 for the default");
    if (out.empty() || (w.position - out.back().position).norm() > 1e-9) {
      out.push_back(w);
    } else {  // a duplicate: one stop, its pauses added, the later speed
      out.back().pause += w.pause;
      out.back().speed = w.speed;
    }
  }
  if (out.size() < 2) throw std::invalid_argument("samplePath: need at least two distinct waypoints");
  return out;
}

std::vector<Primitive> buildPrimitives(const std::vector<Waypoint>& waypoints_in, const PathConfig& config) {
  config.validate();
  const std::vector<Waypoint> wps = distinctWaypoints(waypoints_in, config);
  std::vector<Primitive> prims;
  double t = 0.0;
  const Eigen::Vector2d d0 = wps[1].position - wps[0].position;
  Pose2D pose(wps[0].position.x(), wps[0].position.y(), std::atan2(d0.y(), d0.x()));
  auto push = [&](Primitive p) {
    p.t0 = t;
    p.start = pose;
    t += p.duration;
    prims.push_back(p);
  };
  auto pause = [&](double seconds) {
    if (!(seconds > 0.0)) return;
    Primitive p;
    p.kind = Primitive::kPause;
    p.duration = seconds;
    push(p);
  };
  pause(config.start_pause);
  for (std::size_t i = 0; i + 1 < wps.size(); ++i) {
    pause(wps[i].pause);
    const Eigen::Vector2d d = wps[i + 1].position - wps[i].position;
    const double heading = std::atan2(d.y(), d.x());
    const double turn = normalizeAngle(heading - pose.theta);
    if (std::abs(turn) > 1e-12) {
      Primitive p;
      p.kind = Primitive::kTurn;
      p.sign = turn > 0 ? 1.0 : -1.0;
      p.profile = Profile(std::abs(turn), config.turn_rate, config.angular_acceleration);
      p.duration = p.profile.duration();
      push(p);
    }
    pose.theta = heading;
    Primitive p;
    p.kind = Primitive::kDrive;
    const double speed = wps[i].speed > 0.0 ? wps[i].speed : config.cruise_speed;
    p.profile = Profile(d.norm(), speed, config.linear_acceleration);
    p.duration = p.profile.duration();
    push(p);
    pose.x = wps[i + 1].position.x();
    pose.y = wps[i + 1].position.y();
  }
  pause(wps.back().pause);
  Primitive end;
  end.kind = Primitive::kPause;
  end.duration = config.end_pause;
  push(end);  // zero-length when end_pause is 0: holds the final pose
  return prims;
}

}  // namespace

std::vector<Waypoint> toWaypoints(const std::vector<Eigen::Vector2d>& positions) {
  std::vector<Waypoint> out(positions.size());
  for (std::size_t i = 0; i < positions.size(); ++i) out[i].position = positions[i];
  return out;
}

std::vector<Eigen::Vector2d> positionsOf(const std::vector<Waypoint>& waypoints) {
  std::vector<Eigen::Vector2d> out;
  out.reserve(waypoints.size());
  for (const auto& w : waypoints) out.push_back(w.position);
  return out;
}

double pathDuration(const std::vector<Eigen::Vector2d>& waypoints, const PathConfig& config) {
  return pathDuration(toWaypoints(waypoints), config);
}

std::vector<TimedPose> samplePath(const std::vector<Eigen::Vector2d>& waypoints, double rate_hz,
                                  const PathConfig& config) {
  return samplePath(toWaypoints(waypoints), rate_hz, config);
}

double pathDuration(const std::vector<Waypoint>& waypoints, const PathConfig& config) {
  const std::vector<Primitive> prims = buildPrimitives(waypoints, config);
  return prims.back().t0 + prims.back().duration;
}

std::vector<TimedPose> samplePath(const std::vector<Waypoint>& waypoints, double rate_hz,
                                  const PathConfig& config) {
  if (!(rate_hz > 0.0) || !std::isfinite(rate_hz)) throw std::invalid_argument("samplePath: rate_hz must be positive");
  const std::vector<Primitive> prims = buildPrimitives(waypoints, config);
  const double total = prims.back().t0 + prims.back().duration;
  const long n = static_cast<long>(std::ceil(total * rate_hz - 1e-9));
  std::vector<TimedPose> out;
  out.reserve(static_cast<std::size_t>(n + 1));
  std::size_t j = 0;
  for (long k = 0; k <= n; ++k) {
    const double stamp = static_cast<double>(k) / rate_hz;
    const double t = std::min(stamp, total);
    while (j + 1 < prims.size() && t >= prims[j].t0 + prims[j].duration) ++j;
    TimedPose tp = prims[j].at(t);
    tp.stamp = stamp;
    out.push_back(tp);
  }
  return out;
}

namespace {

/// Parses a waypoint file whose lines hold min_fields to max_fields numbers; `expected` names the format.
std::vector<std::vector<double>> loadNumberLines(const std::string& path, std::size_t min_fields,
                                                 std::size_t max_fields, const std::string& expected) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot open the waypoint file (missing or unreadable)");
  std::vector<std::vector<double>> out;
  std::string line;
  int line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    const std::vector<std::string> words = lineWords(line);
    if (words.empty()) continue;
    auto fail = [&](const std::string& why) {
      throw std::runtime_error(path + ":" + std::to_string(line_no) + ": " + why + " (expected " + expected + ")");
    };
    if (words.size() < min_fields || words.size() > max_fields) {
      const std::string n = min_fields == max_fields ? std::to_string(min_fields)
                                                     : std::to_string(min_fields) + " to " + std::to_string(max_fields);
      fail("expected " + n + " numbers, found " + std::to_string(words.size()) + " fields");
    }
    std::vector<double> values;
    for (const std::string& word : words) {
      const char* s = word.c_str();
      char* end = nullptr;
      errno = 0;
      const double v = std::strtod(s, &end);
      if (end == s || *end != '\0' || errno == ERANGE || !std::isfinite(v)) fail("'" + word + "' is not a number");
      values.push_back(v);
    }
    if (values.size() > 2 && values[2] < 0.0) fail("the pause must be >= 0 s");
    if (values.size() > 3 && values[3] < 0.0) fail("the speed must be > 0 m/s (0: the default)");
    out.push_back(values);
  }
  if (in.bad()) throw std::runtime_error(path + ": read error");
  if (out.size() < 2) throw std::runtime_error(path + ": needs at least two waypoints, found " + std::to_string(out.size()));
  return out;
}

}  // namespace

std::vector<Eigen::Vector2d> loadWaypoints(const std::string& path) {
  std::vector<Eigen::Vector2d> out;
  for (const auto& v : loadNumberLines(path, 2, 2, "`x y` in metres")) out.emplace_back(v[0], v[1]);
  return out;
}

std::vector<Waypoint> loadTimedWaypoints(const std::string& path) {
  std::vector<Waypoint> out;
  for (const auto& v : loadNumberLines(path, 2, 4, "`x y [pause_s [speed_mps]]`")) {
    Waypoint w;
    w.position = Eigen::Vector2d(v[0], v[1]);
    if (v.size() > 2) w.pause = v[2];
    if (v.size() > 3) w.speed = v[3];
    out.push_back(w);
  }
  return out;
}

bool isClosedLoop(const std::vector<Eigen::Vector2d>& waypoints, double tolerance) {
  return waypoints.size() >= 3 && (waypoints.front() - waypoints.back()).norm() <= tolerance;
}

std::vector<Eigen::Vector2d> repeatLoop(const std::vector<Eigen::Vector2d>& loop, int laps) {
  if (laps < 1) throw std::invalid_argument("repeatLoop: laps must be at least 1");
  if (loop.size() < 2) throw std::invalid_argument("repeatLoop: need at least two waypoints");
  std::vector<Eigen::Vector2d> closed = loop;
  if (!isClosedLoop(closed)) closed.push_back(loop.front());
  std::vector<Eigen::Vector2d> out = closed;
  for (int lap = 1; lap < laps; ++lap) out.insert(out.end(), closed.begin() + 1, closed.end());
  return out;
}

std::vector<Waypoint> repeatLoop(const std::vector<Waypoint>& loop, int laps) {
  if (laps < 1) throw std::invalid_argument("repeatLoop: laps must be at least 1");
  if (loop.size() < 2) throw std::invalid_argument("repeatLoop: need at least two waypoints");
  std::vector<Waypoint> closed = loop;
  if (!isClosedLoop(positionsOf(closed))) closed.push_back(loop.front());
  std::vector<Waypoint> out = closed;
  for (int lap = 1; lap < laps; ++lap) out.insert(out.end(), closed.begin() + 1, closed.end());
  return out;
}

std::string builtinPathFile(const std::string& plan_yaml, const std::string& name) {
  const std::filesystem::path yaml(plan_yaml);
  return (yaml.parent_path() / (yaml.stem().string() + "_" + name + ".txt")).string();
}

std::string checkPathClearance(const FloorPlan& plan, const std::vector<Eigen::Vector2d>& waypoints,
                               double robot_radius) {
  return checkPathClearance([&plan](const Eigen::Vector2d& p, double r) { return plan.clearance(p, r); },
                            std::max(0.25 * plan.resolution(), 1e-3), waypoints, robot_radius);
}

std::string checkPathClearance(const std::function<double(const Eigen::Vector2d&, double)>& clearance,
                               double step, const std::vector<Eigen::Vector2d>& waypoints, double robot_radius) {
  for (std::size_t i = 0; i < waypoints.size(); ++i) {
    const Eigen::Vector2d a = waypoints[i];
    const Eigen::Vector2d b = i + 1 < waypoints.size() ? waypoints[i + 1] : a;
    const double len = (b - a).norm();
    const int n = std::max(1, static_cast<int>(std::ceil(len / step)));
    for (int k = 0; k <= n; ++k) {
      const Eigen::Vector2d p = a + (b - a) * (static_cast<double>(k) / n);
      const double c = clearance(p, robot_radius);
      if (c < robot_radius) {
        std::ostringstream msg;
        msg.precision(3);
        msg << std::fixed;
        if (i + 1 < waypoints.size()) {
          msg << "segment from waypoint " << i + 1 << " (" << a.x() << ", " << a.y() << ") to waypoint " << i + 2
              << " (" << b.x() << ", " << b.y() << ")";
        } else {
          msg << "waypoint " << i + 1 << " (" << a.x() << ", " << a.y() << ")";
        }
        msg << " passes within " << c << " m of a wall at (" << p.x() << ", " << p.y() << "); the robot needs "
            << robot_radius << " m";
        return msg.str();
      }
    }
  }
  return "";
}

}  // namespace laser_dpslam
