// The SLAM's parameters: one table, read from any ParameterSource (YAML file or ROS). Names and units
// are documented in config/dpslam.yaml (which test/dpslam_parameters_test.cpp keeps equal to the defaults).
#pragma once

#include "laser_dpslam/dpslam.h"
#include "laser_dpslam/parameter_source.h"

namespace laser_dpslam {

/// Overwrites the fields whose keys are present; throws std::invalid_argument naming the parameter when a
/// value is of the wrong type or out of its valid range.
void readDpSlamParameters(const ParameterSource& source, DpSlamConfig& config);

/// The keys dpslam_node reads itself (frames, publishing, TF, range limits), beside readDpSlamParameters's.
const std::vector<std::string>& dpslamNodeKeys();

}  // namespace laser_dpslam
