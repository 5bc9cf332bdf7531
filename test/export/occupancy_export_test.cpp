#include "laser_dpslam/export/occupancy_export.h"

#include <gtest/gtest.h>

#include <dirent.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <sstream>

#include "laser_dpslam/sim/floor_plan.h"

using namespace laser_dpslam;

namespace {

std::string readFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

std::uint32_t be32(const std::string& s, std::size_t at) {
  return (std::uint32_t(std::uint8_t(s[at])) << 24) | (std::uint32_t(std::uint8_t(s[at + 1])) << 16) |
         (std::uint32_t(std::uint8_t(s[at + 2])) << 8) | std::uint32_t(std::uint8_t(s[at + 3]));
}

std::uint32_t crc(const std::string& s) {
  std::uint32_t c = 0xFFFFFFFFu;
  for (unsigned char ch : s) {
    c ^= ch;
    for (int k = 0; k < 8; ++k) c = (c & 1) ? 0xEDB88320u ^ (c >> 1) : c >> 1;
  }
  return c ^ 0xFFFFFFFFu;
}

// A minimal inflater for stored and fixed-Huffman blocks (what the encoder may produce), independent of it.
struct Inflater {
  const std::string& in;
  std::size_t pos = 0;
  int bit = 0;
  int get(int n) {
    int v = 0;
    for (int i = 0; i < n; ++i) {
      if (pos >= in.size()) throw std::runtime_error("inflate: out of data");
      v |= ((std::uint8_t(in[pos]) >> bit) & 1) << i;
      if (++bit == 8) {
        bit = 0;
        ++pos;
      }
    }
    return v;
  }
  int huff(int n) {  // n bits, MSB first
    int v = 0;
    for (int i = 0; i < n; ++i) v = (v << 1) | get(1);
    return v;
  }
  int literal() {
    int v = huff(7);
    if (v <= 23) return 256 + v;
    v = (v << 1) | get(1);
    if (v >= 0x30 && v <= 0xBF) return v - 0x30;
    if (v >= 0xC0 && v <= 0xC7) return 280 + v - 0xC0;
    v = (v << 1) | get(1);
    return 144 + v - 0x190;
  }
  std::string run() {
    static const int lb[] = {3, 4, 5, 6, 7, 8, 9, 10, 11, 13, 15, 17, 19, 23, 27, 31, 35, 43, 51, 59, 67, 83, 99, 115, 131, 163, 195, 227, 258};
    static const int le[] = {0, 0, 0, 0, 0, 0, 0, 0, 1, 1, 1, 1, 2, 2, 2, 2, 3, 3, 3, 3, 4, 4, 4, 4, 5, 5, 5, 5, 0};
    static const int db[] = {1, 2, 3, 4, 5, 7, 9, 13, 17, 25, 33, 49, 65, 97, 129, 193, 257, 385, 513, 769, 1025, 1537, 2049, 3073, 4097, 6145, 8193, 12289, 16385, 24577};
    static const int de[] = {0, 0, 0, 0, 1, 1, 2, 2, 3, 3, 4, 4, 5, 5, 6, 6, 7, 7, 8, 8, 9, 9, 10, 10, 11, 11, 12, 12, 13, 13};
    std::string out;
    pos = 2;  // zlib header
    for (bool last = false; !last;) {
      last = get(1);
      const int type = get(2);
      if (type == 0) {
        if (bit) {
          bit = 0;
          ++pos;
        }
        const int len = std::uint8_t(in[pos]) | (std::uint8_t(in[pos + 1]) << 8);
        pos += 4;
        out += in.substr(pos, len);
        pos += len;
      } else if (type == 1) {
        for (;;) {
          const int sym = literal();
          if (sym < 256) {
            out.push_back(static_cast<char>(sym));
          } else if (sym == 256) {
            break;
          } else {
            const int len = lb[sym - 257] + get(le[sym - 257]);
            const int dc = huff(5);
            const int dist = db[dc] + get(de[dc]);
            if (dist > static_cast<int>(out.size())) throw std::runtime_error("inflate: distance too far");
            for (int k = 0; k < len; ++k) out.push_back(out[out.size() - dist]);
          }
        }
      } else {
        throw std::runtime_error("inflate: unexpected block type");
      }
    }
    return out;
  }
};

struct DecodedPng {
  int width = 0, height = 0;
  std::string palette;
  std::vector<std::uint8_t> pixels;  // indices, rows top to bottom
};

DecodedPng decodePng(const std::string& png) {
  DecodedPng d;
  EXPECT_EQ(png.substr(0, 8), std::string("\x89PNG\r\n\x1a\n", 8));
  std::size_t at = 8;
  std::string idat;
  bool end = false;
  while (at + 12 <= png.size()) {
    const std::uint32_t len = be32(png, at);
    const std::string type = png.substr(at + 4, 4), data = png.substr(at + 8, len);
    EXPECT_EQ(be32(png, at + 8 + len), crc(type + data)) << "CRC of " << type;
    if (type == "IHDR") {
      d.width = static_cast<int>(be32(data, 0));
      d.height = static_cast<int>(be32(data, 4));
      EXPECT_EQ(data[8], 8);  // bit depth
      EXPECT_EQ(data[9], 3);  // palette
    } else if (type == "PLTE") {
      d.palette = data;
    } else if (type == "IDAT") {
      idat += data;
    } else if (type == "IEND") {
      end = true;
    }
    at += 12 + len;
  }
  EXPECT_TRUE(end);
  Inflater inf{idat};
  const std::string raw = inf.run();
  // Adler-32 of the raw data closes the zlib stream.
  std::uint32_t a = 1, b = 0;
  for (unsigned char c : raw) {
    a = (a + c) % 65521;
    b = (b + a) % 65521;
  }
  EXPECT_EQ(be32(idat, idat.size() - 4), (b << 16) | a);
  EXPECT_EQ(raw.size(), static_cast<std::size_t>(d.width + 1) * d.height);
  for (int r = 0; r < d.height; ++r) {
    EXPECT_EQ(raw[static_cast<std::size_t>(r) * (d.width + 1)], 0) << "filter byte";
    for (int c = 0; c < d.width; ++c) d.pixels.push_back(std::uint8_t(raw[static_cast<std::size_t>(r) * (d.width + 1) + 1 + c]));
  }
  return d;
}

// A 0.1 m map: root saw a free row y = 0 (x = 0..4) and a wall cell (5, 0); particle A saw a wall at (2, 3).
struct SmallWorld {
  AncestryTree tree;
  DpSlamMap map{0.1, 4.0};
  std::vector<int> leaves;
  SmallWorld() {
    const int root = tree.createRoot();
    for (int x = 0; x < 5; ++x) map.observe(x, 0, root, tree, 0.1, false);
    for (int k = 0; k < 5; ++k) map.observe(5, 0, root, tree, 0.02, true);  // hits 5, distance 0.5 → density 10
    leaves = tree.advance({root}, {0, 0}, 1, map);
    map.observe(2, 3, leaves[0], tree, 0.0, true);  // hits 1, distance 0.4 → density 2.5
  }
};

}  // namespace

