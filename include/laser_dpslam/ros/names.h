// Every topic, service and default frame name of the package's nodes, in one place.
#pragma once

namespace laser_dpslam {
namespace names {

// Topics (relative: remap them in launch files).
constexpr const char* kScanTopic = "scan";
constexpr const char* kOdomTopic = "odom";

// Default frames (REP-105); each node has a parameter to change them.
constexpr const char* kOdomFrame = "odom";
constexpr const char* kBaseFrame = "base_link";
constexpr const char* kMapFrame = "map";

}  // namespace names
}  // namespace laser_dpslam
