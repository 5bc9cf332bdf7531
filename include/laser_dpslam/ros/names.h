// Every topic, service and default frame name of the package's nodes, in one place.
#pragma once

namespace laser_dpslam {
namespace names {

// Topics (relative: remap them in launch files).
constexpr const char* kScanTopic = "scan";
constexpr const char* kOdomTopic = "odom";
constexpr const char* kOdometryHoldTopic = "odom_held";  ///< laser_odometry_node → dpslam_node (msg/OdometryHold.msg)
constexpr const char* kWheelOdomTopic = "wheel_odom";  ///< the wheels' odometry, laser_odometry_node's input
constexpr const char* kMapTopic = "map";
constexpr const char* kMapMetadataTopic = "map_metadata";
constexpr const char* kPoseTopic = "pose";
constexpr const char* kTrajectoryTopic = "trajectory";
constexpr const char* kParticlesTopic = "particles";

// Services.
constexpr const char* kDynamicMapService = "dynamic_map";
constexpr const char* kSaveMapService = "save_map";

// Frames are parameters: their defaults (REP-105) are in the nodes' settings (odometry_parameters.h,
// dpslam_parameters.h).

}  // namespace names
}  // namespace laser_dpslam
