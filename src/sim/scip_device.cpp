#include "laser_dpslam/sim/scip_device.h"

#include <algorithm>
#include <cctype>
#include <stdexcept>
#include <utility>

namespace laser_dpslam {
namespace scip {

char checksum(const std::string& text) {
  unsigned sum = 0;
  for (unsigned char c : text) sum += c;
  return static_cast<char>((sum & 0x3F) + 0x30);
}

std::string withChecksum(const std::string& text) { return text + checksum(text); }

std::string encode(std::uint32_t value, int chars) {
  if (chars < 1 || chars > 5 || (chars < 5 && value >= (1u << (6 * chars))))
    throw std::invalid_argument("scip::encode: " + std::to_string(value) + " does not fit in " +
                                std::to_string(chars) + " characters");
  std::string out(chars, '0');
  for (int i = chars - 1; i >= 0; --i) {
    out[i] = static_cast<char>((value & 0x3F) + 0x30);
    value >>= 6;
  }
  return out;
}

std::uint32_t decode(const std::string& text) {
  std::uint32_t value = 0;
  for (unsigned char c : text) {
    if (c < 0x30 || c > 0x6F) throw std::invalid_argument("scip::decode: invalid character in '" + text + "'");
    value = (value << 6) | (c - 0x30u);
  }
  return value;
}

std::string dataBlocks(const std::string& encoded) {
  std::string out;
  for (std::size_t i = 0; i < encoded.size(); i += 64) out += withChecksum(encoded.substr(i, 64)) + "\n";
  return out;
}

namespace {

// The reply of a command that carries no data: echo, status with its sum, blank line.
std::string statusReply(const std::string& echo, const std::string& status) {
  return echo + "\n" + withChecksum(status) + "\n\n";
}

// Parses a fixed-width decimal field; false on anything but digits.
bool number(const std::string& s, int* value) {
  if (s.empty() || !std::all_of(s.begin(), s.end(), [](unsigned char c) { return std::isdigit(c); }))
    return false;
  *value = std::stoi(s);
  return true;
}

// "KEY:value;" and the sum of "KEY:value" (the specification's examples leave the ';' out of the sum).
std::string infoLine(const std::string& key_value) { return key_value + ";" + checksum(key_value); }

}  // namespace

ScipDevice::ScipDevice(ScanSource source, UrgParameters parameters)
    : source_(std::move(source)), p_(parameters) {}

std::string ScipDevice::feed(const std::string& bytes, std::uint32_t now_ms) {
  std::string out;
  for (char c : bytes) {
    if (c == '\n' || c == '\r') {
      if (!pending_.empty()) out += command(pending_, now_ms);
      pending_.clear();
    } else if (pending_.size() < 64) {
      pending_ += c;
    } else {
      // The device refuses strings longer than it buffers (status 0G, "exceeds 16 letters" of free text
      // plus the command); keep the reply bounded by answering once and dropping the rest of the line.
      out += statusReply(pending_.substr(0, 2), "0G");
      pending_.clear();
    }
  }
  return out;
}

std::string ScipDevice::command(const std::string& line, std::uint32_t now_ms) {
  const std::string head = line.substr(0, 2);
  if (line == "QT" || line == "RS") {
    stream_.active = false;
    laser_on_ = false;
    if (line == "RS") time_mode_ = false;
    return statusReply(line, "00");
  }
  if (line == "BM") {
    // The laser stays off while the sensor is in time adjustment mode (TM0..TM2).
    if (time_mode_) return statusReply(line, "01");
    const bool was_on = laser_on_;
    laser_on_ = true;
    return statusReply(line, was_on ? "02" : "00");
  }
  if (line == "PP" || line == "VV" || line == "II") return info(line);
  if (head == "TM") return timeCommand(line, now_ms);
  if (head == "MD" || head == "MS" || head == "GD" || head == "GS") return measure(line, now_ms);
  if (head == "SS") {
    int rate = 0;
    if (line.size() != 8 || !number(line.substr(2), &rate)) return statusReply(line, "01");
    static const int kRates[] = {19200, 38400, 57600, 115200, 250000, 500000, 750000};
    return statusReply(line, std::find(std::begin(kRates), std::end(kRates), rate) != std::end(kRates) ? "00" : "01");
  }
  // ME/HD/ND/... (intensity and multi-echo) and anything else: the URG-04LX does not know them.
  return statusReply(line, "0E");
}

std::string ScipDevice::timeCommand(const std::string& line, std::uint32_t now_ms) {
  if (line == "TM0") {
    if (time_mode_) return statusReply(line, "02");
    time_mode_ = true;
    stream_.active = false;
    laser_on_ = false;
    return statusReply(line, "00");
  }
  if (line == "TM1") {
    if (!time_mode_) return statusReply(line, "04");
    return line + "\n" + withChecksum("00") + "\n" + withChecksum(encode(now_ms & 0xFFFFFF, 4)) + "\n\n";
  }
  if (line == "TM2") {
    if (!time_mode_) return statusReply(line, "03");
    time_mode_ = false;
    return statusReply(line, "00");
  }
  return statusReply(line, line.size() == 3 ? "01" : "0C");
}

std::string ScipDevice::info(const std::string& line) const {
  std::vector<std::string> lines;
  if (line == "PP") {
    lines = {"MODL:URG-04LX(Hokuyo Automatic Co.,Ltd.)", "DMIN:" + std::to_string(p_.dmin),
             "DMAX:" + std::to_string(p_.dmax), "ARES:" + std::to_string(p_.ares),
             "AMIN:" + std::to_string(p_.amin), "AMAX:" + std::to_string(p_.amax),
             "AFRT:" + std::to_string(p_.afrt), "SCAN:" + std::to_string(p_.scan_rpm)};
  } else if (line == "VV") {
    lines = {"VEND:Hokuyo Automatic Co.,Ltd.", "PROD:SOKUIKI Sensor URG-04LX",
             "FIRM:3.4.03(17/Dec./2007)", "PROT:SCIP 2.0", "SERI:H0000000 (emulated)"};
  } else {
    lines = {"MODL:URG-04LX(Hokuyo Automatic Co.,Ltd.)", std::string("LASR:") + (laser_on_ ? "ON" : "OFF"),
             "SCSP:Initial(600[rpm])", "MESM:Measuring by Normal Mode", "SBPS:USB only",
             "TIME:" + encode(0, 4), "STAT:Stable 000 no error."};
  }
  std::string out = line + "\n" + withChecksum("00") + "\n";
  for (const auto& l : lines) out += infoLine(l) + "\n";
  return out + "\n";
}

// MD/MS (stream), GD/GS (one scan): parameters checked in the specification's order and status codes.
std::string ScipDevice::measure(const std::string& line, std::uint32_t now_ms) {
  const bool stream = line[0] == 'M';
  const std::size_t expected = stream ? 15 : 12;
  if (line.size() != expected) return statusReply(line, "0C");
  int first = 0, last = 0, cluster = 0, interval = 0, scans = 0;
  if (!number(line.substr(2, 4), &first)) return statusReply(line, "01");
  if (!number(line.substr(6, 4), &last)) return statusReply(line, "02");
  if (!number(line.substr(10, 2), &cluster)) return statusReply(line, "03");
  if (last > 768) return statusReply(line, "04");
  if (last < first) return statusReply(line, "05");
  if (stream) {
    if (!number(line.substr(12, 1), &interval)) return statusReply(line, "06");
    if (!number(line.substr(13, 2), &scans)) return statusReply(line, "07");
  }
  cluster = std::max(cluster, 1);
  if (time_mode_) return statusReply(line, "0E");  // in time adjustment mode only TM/QT/RS are served
  if (!stream) {
    if (!laser_on_) return statusReply(line, "10");
    return scanReply(line, line[1] == 'S', first, last, cluster, now_ms);
  }
  stream_ = Stream();
  stream_.active = true;
  stream_.head = line.substr(0, 2);
  stream_.params = line.substr(2, 11);
  stream_.first = first;
  stream_.last = last;
  stream_.cluster = cluster;
  stream_.interval = interval;
  stream_.remaining = scans;
  stream_.forever = scans == 0;
  stream_.next_ms = now_ms + 100;  // the first scan after one turn of the mirror
  laser_on_ = true;
  return statusReply(line, "00");
}

std::string ScipDevice::scanReply(const std::string& echo, bool two_chars, int first, int last, int cluster,
                                  std::uint32_t now_ms) {
  std::vector<std::uint32_t> ranges = source_(first, last);
  ranges.resize(last - first + 1, 0);
  std::string data;
  for (std::size_t i = 0; i < ranges.size(); i += cluster) {
    // A cluster reports the shortest valid echo of its steps (codes < dmin are errors).
    std::uint32_t v = 0;
    for (std::size_t j = i; j < std::min(ranges.size(), i + cluster); ++j)
      if (ranges[j] >= static_cast<std::uint32_t>(p_.dmin) && (v == 0 || ranges[j] < v)) v = ranges[j];
    if (two_chars && v > 4095) v = 0;  // MS/GS: 2-character data, longer ranges are not representable
    data += encode(std::min<std::uint32_t>(v, two_chars ? 4095 : 262143), two_chars ? 2 : 3);
  }
  ++scans_sent_;
  const std::string status = echo[0] == 'M' ? "99" : "00";
  return echo + "\n" + withChecksum(status) + "\n" + withChecksum(encode(now_ms & 0xFFFFFF, 4)) + "\n" +
         dataBlocks(data) + "\n";
}

std::string ScipDevice::tick(std::uint32_t now_ms) {
  std::string out;
  // Never more than one scan per call: a host that stops reading does not get a burst afterwards.
  if (stream_.active && static_cast<std::int32_t>(now_ms - stream_.next_ms) >= 0) {
    stream_.next_ms += 100u * (stream_.interval + 1);
    if (static_cast<std::int32_t>(now_ms - stream_.next_ms) >= 0) stream_.next_ms = now_ms + 100;
    int remaining = 0;
    if (!stream_.forever) remaining = --stream_.remaining;
    const std::string echo = stream_.head + stream_.params + (remaining < 10 ? "0" : "") +
                             std::to_string(remaining);
    out = scanReply(echo, stream_.head[1] == 'S', stream_.first, stream_.last, stream_.cluster, now_ms);
    if (!stream_.forever && stream_.remaining <= 0) {
      stream_.active = false;
      laser_on_ = false;  // MD/MS with a scan count turn the laser off after the last scan
    }
  }
  return out;
}

}  // namespace scip
}  // namespace laser_dpslam
