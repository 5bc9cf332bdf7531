#include "laser_dpslam/trajectory_io.h"

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <unistd.h>

namespace laser_dpslam {

void writeFileAtomically(const std::string& path, const std::string& content) {
  const std::string tmp = path + ".tmp." + std::to_string(::getpid());
  FILE* f = std::fopen(tmp.c_str(), "wb");
  if (!f) throw std::runtime_error("cannot write '" + path + "': " + std::strerror(errno));
  const bool written = std::fwrite(content.data(), 1, content.size(), f) == content.size();
  const int write_errno = errno;
  const bool flushed = std::fflush(f) == 0 && ::fsync(::fileno(f)) == 0;
  const int flush_errno = errno;
  const bool closed = std::fclose(f) == 0;
  if (!written || !flushed || !closed) {
    std::remove(tmp.c_str());
    throw std::runtime_error("cannot write '" + path + "': " +
                             std::strerror(!written ? write_errno : (!flushed ? flush_errno : errno)));
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    const int e = errno;
    std::remove(tmp.c_str());
    throw std::runtime_error("cannot write '" + path + "': " + std::strerror(e));
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

}  // namespace laser_dpslam
