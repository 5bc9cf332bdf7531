#include "laser_dpslam/sim/create_oi.h"

#include <algorithm>
#include <cmath>

namespace laser_dpslam {
namespace create_oi {

int packetSize(int id) {
  // Create OI manual, "Sensor Packets": 7..42.
  static const int kSizes[] = {1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 2, 2, 1, 2, 2, 1, 2, 2,  // 7..26
                               2, 2, 2, 2, 2, 1, 2, 1, 1, 1, 1, 1, 2, 2, 2, 2};            // 27..42
  return id >= 7 && id <= 42 ? kSizes[id - 7] : 0;
}

std::vector<std::uint8_t> streamFrame(const std::vector<std::uint8_t>& payload) {
  std::vector<std::uint8_t> frame;
  frame.reserve(payload.size() + 3);
  frame.push_back(19);
  frame.push_back(static_cast<std::uint8_t>(payload.size()));
  for (std::uint8_t b : payload) frame.push_back(b);
  unsigned sum = 0;
  for (std::uint8_t b : frame) sum += b;
  frame.push_back(static_cast<std::uint8_t>((256 - (sum & 0xFF)) & 0xFF));
  return frame;
}

void driveToWheels(int velocity, int radius, double* left, double* right) {
  const double v = std::clamp(velocity, -kMaxVelocity, kMaxVelocity);
  const double half = kAxleLength * 1000.0 / 2.0;
  if (radius == 32767 || radius == -32768) {  // 0x7FFF / 0x8000: straight
    *left = *right = v;
  } else if (radius == -1) {  // turn in place clockwise
    *left = v;
    *right = -v;
  } else if (radius == 1) {  // counter-clockwise
    *left = -v;
    *right = v;
  } else {
    const double r = std::clamp(radius, -kMaxRadius, kMaxRadius);
    // Centre speed v on a circle of radius r (positive: turn left): wheels at r ∓ half.
    *left = v * (r - half) / r;
    *right = v * (r + half) / r;
  }
}

namespace {
std::int16_t int16At(const std::vector<std::uint8_t>& b, std::size_t i) {
  return static_cast<std::int16_t>(static_cast<std::uint16_t>((b[i] << 8) | b[i + 1]));
}
void push16(std::vector<std::uint8_t>& out, int value) {
  const auto v = static_cast<std::uint16_t>(static_cast<std::int16_t>(std::clamp(value, -32768, 32767)));
  out.push_back(static_cast<std::uint8_t>(v >> 8));
  out.push_back(static_cast<std::uint8_t>(v & 0xFF));
}
// Takes the whole part of an accumulated motion for a report and keeps the fraction for the next one.
int takeWhole(double& accumulated) {
  const double whole = std::trunc(std::clamp(accumulated, -32768.0, 32767.0));
  accumulated -= whole;
  return static_cast<int>(whole);
}
}  // namespace

int CreateDevice::argumentBytes(std::uint8_t opcode, const std::vector<std::uint8_t>& pending) const {
  switch (opcode) {
    case 128: case 130: case 131: case 132: case 133: case 134: case 135: case 136: case 143:
    case 153: case 154: case 173:
      return 0;
    case 129: case 138: case 141: case 142: case 147: case 150: case 151: case 155: case 158: case 165:
      return 1;
    case 156: case 157: case 162:
      return 2;
    case 139: case 144: case 168:
      return 3;
    case 137: case 145: case 146: case 163: case 164:
      return 4;
    case 167:
      return 15;
    case 140:  // song: number, length, then length × (note, duration)
      return pending.size() < 3 ? 2 : 2 + 2 * pending[2];
    case 148: case 149: case 152:  // n, then n bytes
      return pending.size() < 2 ? 1 : 1 + pending[1];
    default:
      return -1;
  }
}

std::vector<std::uint8_t> CreateDevice::feed(const std::vector<std::uint8_t>& bytes, SensorState& sensors) {
  std::vector<std::uint8_t> out;
  for (std::uint8_t b : bytes) {
    if (pending_.empty() && argumentBytes(b, pending_) < 0) {
      ++ignored_;  // not an opcode: the Create skips the byte
      continue;
    }
    pending_.push_back(b);
    const int need = argumentBytes(pending_[0], pending_);
    if (static_cast<int>(pending_.size()) < need + 1) continue;
    const auto reply = execute(pending_, sensors);
    out.insert(out.end(), reply.begin(), reply.end());
    pending_.clear();
  }
  return out;
}

std::vector<std::uint8_t> CreateDevice::execute(const std::vector<std::uint8_t>& cmd, SensorState& sensors) {
  const std::uint8_t op = cmd[0];
  // Before Start the OI is off and every command but Start is ignored; actuators need safe or full mode.
  if (mode_ == kOff && op != kStart) { ++ignored_; return {}; }
  const bool actuator = op == kDrive || op == kDriveDirect || op == 146 || op == 138 || op == 144 || op == 147;
  if (actuator && mode_ < kSafeMode) { ++ignored_; return {}; }
  switch (op) {
    case kStart:
      mode_ = kPassive;
      left_ = right_ = 0.0;
      break;
    case kControl: case kSafe:
      mode_ = kSafeMode;
      break;
    case kFull:
      mode_ = kFullMode;
      break;
    case kStop:  // OI stopped: back to off, motors and stream stop
      mode_ = kOff;
      left_ = right_ = 0.0;
      stream_ids_.clear();
      break;
    case kDrive:
      requested_velocity_ = int16At(cmd, 1);
      requested_radius_ = int16At(cmd, 3);
      driveToWheels(requested_velocity_, requested_radius_, &left_, &right_);
      break;
    case kDriveDirect:  // right, then left
      right_ = std::clamp<int>(int16At(cmd, 1), -kMaxVelocity, kMaxVelocity);
      left_ = std::clamp<int>(int16At(cmd, 3), -kMaxVelocity, kMaxVelocity);
      requested_velocity_ = static_cast<int>((left_ + right_) / 2.0);
      requested_radius_ = 32767;
      break;
    case kStream: {
      const std::vector<std::uint8_t> ids(cmd.begin() + 2, cmd.end());
      // A request naming a packet the Create does not have is dropped as a whole.
      if (std::any_of(ids.begin(), ids.end(), [](std::uint8_t id) { return packetSize(id) == 0; })) {
        ++ignored_;
        break;
      }
      stream_ids_ = ids;
      paused_ = false;
      next_frame_s_ = -1.0;
      break;
    }
    case kPauseResume:
      paused_ = cmd[1] == 0;
      break;
    case kSensors: case kQueryList: {
      std::vector<std::uint8_t> ids;
      if (op == kSensors) {
        static const int kGroups[7][2] = {{7, 26}, {7, 16}, {17, 20}, {21, 26}, {27, 34}, {35, 42}, {7, 42}};
        if (cmd[1] <= 6) for (int id = kGroups[cmd[1]][0]; id <= kGroups[cmd[1]][1]; ++id) ids.push_back(id);
        else ids.push_back(cmd[1]);
      } else {
        ids.assign(cmd.begin() + 2, cmd.end());
      }
      std::vector<std::uint8_t> out;
      for (std::uint8_t id : ids) {
        const auto data = packetData(id, sensors);
        out.insert(out.end(), data.begin(), data.end());
      }
      return out;
    }
    default:
      break;  // LEDs, songs, baud, ...: accepted, nothing to emulate
  }
  return {};
}

std::vector<std::uint8_t> CreateDevice::packetData(int id, SensorState& s) {
  std::vector<std::uint8_t> out;
  switch (id) {
    case 19: push16(out, takeWhole(s.distance_mm)); break;
    case 20: push16(out, takeWhole(s.angle_deg)); break;
    case 22: push16(out, s.voltage_mv); break;
    case 23: push16(out, s.current_ma); break;
    case 24: out.push_back(static_cast<std::uint8_t>(static_cast<std::int8_t>(s.temperature_c))); break;
    case 25: push16(out, s.charge_mah); break;
    case 26: push16(out, s.capacity_mah); break;
    case 35: out.push_back(mode_); break;
    case 38: out.push_back(static_cast<std::uint8_t>(stream_ids_.size())); break;
    case 39: push16(out, requested_velocity_); break;
    case 40: push16(out, requested_radius_); break;
    case 41: push16(out, static_cast<int>(right_)); break;
    case 42: push16(out, static_cast<int>(left_)); break;
    default: out.assign(packetSize(id), 0); break;  // bumpers, cliffs, buttons, ...: nothing pressed
  }
  return out;
}

std::vector<std::uint8_t> CreateDevice::streamTick(double now_s, SensorState& sensors) {
  if (!streaming() || mode_ == kOff) return {};
  if (next_frame_s_ >= 0.0 && now_s < next_frame_s_) return {};
  next_frame_s_ = (next_frame_s_ < 0.0 || now_s - next_frame_s_ > 0.015) ? now_s + 0.015 : next_frame_s_ + 0.015;
  std::vector<std::uint8_t> payload;
  for (std::uint8_t id : stream_ids_) {
    payload.push_back(id);
    const auto data = packetData(id, sensors);
    payload.insert(payload.end(), data.begin(), data.end());
  }
  ++frames_;
  return streamFrame(payload);
}

}  // namespace create_oi
}  // namespace laser_dpslam
