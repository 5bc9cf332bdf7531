// Synthetic rooms for the matcher and odometry tests, built on the floor-plan simulator.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "laser_dpslam/sim/floor_plan.h"

namespace laser_dpslam {
namespace test {

struct Box {
  double x0, y0, x1, y1;  // m
};

/// A plan of `w`×`h` metres at `res` m/cell whose occupied cells are the given boxes.
inline FloorPlan planFromBoxes(double w, double h, double res, const std::vector<Box>& boxes) {
  const int nx = static_cast<int>(w / res), ny = static_cast<int>(h / res);
  std::vector<std::uint8_t> occ(static_cast<std::size_t>(nx) * ny, 0);
  for (const Box& b : boxes) {
    for (int iy = 0; iy < ny; ++iy) {
      for (int ix = 0; ix < nx; ++ix) {
        const double x = (ix + 0.5) * res, y = (iy + 0.5) * res;
        if (x >= b.x0 && x <= b.x1 && y >= b.y0 && y <= b.y1) occ[static_cast<std::size_t>(iy) * nx + ix] = 1;
      }
    }
  }
  return FloorPlan::fromOccupancy(nx, ny, res, Eigen::Vector2d(0, 0), occ);
}

/// An 8 m × 6 m room (walls 0.1 m thick) with an inner wall stub, a pillar and a cabinet, so that no
/// direction is unconstrained and the scene is not symmetric.
inline FloorPlan furnishedRoom() {
  return planFromBoxes(8.0, 6.0, 0.02,
                       {{0.0, 0.0, 8.0, 0.1}, {0.0, 5.9, 8.0, 6.0}, {0.0, 0.0, 0.1, 6.0}, {7.9, 0.0, 8.0, 6.0},
                        {4.0, 0.0, 4.1, 2.2},    // wall stub from the bottom wall
                        {5.8, 3.8, 6.2, 4.2},    // pillar
                        {1.0, 4.9, 2.4, 5.9},    // cabinet against the top wall
                        {0.1, 1.0, 0.6, 1.6}});  // box in the left wall
}

}  // namespace test
}  // namespace laser_dpslam