TEST(OccupancyExport, ValuesFromPenetrationStatistics) {
  EXPECT_EQ(occupancyValue(nullptr, 0.1), -1);
  MapEntry e;
  e.hits = 0;
  e.distance = 3;
  EXPECT_EQ(occupancyValue(&e, 0.1), 0);
  e.hits = 1;
  e.distance = 0.1f;  // density 10 /m: 1 − e^−1 = 0.632
  EXPECT_EQ(occupancyValue(&e, 0.1), 63);
  e.hits = 50;
  EXPECT_EQ(occupancyValue(&e, 0.1), 100);
  EXPECT_EQ(pgmValue(-1), 205);
  EXPECT_EQ(pgmValue(0), 254);
  EXPECT_EQ(pgmValue(19), 254);
  EXPECT_EQ(pgmValue(20), 205);
  EXPECT_EQ(pgmValue(64), 205);
  EXPECT_EQ(pgmValue(65), 0);
  EXPECT_EQ(pgmValue(100), 0);
}

TEST(OccupancyExport, GridFollowsTheParticlesAncestryAndRowOrder) {
  SmallWorld w;
  const OccupancyGridData a = occupancyFromMap(w.map, w.tree, w.leaves[0], 0.1, 1);
  // Observed cells x 0..5, y 0..3 for A, plus a margin of 1.
  EXPECT_EQ(a.width, 8);
  EXPECT_EQ(a.height, 6);
  EXPECT_NEAR(a.origin_x, -0.1, 1e-12);
  EXPECT_NEAR(a.origin_y, -0.1, 1e-12);
  EXPECT_EQ(a.data.size(), 48u);
  EXPECT_EQ(a.at(1, 1), 0);     // cell (0, 0): free
  EXPECT_EQ(a.at(6, 1), 63);    // cell (5, 0): density 10 → 63
  EXPECT_EQ(a.at(3, 4), 22);    // cell (2, 3): density 2.5 → 1 − e^−0.25 = 0.221
  EXPECT_EQ(a.at(3, 3), -1);    // cell (2, 2): never seen
  EXPECT_EQ(a.data[1 * 8 + 6], 63);  // row-major, row 0 = lowest y
  // Particle B never saw (2, 3): its map is smaller and does not have that wall.
  const OccupancyGridData b = occupancyFromMap(w.map, w.tree, w.leaves[1], 0.1, 1);
  EXPECT_EQ(b.height, 3);
  EXPECT_EQ(b.at(6, 1), 63);
}

