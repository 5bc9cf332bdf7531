// SCIP 2.0 encoding and the emulated URG-04LX's replies, against the examples of Hokuyo's
// "Communication Protocol Specification For SCIP2.0" (C-42-03320B) and what urg_c expects.
#include "laser_dpslam/sim/scip_device.h"

#include <gtest/gtest.h>

#include <sstream>
#include <string>
#include <vector>

namespace laser_dpslam {
namespace scip {
namespace {

std::vector<std::string> lines(const std::string& s) {
  std::vector<std::string> out;
  std::string line;
  std::istringstream in(s);
  while (std::getline(in, line)) out.push_back(line);
  return out;
}

ScipDevice device(std::uint32_t range_mm = 1234) {
  return ScipDevice([range_mm](int first, int last) { return std::vector<std::uint32_t>(last - first + 1, range_mm); });
}

TEST(Scip, EncodingExamplesOfTheSpecification) {
  EXPECT_EQ(encode(1234, 2), "CB");   // 2-character encoding example
  EXPECT_EQ(encode(5432, 3), "1Dh");  // 3-character encoding example
  EXPECT_EQ(decode("CB"), 1234u);
  EXPECT_EQ(decode("1Dh"), 5432u);
  EXPECT_EQ(decode(encode(16000000, 4)), 16000000u);
  EXPECT_THROW(encode(4096, 2), std::invalid_argument);
  EXPECT_THROW(decode("C~"), std::invalid_argument);
}

TEST(Scip, ChecksumExamples) {
  EXPECT_EQ(checksum("00"), 'P');  // "00P": command received
  EXPECT_EQ(checksum("99"), 'b');  // "99b": scan data follows
  EXPECT_EQ(checksum("0E"), 'e');  // "0Ee", the reply urg_c looks for in time adjustment mode
  EXPECT_EQ(withChecksum("DMIN:20"), "DMIN:204");  // PP example lines, sum without the ';'
  EXPECT_EQ(withChecksum("AMIN:44"), "AMIN:447");
}

TEST(Scip, QuitAndLaserOn) {
  auto d = device();
  EXPECT_EQ(d.feed("QT\n", 0), "QT\n00P\n\n");
  EXPECT_EQ(d.feed("BM\n", 0), "BM\n00P\n\n");
  EXPECT_TRUE(d.laserOn());
  EXPECT_EQ(d.feed("BM\n", 0), "BM\n02R\n\n");  // already on
  EXPECT_EQ(d.feed("QT\n", 0), "QT\n00P\n\n");
  EXPECT_FALSE(d.laserOn());
}

TEST(Scip, ParameterReplyHasWhatUrgCReads) {
  auto d = device();
  const auto l = lines(d.feed("PP\n", 0));
  ASSERT_EQ(l.size(), 11u);  // echo, status, 8 parameters, blank line (urg_c: PP_RESPONSE_LINES = 10)
  EXPECT_EQ(l[1], "00P");
  EXPECT_EQ(l[3], "DMIN:20;4");  // the specification's example line
  EXPECT_EQ(l[6], "AMIN:44;7");
  EXPECT_EQ(l[10], "");
  for (std::size_t i = 2; i < 10; ++i) {
    const auto semi = l[i].find(';');
    EXPECT_EQ(l[i][semi + 1], checksum(l[i].substr(0, semi))) << l[i];
  }
  EXPECT_EQ(lines(d.feed("VV\n", 0)).size(), 8u);   // VV_RESPONSE_LINES = 7 + echo
  EXPECT_EQ(lines(d.feed("II\n", 0)).size(), 10u);  // II_RESPONSE_LINES = 9 + echo
}

TEST(Scip, MdStreamsScansWithTimeStampAndChecksummedBlocks) {
  auto d = device(1234);
  EXPECT_EQ(d.feed("MD0044072501000\n", 1000), "MD0044072501000\n00P\n\n");
  EXPECT_EQ(d.tick(1050), "");  // the first scan after one turn (100 ms)
  const auto l = lines(d.tick(1100));
  ASSERT_GE(l.size(), 5u);
  EXPECT_EQ(l[0], "MD0044072501000");
  EXPECT_EQ(l[1], "99b");
  EXPECT_EQ(l[2], withChecksum(encode(1100, 4)));
  std::string data;
  for (std::size_t i = 3; i + 1 < l.size(); ++i) {
    ASSERT_LE(l[i].size(), 65u);
    EXPECT_EQ(l[i].back(), checksum(l[i].substr(0, l[i].size() - 1)));
    data += l[i].substr(0, l[i].size() - 1);
  }
  EXPECT_EQ(l.back(), "");
  ASSERT_EQ(data.size(), 3u * 682);  // steps 44..725, 3 characters each
  EXPECT_EQ(decode(data.substr(0, 3)), 1234u);
  EXPECT_EQ(d.tick(1150), "");
  EXPECT_NE(d.tick(1200), "");
  EXPECT_EQ(d.feed("QT\n", 1210), "QT\n00P\n\n");
  EXPECT_EQ(d.tick(1400), "");
}

TEST(Scip, MdWithScanCountCountsDownAndStops) {
  auto d = device();
  d.feed("MS0100011003002\n", 0);  // 2-character data, cluster 3, 2 scans
  auto l = lines(d.tick(100));
  EXPECT_EQ(l[0], "MS0100011003001");  // remaining scans in the echo
  EXPECT_EQ(l[3].size(), 2u * 4 + 1);  // 11 steps in clusters of 3: 4 values
  l = lines(d.tick(200));
  EXPECT_EQ(l[0], "MS0100011003000");
  EXPECT_FALSE(d.streaming());
  EXPECT_EQ(d.tick(300), "");
}

TEST(Scip, GdNeedsTheLaserOn) {
  auto d = device(4000);
  EXPECT_EQ(d.feed("GD0044072501\n", 0), "GD0044072501\n" + withChecksum("10") + "\n\n");
  d.feed("BM\n", 0);
  const auto l = lines(d.feed("GD0384038401\n", 7));
  ASSERT_EQ(l.size(), 5u);
  EXPECT_EQ(l[1], "00P");
  EXPECT_EQ(l[3], withChecksum(encode(4000, 3)));
}

TEST(Scip, MalformedCommandsGetTheSpecificationsStatus) {
  auto d = device();
  EXPECT_EQ(lines(d.feed("MD00440725010\n", 0))[1], withChecksum("0C"));    // too short
  EXPECT_EQ(lines(d.feed("MDx044072501000\n", 0))[1], withChecksum("01"));  // start not numeric
  EXPECT_EQ(lines(d.feed("MD0044x72501000\n", 0))[1], withChecksum("02"));
  EXPECT_EQ(lines(d.feed("MD00440725x1000\n", 0))[1], withChecksum("03"));
  EXPECT_EQ(lines(d.feed("MD0044080001000\n", 0))[1], withChecksum("04"));  // end beyond the last step
  EXPECT_EQ(lines(d.feed("MD0500040001000\n", 0))[1], withChecksum("05"));  // end before start
  EXPECT_EQ(lines(d.feed("MD0044072501x00\n", 0))[1], withChecksum("06"));
  EXPECT_EQ(lines(d.feed("MD00440725010x0\n", 0))[1], withChecksum("07"));
  EXPECT_FALSE(d.streaming());
  EXPECT_EQ(d.feed("ME0044072501000\n", 0), "ME0044072501000\n0Ee\n\n");  // no intensity on a URG-04LX
  EXPECT_EQ(d.feed("XX\n", 0), "XX\n0Ee\n\n");
  EXPECT_EQ(d.feed("\n\r\n", 0), "");  // empty lines are ignored
  const std::string flood(200, 'A');
  EXPECT_EQ(lines(d.feed(flood + "\n", 0))[1], withChecksum("0G"));
}

TEST(Scip, TimeAdjustmentMode) {
  auto d = device();
  EXPECT_EQ(lines(d.feed("TM1\n", 0))[1], withChecksum("04"));  // not in adjustment mode
  EXPECT_EQ(d.feed("TM0\n", 0), "TM0\n00P\n\n");
  EXPECT_EQ(lines(d.feed("TM0\n", 0))[1], withChecksum("02"));
  const auto l = lines(d.feed("TM1\n", 123456));
  ASSERT_EQ(l.size(), 4u);
  EXPECT_EQ(l[1], "00P");
  EXPECT_EQ(l[2], withChecksum(encode(123456, 4)));
  EXPECT_EQ(decode(l[2].substr(0, 4)), 123456u);
  EXPECT_EQ(lines(d.feed("MD0044072501000\n", 0))[1], withChecksum("0E"));
  EXPECT_EQ(d.feed("TM2\n", 0), "TM2\n00P\n\n");
  EXPECT_EQ(lines(d.feed("TM2\n", 0))[1], withChecksum("03"));
}

}  // namespace
}  // namespace scip
}  // namespace laser_dpslam
