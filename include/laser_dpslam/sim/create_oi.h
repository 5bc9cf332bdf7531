// An emulated iRobot Create (1) speaking the Open Interface (iRobot "Create Open Interface" v2 manual) as
// libcreate (under create_driver) uses it: start, safe/full mode, drive / drive direct, sensor stream
// requests, streamed sensor frames. Byte stream in, byte stream out; no I/O, no ROS.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace laser_dpslam {
namespace create_oi {

enum Opcode : std::uint8_t {
  kStart = 128, kBaud = 129, kControl = 130, kSafe = 131, kFull = 132, kDrive = 137, kLeds = 139,
  kSensors = 142, kDriveDirect = 145, kStream = 148, kQueryList = 149, kPauseResume = 150, kStop = 173
};
enum Mode : std::uint8_t { kOff = 0, kPassive = 1, kSafeMode = 2, kFullMode = 3 };

constexpr double kAxleLength = 0.258;  ///< m, Create 1 wheel base (libcreate's CREATE_1 model)
constexpr int kMaxVelocity = 500;      ///< mm/s per wheel
constexpr int kMaxRadius = 2000;       ///< mm

/// Data bytes of sensor packet `id` (7..42), 0 for an id the Create 1 does not have.
int packetSize(int id);
/// A stream frame: 19, n, [id, data...]..., checksum with all bytes summing to 0 mod 256.
/// `payload` is the [id, data...] part.
std::vector<std::uint8_t> streamFrame(const std::vector<std::uint8_t>& payload);
/// Wheel speeds [mm/s] (left, right) for Drive (137): velocity [mm/s], radius [mm] with the special radii
/// 32768/32767 (straight), -1 (turn in place clockwise), 1 (counter-clockwise). Values outside the
/// manual's ranges are clamped (velocity ±500, radius ±2000).
void driveToWheels(int velocity, int radius, double* left, double* right);

/// The device state the sensor packets report.
struct SensorState {
  double distance_mm = 0.0;  ///< since the last report (the mean of both wheels' travel)
  double angle_deg = 0.0;    ///< since the last report, counter-clockwise positive
  int voltage_mv = 16000, current_ma = -300, temperature_c = 25, charge_mah = 2500, capacity_mah = 3000;
};

/// The device. feed() takes the host's bytes, updates the mode and wheel commands, and returns the
/// bytes answered at once (Sensors / Query List); streamTick() returns a stream frame when one is due
/// (every 15 ms while a stream is requested and not paused) and resets the reported motion.
class CreateDevice {
 public:
  std::vector<std::uint8_t> feed(const std::vector<std::uint8_t>& bytes, SensorState& sensors);
  std::vector<std::uint8_t> streamTick(double now_s, SensorState& sensors);

  Mode mode() const { return mode_; }
  double leftVelocity() const { return left_; }    ///< mm/s commanded
  double rightVelocity() const { return right_; }  ///< mm/s commanded
  const std::vector<std::uint8_t>& streamIds() const { return stream_ids_; }
  bool streaming() const { return !stream_ids_.empty() && !paused_; }
  int framesSent() const { return frames_; }
  int ignoredCommands() const { return ignored_; }

 private:
  /// Bytes that must follow `opcode` before it is complete; -1 for an opcode the Create ignores.
  int argumentBytes(std::uint8_t opcode, const std::vector<std::uint8_t>& pending) const;
  std::vector<std::uint8_t> execute(const std::vector<std::uint8_t>& cmd, SensorState& sensors);
  std::vector<std::uint8_t> packetData(int id, SensorState& sensors);

  Mode mode_ = kOff;
  double left_ = 0.0, right_ = 0.0;
  int requested_velocity_ = 0, requested_radius_ = 0;
  std::vector<std::uint8_t> stream_ids_;
  bool paused_ = false;
  double next_frame_s_ = -1.0;
  std::vector<std::uint8_t> pending_;
  int frames_ = 0;
  int ignored_ = 0;
};

}  // namespace create_oi
}  // namespace laser_dpslam
