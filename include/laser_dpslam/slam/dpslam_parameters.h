// The SLAM node's parameters: one registry (parameter_registry.h) from which the reader, the check of
// config/dpslam.yaml and doc/parameters.md come. Adding a key is one entry in src/core/slam/dpslam_parameters.cpp;
// its default is the settings struct's.
#pragma once

#include <string>
#include <vector>

#include "laser_dpslam/common/parameter_registry.h"
#include "laser_dpslam/common/parameter_source.h"
#include "laser_dpslam/scan/scan_preprocessor.h"
#include "laser_dpslam/slam/dpslam.h"

namespace laser_dpslam {

/// Everything dpslam_node is configured with.
struct DpSlamNodeSettings {
  std::string map_frame = "map";
  std::string odom_frame = "odom";
  std::string base_frame = "base_link";
  double map_update_interval = 2.0;  ///< s of data time
  bool publish_particles = true;
  double transform_timeout = 0.2;  ///< s
  /// Benchmarks only: after each scan the node busy-waits (this − 1) × that scan's processing CPU time,
  /// as a CPU this many times slower would take (scripts/benchmark_lag.sh). 1 = off.
  double work_multiplier = 1.0;
  ScanPreprocessorConfig preprocessing;  ///< only min_range and max_range are parameters
  DpSlamConfig slam;
};

/// Every key dpslam_node reads, in documentation order.
const std::vector<Parameter<DpSlamNodeSettings>>& dpslamParameters();

/// Overwrites the fields whose keys are present and checks them together; throws std::invalid_argument
/// naming the key, the value and its range when a value is of the wrong type or out of range.
void readDpSlamNodeParameters(const ParameterSource& source, DpSlamNodeSettings& settings);

/// The same for the SLAM alone (dpslam_offline): the node's own keys are read, and so count as known, but
/// not kept.
void readDpSlamParameters(const ParameterSource& source, DpSlamConfig& config);

}  // namespace laser_dpslam