TEST(OccupancyExport, MapServerFilesRoundTripThroughTheFloorPlanLoader) {
  SmallWorld w;
  const OccupancyGridData g = occupancyFromMap(w.map, w.tree, w.leaves[0], 0.2, 1);  // wall (5, 0): 86 → occupied
  const std::string dir = ::testing::TempDir();
  writeMapServerFiles(g, dir + "/export_map.yaml");
  const std::string yaml = readFile(dir + "/export_map.yaml");
  EXPECT_NE(yaml.find("image: export_map.pgm"), std::string::npos) << yaml;
  EXPECT_NE(yaml.find("resolution: 0.1"), std::string::npos);
  EXPECT_NE(yaml.find("origin: [-0.1"), std::string::npos);
  EXPECT_NE(yaml.find("negate: 0"), std::string::npos);
  EXPECT_NE(yaml.find("occupied_thresh: 0.65"), std::string::npos);
  EXPECT_NE(yaml.find("free_thresh: 0.196"), std::string::npos);
  const std::string pgm = readFile(dir + "/export_map.pgm");
  ASSERT_EQ(pgm.substr(0, 2), "P5");
  // The last image row is the lowest y: cell (5, 0) is at image row height − 2, column 6.
  const std::size_t data = pgm.size() - static_cast<std::size_t>(g.width) * g.height;
  EXPECT_EQ(std::uint8_t(pgm[data + static_cast<std::size_t>(g.height - 2) * g.width + 6]), 0);
  EXPECT_EQ(std::uint8_t(pgm[data + static_cast<std::size_t>(g.height - 2) * g.width + 1]), 254);
  EXPECT_EQ(std::uint8_t(pgm[data]), 205);
  // map_server semantics, read back by the project's own loader.
  const FloorPlan plan = FloorPlan::load(dir + "/export_map.yaml");
  EXPECT_EQ(plan.width(), g.width);
  EXPECT_EQ(plan.height(), g.height);
  EXPECT_TRUE(plan.occupied(0.55, 0.05));
  EXPECT_TRUE(plan.isFree(0.15, 0.05));
  EXPECT_EQ(plan.cell(3, 3), FloorPlan::kUnknown);
  // No temporary files left behind.
  EXPECT_EQ(readFile(dir + "/export_map.yaml.tmp." + std::to_string(::getpid())), "");
}

