// The emulated Create's Open Interface against the examples of iRobot's "Create Open Interface" manual
// and the byte sequences libcreate sends for a CREATE_1 (protocol version 2, streamed sensors).
#include "laser_dpslam/sim/create_oi.h"

#include <gtest/gtest.h>

#include <numeric>
#include <vector>

namespace laser_dpslam {
namespace create_oi {
namespace {

using Bytes = std::vector<std::uint8_t>;

// libcreate's packet list for protocol version 2 (data.cpp), in its std::map order.
const Bytes kLibcreateIds = {7, 8, 9, 10, 11, 12, 13, 14, 15, 17, 18, 19, 20, 21, 22, 23, 24, 25, 26, 35};

int sumMod256(const Bytes& b) { return std::accumulate(b.begin(), b.end(), 0) & 0xFF; }

TEST(CreateOi, StreamFrameOfTheManual) {
  // Manual example: a stream of packets 29 (2 bytes, 2 = 0x0002) and 13 (1 byte, 1):
  // 19 5 29 2 25 13 0 163 -- here with the values 0x0219 and 0 as in the manual.
  const Bytes frame = streamFrame({29, 2, 25, 13, 0});
  EXPECT_EQ(frame, (Bytes{19, 5, 29, 2, 25, 13, 0, 163}));
  EXPECT_EQ(sumMod256(frame), 0);
}

TEST(CreateOi, PacketSizes) {
  EXPECT_EQ(packetSize(7), 1);
  EXPECT_EQ(packetSize(19), 2);
  EXPECT_EQ(packetSize(20), 2);
  EXPECT_EQ(packetSize(22), 2);
  EXPECT_EQ(packetSize(24), 1);
  EXPECT_EQ(packetSize(35), 1);
  EXPECT_EQ(packetSize(42), 2);
  EXPECT_EQ(packetSize(43), 0);  // encoder counts: Create 2 only
  EXPECT_EQ(packetSize(6), 0);   // a group, not a packet
}

TEST(CreateOi, DriveSpecialRadiiAndExample) {
  double l = 0, r = 0;
  driveToWheels(-200, 500, &l, &r);  // manual example: 137 255 56 1 244 (-200 mm/s, radius 500 mm)
  EXPECT_NEAR((l + r) / 2.0, -200.0, 1e-9);
  EXPECT_NEAR(r - l, -200.0 * 258.0 / 500.0, 1e-9);
  driveToWheels(300, 32768 - 65536, &l, &r);  // 0x8000: straight
  EXPECT_EQ(l, 300.0);
  EXPECT_EQ(r, 300.0);
  driveToWheels(300, 32767, &l, &r);
  EXPECT_EQ(l, r);
  driveToWheels(100, 1, &l, &r);  // counter-clockwise in place
  EXPECT_EQ(l, -100.0);
  EXPECT_EQ(r, 100.0);
  driveToWheels(100, -1, &l, &r);  // clockwise
  EXPECT_EQ(l, 100.0);
  EXPECT_EQ(r, -100.0);
  driveToWheels(900, 32767, &l, &r);  // clamped to 500 mm/s
  EXPECT_EQ(l, 500.0);
}

TEST(CreateOi, LibcreateSessionDrivesAndStreams) {
  CreateDevice d;
  SensorState s;
  // Before Start the OI is off: drive and stream requests are ignored.
  EXPECT_TRUE(d.feed({145, 0, 100, 0, 100}, s).empty());
  EXPECT_EQ(d.rightVelocity(), 0.0);
  Bytes stream = {148, static_cast<std::uint8_t>(kLibcreateIds.size())};
  stream.insert(stream.end(), kLibcreateIds.begin(), kLibcreateIds.end());
  Bytes exchange;
  exchange.push_back(128);
  for (std::uint8_t b : stream) exchange.push_back(b);
  d.feed(exchange, s);
  EXPECT_EQ(d.mode(), kPassive);
  EXPECT_TRUE(d.streaming());
  d.feed({145, 0, 200, 0, 100}, s);  // passive: actuators ignored
  EXPECT_EQ(d.leftVelocity(), 0.0);
  d.feed({132}, s);
  EXPECT_EQ(d.mode(), kFullMode);
  d.feed({145, 0, 200, 0xFF, 0x9C}, s);  // right 200, left -100 mm/s
  EXPECT_EQ(d.rightVelocity(), 200.0);
  EXPECT_EQ(d.leftVelocity(), -100.0);

  s.distance_mm = 12.7;
  s.angle_deg = -3.4;
  const Bytes f = d.streamTick(1.0, s);
  EXPECT_EQ(f[0], 19);
  EXPECT_EQ(f[1], 26 + 20);  // libcreate: expectedNumBytes = data bytes + number of packets
  EXPECT_EQ(f.size(), 2u + 46 + 1);
  EXPECT_EQ(sumMod256(f), 0);
  // Packet 19 (distance, big-endian signed) and 20 (angle) after ids 7..18 (11 one-byte packets).
  const std::size_t p19 = 2 + 11 * 2;
  EXPECT_EQ(f[p19], 19);
  EXPECT_EQ(static_cast<std::int16_t>((f[p19 + 1] << 8) | f[p19 + 2]), 12);
  EXPECT_EQ(f[p19 + 3], 20);
  EXPECT_EQ(static_cast<std::int16_t>((f[p19 + 4] << 8) | f[p19 + 5]), -3);
  EXPECT_NEAR(s.distance_mm, 0.7, 1e-9);  // the fraction is carried to the next frame
  EXPECT_EQ(f[f.size() - 3], 35);
  EXPECT_EQ(f[f.size() - 2], kFullMode);
  EXPECT_TRUE(d.streamTick(1.005, s).empty());  // one frame per 15 ms
  EXPECT_FALSE(d.streamTick(1.016, s).empty());
  d.feed({150, 0}, s);  // pause
  EXPECT_TRUE(d.streamTick(2.0, s).empty());
  d.feed({150, 1}, s);
  EXPECT_FALSE(d.streamTick(2.1, s).empty());
  d.feed({128, 173}, s);  // libcreate's disconnect: passive, then stop
  EXPECT_EQ(d.mode(), kOff);
  EXPECT_EQ(d.leftVelocity(), 0.0);
  EXPECT_TRUE(d.streamTick(3.0, s).empty());
}

TEST(CreateOi, MalformedInputIsIgnoredAsTheCreateDoes) {
  CreateDevice d;
  SensorState s;
  d.feed({0, 17, 255, 128, 131}, s);  // bytes that are no opcode are skipped
  EXPECT_EQ(d.mode(), kSafeMode);
  EXPECT_EQ(d.ignoredCommands(), 3);
  d.feed({148, 2, 19, 99}, s);  // unknown packet 99: the request is dropped
  EXPECT_FALSE(d.streaming());
  d.feed({137, 0x01}, s);  // split command: completed by the next bytes
  d.feed({0x2C, 0x80, 0x00}, s);  // 300 mm/s, straight
  EXPECT_EQ(d.leftVelocity(), 300.0);
  EXPECT_EQ(d.rightVelocity(), 300.0);
  d.feed({145, 0x7F, 0xFF, 0x80, 0x00}, s);  // beyond ±500 mm/s: clamped
  EXPECT_EQ(d.rightVelocity(), 500.0);
  EXPECT_EQ(d.leftVelocity(), -500.0);
  d.feed({140, 0, 2, 60, 32, 62, 32, 141, 0}, s);  // a song and its play: consumed, nothing else changes
  EXPECT_EQ(d.mode(), kSafeMode);
  const Bytes q = d.feed({142, 35, 149, 2, 22, 26}, s);  // sensors / query list replies
  EXPECT_EQ(q, (Bytes{kSafeMode, 16000 >> 8, 16000 & 0xFF, 3000 >> 8, 3000 & 0xFF}));
}

}  // namespace
}  // namespace create_oi
}  // namespace laser_dpslam
