// The laser odometry node's parameters: one registry (parameter_registry.h) from which the reader, the
// check of config/laser_odometry.yaml and doc/parameters.md come. Adding a key is one entry in
// src/core/odometry/odometry_parameters.cpp; its default is the settings struct's.
#pragma once

#include <string>
#include <vector>

#include "laser_dpslam/common/parameter_registry.h"
#include "laser_dpslam/common/parameter_source.h"
#include "laser_dpslam/odometry/laser_odometry.h"
#include "laser_dpslam/scan/scan_preprocessor.h"

namespace laser_dpslam {

/// Everything laser_odometry_node is configured with.
struct OdometryNodeSettings {
  std::string base_frame = "base_link";
  std::string odom_frame = "odom";
  bool publish_tf = true;
  double transform_timeout = 0.2;  ///< s
  bool use_wheel_odometry = false;  ///< subscribe the wheels' odometry (LaserOdometry::addWheelOdometry)
  LaserOdometryConfig odometry;
  ScanPreprocessorConfig preprocessing;
};

/// Every key laser_odometry_node reads, in documentation order.
const std::vector<Parameter<OdometryNodeSettings>>& odometryParameters();

/// Overwrites the fields whose keys are present and checks them together; throws std::invalid_argument
/// naming the key, the value and its range when a value is of the wrong type or out of range.
void readOdometryNodeParameters(const ParameterSource& source, OdometryNodeSettings& settings);

/// The same for the odometry alone (dpslam_offline): the node's own keys are read, and so count as known,
/// but not kept.
void readOdometryParameters(const ParameterSource& source, LaserOdometryConfig& odometry,
                            ScanPreprocessorConfig& preprocessing);

}  // namespace laser_dpslam
