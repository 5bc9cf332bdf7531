// TUM trajectory files (`stamp x y z qx qy qz qw`) and atomic file writing.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "laser_dpslam/common/pose2d.h"

namespace laser_dpslam {

struct StampedPose {
  double stamp = 0.0;
  Pose2D pose;
};

/// Writes `content` to `path` through a temporary file in the same directory and a rename, so a reader
/// never sees a partial file and an existing file survives a failed write. Throws std::runtime_error
/// naming the path (and errno's text) on failure.
void writeFileAtomically(const std::string& path, const std::string& content);

/// Several files (path, content) that belong together: all are written to temporaries (and synced)
/// first, then renamed in the given order. A failure while writing (no space, no permission, no
/// directory) leaves every existing file untouched and no temporary behind; only a failing rename
/// (e.g. the destination is a directory) can leave the files before it replaced. Throws
/// std::runtime_error naming the path.
void writeFilesAtomically(const std::vector<std::pair<std::string, std::string>>& files);

/// TUM text of a planar trajectory (z = 0, rotation about z), stamps with 9 decimals.
std::string formatTum(const std::vector<StampedPose>& poses);

/// Reads a TUM file (planar part); throws std::runtime_error "FILE:LINE: what" on malformed lines.
std::vector<StampedPose> readTum(const std::string& path);

/// The pose of `poses` (sorted by stamp) at `stamp`: linear in x, y and along the shorter arc in θ between
/// the two poses around it. False when `stamp` lies outside their time span (no extrapolation).
bool interpolatePose(const std::vector<StampedPose>& poses, double stamp, Pose2D* pose);

}  // namespace laser_dpslam
