// The laser odometry's parameters: one table, read from any ParameterSource (YAML file or ROS).
// Names and units are documented in config/laser_odometry.yaml and doc/parameters.md.
#pragma once

#include "laser_dpslam/laser_odometry.h"
#include "laser_dpslam/parameter_source.h"
#include "laser_dpslam/scan_preprocessor.h"

namespace laser_dpslam {

/// Overwrites the fields whose keys are present; throws std::invalid_argument naming the parameter when a
/// value is of the wrong type or out of its valid range.
void readOdometryParameters(const ParameterSource& source, LaserOdometryConfig& odometry,
                            ScanPreprocessorConfig& preprocessing);

/// The keys laser_odometry_node reads itself (frames, TF), beside readOdometryParameters's.
const std::vector<std::string>& odometryNodeKeys();

}  // namespace laser_dpslam