TEST(OccupancyExport, PngDecodesToTheMapAndTrajectory) {
  SmallWorld w;
  const OccupancyGridData g = occupancyFromMap(w.map, w.tree, w.leaves[0], 0.1, 3);
  std::vector<StampedPose> traj(3);
  traj[0].pose = Pose2D(0.05, 0.05, 0);   // cell (0, 0)
  traj[1].pose = Pose2D(0.05, -0.25, 0);  // cell (0, -3)
  traj[2].pose = Pose2D(-0.25, -0.25, 0); // cell (-3, -3): the grid's corner
  const std::string path = ::testing::TempDir() + "/export_map.png";
  writeMapPng(g, traj, path);
  const DecodedPng d = decodePng(readFile(path));
  ASSERT_EQ(d.width, g.width);
  ASSERT_EQ(d.height, g.height);
  ASSERT_EQ(d.palette.size(), 105u * 3);
  auto px = [&](int ix, int iy) { return d.pixels[static_cast<std::size_t>(g.height - 1 - iy) * g.width + ix]; };
  EXPECT_EQ(px(3 + 5, 3 + 0), 63);   // the wall cell (5, 0), grey level index = occupancy
  EXPECT_EQ(px(3 + 2, 3 + 3), 22);
  EXPECT_EQ(px(g.width - 1, g.height - 1), 101);  // unknown
  EXPECT_EQ(px(3 + 0, 3 + 0), 103);  // start marker
  EXPECT_EQ(px(0, 0), 104);          // end marker
  EXPECT_EQ(px(3, 0), 102);          // the path (cell (0, -3), outside both markers)
  // A larger, repetitive image compresses well and still decodes.
  std::vector<std::uint8_t> big(300 * 200);
  for (std::size_t i = 0; i < big.size(); ++i) big[i] = static_cast<std::uint8_t>((i / 300) % 7 == 0 ? 5 : (i % 300 > 150));
  const std::string png = encodePalettePng(300, 200, big, std::vector<std::uint8_t>(18, 9));
  EXPECT_LT(png.size(), big.size() / 10);
  const DecodedPng db = decodePng(png);
  EXPECT_EQ(db.pixels, big);
}

