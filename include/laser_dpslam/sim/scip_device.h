// An emulated Hokuyo URG-04LX speaking SCIP 2.0 (Hokuyo's "Communication Protocol Specification For
// SCIP2.0", C-42-03320B), as urg_c (the library under urg_node) uses it. Byte stream in, byte stream out;
// no I/O, no ROS: emulate_robot puts it on a pseudo-terminal.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace laser_dpslam {
namespace scip {

/// SCIP's check sum of a line: the low 6 bits of the byte sum, plus 0x30.
char checksum(const std::string& text);
/// `text` followed by its check sum.
std::string withChecksum(const std::string& text);
/// The 6-bit character encoding of `value` in `chars` characters (2: < 4096, 3: < 262144, 4: < 2^24),
/// most significant first, each 6 bits + 0x30. Throws std::invalid_argument if it does not fit.
std::string encode(std::uint32_t value, int chars);
/// Inverse of encode(); throws std::invalid_argument on a character outside 0x30..0x6F.
std::uint32_t decode(const std::string& text);
/// Splits encoded measurement data into lines of at most 64 characters, each followed by its check
/// sum and LF, as MD/GD replies carry them.
std::string dataBlocks(const std::string& encoded);

/// The URG-04LX's geometry (PP reply): steps 44..725 of 1024 per turn, step 384 straight ahead.
struct UrgParameters {
  int dmin = 20;      ///< mm
  int dmax = 5600;    ///< mm
  int ares = 1024;    ///< steps per turn
  int amin = 44;      ///< first measurable step
  int amax = 725;     ///< last measurable step
  int afrt = 384;     ///< front step
  int scan_rpm = 600; ///< 10 scans per second
};

/// The device. feed() takes the bytes the host sent and returns the bytes the device answers at once;
/// tick() is called with the sensor's clock and returns the scans due in MD/MS streaming (one per
/// scan period). Scans come from the callback: ranges [mm] for steps first..last (0 = no echo, as the
/// URG-04LX reports errors with codes < 20).
class ScipDevice {
 public:
  using ScanSource = std::function<std::vector<std::uint32_t>(int first_step, int last_step)>;

  ScipDevice(ScanSource source, UrgParameters parameters = UrgParameters());

  /// Bytes from the host; returns the replies to every command line completed by them (LF or CR ends
  /// a line; an empty line is ignored, as the device does).
  std::string feed(const std::string& bytes, std::uint32_t now_ms);
  /// Streaming: the MD/MS scans due at `now_ms` (sensor clock, ms), empty when none.
  std::string tick(std::uint32_t now_ms);

  bool laserOn() const { return laser_on_; }
  bool streaming() const { return stream_.active; }
  int scansSent() const { return scans_sent_; }

  /// One command line (without its LF) → the complete reply.
  std::string command(const std::string& line, std::uint32_t now_ms);

 private:
  struct Stream {
    bool active = false;
    std::string head;     ///< "MD" or "MS"
    std::string params;   ///< start, end, cluster, interval (11 chars)
    int first = 0, last = 0, cluster = 1, interval = 0;
    int remaining = 0;    ///< 0 = until QT
    bool forever = true;
    std::uint32_t next_ms = 0;
  };

  std::string measure(const std::string& line, std::uint32_t now_ms);
  std::string scanReply(const std::string& echo, bool two_chars, int first, int last, int cluster,
                        std::uint32_t now_ms);
  std::string timeCommand(const std::string& line, std::uint32_t now_ms);
  std::string info(const std::string& line) const;

  ScanSource source_;
  UrgParameters p_;
  std::string pending_;
  bool laser_on_ = false;
  bool time_mode_ = false;
  Stream stream_;
  int scans_sent_ = 0;
};

}  // namespace scip
}  // namespace laser_dpslam
