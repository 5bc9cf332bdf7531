// A particle's DP-SLAM map as an occupancy grid (nav_msgs/OccupancyGrid values, no ROS types), and its
// files: map_server PGM + YAML (written atomically) and a PNG picture with the trajectory drawn on it.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "laser_dpslam/common/trajectory_io.h"
#include "laser_dpslam/slam/ancestry_tree.h"
#include "laser_dpslam/slam/dpslam_map.h"

namespace laser_dpslam {

/// nav_msgs/OccupancyGrid's content: cell (ix, iy) covers [origin_x + ix·res, origin_x + (ix+1)·res) ×
/// [origin_y + iy·res, …); data[iy·width + ix], row 0 = lowest y; -1 unknown, 0 free … 100 occupied.
struct OccupancyGridData {
  double resolution = 0.05;  ///< m per cell
  int width = 0;             ///< cells
  int height = 0;            ///< cells
  double origin_x = 0.0;     ///< m, map-frame x of the corner of cell (0, 0)
  double origin_y = 0.0;     ///< m
  std::vector<std::int8_t> data;

  std::int8_t at(int ix, int iy) const { return data[static_cast<std::size_t>(iy) * width + ix]; }
};

/// Occupancy value of a penetration-map entry: 100·(1 − exp(−density·stop_length)), rounded; the
/// probability that a beam crossing `stop_length` metres of such cells stops. nullptr → -1 (unknown).
std::int8_t occupancyValue(const MapEntry* entry, double stop_length);

/// The map `node` sees, cropped to its observed cells plus `margin` cells.
OccupancyGridData occupancyFromMap(const DpSlamMap& map, const AncestryTree& tree, int node, double stop_length,
                                   int margin = 2);

/// map_server image values: occupied (≥ 65) 0, free (< 19.6, i.e. below free_thresh 0.196) 254, else 205.
std::uint8_t pgmValue(std::int8_t occupancy);
/// PGM (P5) bytes of the grid: image row 0 = top = highest y.
std::string formatPgm(const OccupancyGridData& grid);
/// map_server YAML naming `image` (relative to the YAML's directory).
std::string formatMapYaml(const OccupancyGridData& grid, const std::string& image);
/// Writes YAML_PATH and the PGM beside it (same stem, .pgm) with writeFilesAtomically: on a failure to
/// write either, both previous files stay as they were. Throws std::runtime_error naming the path.
void writeMapServerFiles(const OccupancyGridData& grid, const std::string& yaml_path);

/// PNG bytes of an 8-bit palette image (rows top to bottom, `indices` row-major), zlib stream with fixed
/// Huffman codes (no external library).
std::string encodePalettePng(int width, int height, const std::vector<std::uint8_t>& indices,
                             const std::vector<std::uint8_t>& rgb_palette);
/// The map as a picture (grey levels by occupancy, unknown pale blue) with the trajectory in red, its
/// start in green and its end in blue; written atomically. Throws std::runtime_error on failure.
void writeMapPng(const OccupancyGridData& grid, const std::vector<StampedPose>& trajectory, const std::string& png_path);

}  // namespace laser_dpslam