// --- Failures to save (issue 6). The tests run as root, for whom chmod does not stop a write, so the
// failures are forced with paths that cannot hold a file, and a full disk with /dev/full: the temporary
// file the writer creates (PATH.tmp.<pid>) is made a symlink to it, so the writer's own write, flush and
// fsync meet a real ENOSPC from the kernel.
namespace {

std::string freshDir(const std::string& name) {
  const std::string dir = ::testing::TempDir() + "/" + name + "_" + std::to_string(::getpid());
  EXPECT_EQ(std::system(("rm -rf '" + dir + "'").c_str()), 0);
  EXPECT_EQ(::mkdir(dir.c_str(), 0755), 0) << dir;
  return dir;
}

std::vector<std::string> listDir(const std::string& dir) {
  std::vector<std::string> names;
  if (DIR* d = ::opendir(dir.c_str())) {
    while (const dirent* e = ::readdir(d)) {
      const std::string n = e->d_name;
      if (n != "." && n != "..") names.push_back(n);
    }
    ::closedir(d);
  }
  std::sort(names.begin(), names.end());
  return names;
}

OccupancyGridData grid(int width, int height, std::int8_t value) {
  OccupancyGridData g;
  g.resolution = 0.05;
  g.width = width;
  g.height = height;
  g.origin_x = -0.5 * width * g.resolution;
  g.data.assign(static_cast<std::size_t>(width) * height, value);
  return g;
}

/// Runs `write`, which must throw std::runtime_error; returns the message.
std::string failureOf(const std::function<void()>& write) {
  try {
    write();
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  ADD_FAILURE() << "no exception";
  return "";
}

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

}  // namespace

TEST(OccupancyExportFailure, UnwritableDestinationsThrowAnErrorNamingThePath) {
  const std::string dir = freshDir("unwritable");
  const OccupancyGridData g = grid(20, 10, 0);
  // A directory that does not exist.
  std::string e = failureOf([&] { writeMapServerFiles(g, dir + "/no_such_dir/map.yaml"); });
  EXPECT_TRUE(contains(e, "'" + dir + "/no_such_dir/map.pgm'")) << e;
  EXPECT_TRUE(contains(e, "No such file or directory")) << e;
  e = failureOf([&] { writeMapPng(g, {}, dir + "/no_such_dir/map.png"); });
  EXPECT_TRUE(contains(e, "'" + dir + "/no_such_dir/map.png'")) << e;
  // A "directory" that is a regular file.
  std::ofstream(dir + "/plain") << "not a directory";
  e = failureOf([&] { writeMapServerFiles(g, dir + "/plain/map.yaml"); });
  EXPECT_TRUE(contains(e, "'" + dir + "/plain/map.pgm'")) << e;
  EXPECT_TRUE(contains(e, "Not a directory")) << e;
  // /proc holds no regular files, not even for root.
  e = failureOf([&] { writeMapServerFiles(g, "/proc/laser_dpslam_test_map.yaml"); });
  EXPECT_TRUE(contains(e, "'/proc/laser_dpslam_test_map.pgm'")) << e;
  EXPECT_NE(::access("/proc/laser_dpslam_test_map.pgm", F_OK), 0);
  EXPECT_EQ(listDir(dir), std::vector<std::string>{"plain"});
}

TEST(OccupancyExportFailure, FullDiskKeepsThePreviousMapByteIdenticalAndLeavesNoTemporaries) {
  if (::access("/dev/full", W_OK) != 0) GTEST_SKIP() << "no /dev/full";
  const std::string dir = freshDir("full_disk");
  const std::string yaml = dir + "/map.yaml", pgm = dir + "/map.pgm";
  writeMapServerFiles(grid(20, 10, 0), yaml);
  const std::string old_yaml = readFile(yaml), old_pgm = readFile(pgm);
  ASSERT_FALSE(old_yaml.empty());
  ASSERT_FALSE(old_pgm.empty());
  const OccupancyGridData bigger = grid(300, 200, 100);  // another size and origin: a mixed pair would misplace it
  // The disk fills up while the image is written, then (image done) while the YAML is written: either
  // way the old pair survives, because nothing is renamed before both are complete.
  for (const std::string& victim : {pgm, yaml}) {
    const std::string tmp = victim + ".tmp." + std::to_string(::getpid());
    ASSERT_EQ(::symlink("/dev/full", tmp.c_str()), 0) << tmp;
    const std::string e = failureOf([&] { writeMapServerFiles(bigger, yaml); });
    EXPECT_TRUE(contains(e, "'" + victim + "'")) << e;
    EXPECT_TRUE(contains(e, "No space left on device")) << e;
    EXPECT_EQ(readFile(pgm), old_pgm) << "victim " << victim;
    EXPECT_EQ(readFile(yaml), old_yaml) << "victim " << victim;
    EXPECT_EQ(listDir(dir), (std::vector<std::string>{"map.pgm", "map.yaml"})) << "victim " << victim;
  }
  // With space again the same write replaces both files (so the comparisons above could fail).
  writeMapServerFiles(bigger, yaml);
  EXPECT_NE(readFile(pgm), old_pgm);
  EXPECT_NE(readFile(yaml), old_yaml);
  EXPECT_EQ(listDir(dir), (std::vector<std::string>{"map.pgm", "map.yaml"}));
}

TEST(OccupancyExportFailure, AFailedRenameLeavesNoTemporaryAndTheYamlUntouched) {
  const std::string dir = freshDir("rename");
  const std::string yaml = dir + "/map.yaml";
  std::ofstream(yaml) << "old yaml\n";
  ASSERT_EQ(::mkdir((dir + "/map.pgm").c_str(), 0755), 0);  // the image's place is taken by a directory
  const std::string e = failureOf([&] { writeMapServerFiles(grid(20, 10, 0), yaml); });
  EXPECT_TRUE(contains(e, "'" + dir + "/map.pgm'")) << e;
  EXPECT_EQ(readFile(yaml), "old yaml\n");
  EXPECT_EQ(listDir(dir), (std::vector<std::string>{"map.pgm", "map.yaml"}));
}
