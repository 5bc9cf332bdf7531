#include "laser_dpslam/common/trajectory_io.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <unistd.h>

namespace laser_dpslam {

namespace {

/// Creates (or truncates) `path` and writes `content` to disk (flush + fsync). On failure returns false
/// with errno's text in *error; *created says whether the file exists now (a partial file to remove).
bool writeAndSync(const std::string& path, const std::string& content, bool* created, std::string* error) {
  FILE* f = std::fopen(path.c_str(), "wb");
  *created = f != nullptr;
  if (!f) {
    *error = std::strerror(errno);
    return false;
  }
  const bool written = std::fwrite(content.data(), 1, content.size(), f) == content.size();
  const int write_errno = errno;
  const bool flushed = written && std::fflush(f) == 0 && ::fsync(::fileno(f)) == 0;
  const int flush_errno = errno;
  const bool closed = std::fclose(f) == 0;
  const int close_errno = errno;
  if (written && flushed && closed) return true;
  *error = std::strerror(!written ? write_errno : (!flushed ? flush_errno : close_errno));
  return false;
}

}  // namespace

void writeFileAtomically(const std::string& path, const std::string& content) {
  writeFilesAtomically({{path, content}});
}

void writeFilesAtomically(const std::vector<std::pair<std::string, std::string>>& files) {
  // Every temporary is complete on disk before the first rename: running out of space or permission
  // while writing any of them leaves all previous files as they were (a map's PGM and YAML stay a pair).
  std::vector<std::string> temps;
  auto discard = [&temps](std::size_t from) {
    for (std::size_t k = from; k < temps.size(); ++k) std::remove(temps[k].c_str());
  };
  for (const auto& file : files) {
    const std::string tmp = file.first + ".tmp." + std::to_string(::getpid());
    bool created = false;
    std::string error;
    const bool ok = writeAndSync(tmp, file.second, &created, &error);
    if (created) temps.push_back(tmp);  // only what this call created is removed
    if (!ok) {
      discard(0);
      throw std::runtime_error("cannot write '" + file.first + "': " + error);
    }
  }
  for (std::size_t i = 0; i < files.size(); ++i) {
    if (std::rename(temps[i].c_str(), files[i].first.c_str()) != 0) {
      const int e = errno;
      discard(i);
      throw std::runtime_error("cannot write '" + files[i].first + "': " + std::strerror(e) +
                               (i > 0 ? " (the files listed before it were already replaced)" : ""));
    }
  }
}

std::string formatTum(const std::vector<StampedPose>& poses) {
  std::string out;
  out.reserve(poses.size() * 96);
  char line[256];
  for (const auto& p : poses) {
    std::snprintf(line, sizeof(line), "%.9f %.6f %.6f 0 0 0 %.9f %.9f\n", p.stamp, p.pose.x, p.pose.y,
                  std::sin(0.5 * p.pose.theta), std::cos(0.5 * p.pose.theta));
    out += line;
  }
  return out;
}

std::vector<StampedPose> readTum(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot open '" + path + "'");
  std::vector<StampedPose> poses;
  std::string line;
  int n = 0;
  while (std::getline(in, line)) {
    ++n;
    const auto first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos || line[first] == '#') continue;
    std::istringstream ss(line);
    double v[8];
    for (double& x : v) {
      if (!(ss >> x)) throw std::runtime_error(path + ":" + std::to_string(n) + ": expected 8 numbers");
    }
    for (double x : v) {
      if (!std::isfinite(x)) throw std::runtime_error(path + ":" + std::to_string(n) + ": non-finite value");
    }
    StampedPose p;
    p.stamp = v[0];
    // Yaw of the quaternion (qx, qy, qz, qw).
    const double qx = v[4], qy = v[5], qz = v[6], qw = v[7];
    p.pose = Pose2D(v[1], v[2], std::atan2(2.0 * (qw * qz + qx * qy), 1.0 - 2.0 * (qy * qy + qz * qz)));
    poses.push_back(p);
  }
  return poses;
}

bool interpolatePose(const std::vector<StampedPose>& poses, double stamp, Pose2D* pose) {
  if (poses.empty() || !std::isfinite(stamp) || stamp < poses.front().stamp || stamp > poses.back().stamp) return false;
  const auto hi = std::lower_bound(poses.begin(), poses.end(), stamp,
                                   [](const StampedPose& p, double t) { return p.stamp < t; });
  if (hi->stamp == stamp || hi == poses.begin()) {
    *pose = hi->pose;
    return true;
  }
  const StampedPose& a = *(hi - 1);
  const StampedPose& b = *hi;
  *pose = interpolate(a.pose, b.pose, (stamp - a.stamp) / (b.stamp - a.stamp));
  return true;
}

}  // namespace laser_dpslam
