#include "laser_dpslam/export/occupancy_export.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

namespace laser_dpslam {

std::int8_t occupancyValue(const MapEntry* e, double stop_length) {
  if (!e) return -1;
  const double p = 1.0 - std::exp(-e->density() * stop_length);
  return static_cast<std::int8_t>(std::lround(std::min(1.0, std::max(0.0, p)) * 100.0));
}

OccupancyGridData occupancyFromMap(const DpSlamMap& map, const AncestryTree& tree, int node, double stop_length,
                                   int margin) {
  OccupancyGridData g;
  g.resolution = map.resolution();
  int x0, y0, x1, y1;
  if (!tree.valid(node) || !map.bounds(&x0, &y0, &x1, &y1)) return g;
  const std::vector<int> rank = DpSlamMap::lineageRank(tree, node);
  // Crop to the cells this lineage has seen.
  int cx0 = x1 + 1, cy0 = y1 + 1, cx1 = x0 - 1, cy1 = y0 - 1;
  for (int iy = y0; iy <= y1; ++iy) {
    for (int ix = x0; ix <= x1; ++ix) {
      int n = 0;
      if (!map.cellEntries(ix, iy, &n) || !map.lookup(ix, iy, rank)) continue;
      cx0 = std::min(cx0, ix);
      cy0 = std::min(cy0, iy);
      cx1 = std::max(cx1, ix);
      cy1 = std::max(cy1, iy);
    }
  }
  if (cx1 < cx0) return g;
  cx0 -= margin;
  cy0 -= margin;
  cx1 += margin;
  cy1 += margin;
  g.width = cx1 - cx0 + 1;
  g.height = cy1 - cy0 + 1;
  g.origin_x = cx0 * g.resolution;
  g.origin_y = cy0 * g.resolution;
  g.data.assign(static_cast<std::size_t>(g.width) * g.height, -1);
  for (int iy = cy0; iy <= cy1; ++iy) {
    for (int ix = cx0; ix <= cx1; ++ix) {
      g.data[static_cast<std::size_t>(iy - cy0) * g.width + (ix - cx0)] = occupancyValue(map.lookup(ix, iy, rank), stop_length);
    }
  }
  return g;
}

std::uint8_t pgmValue(std::int8_t v) {
  if (v < 0) return 205;
  if (v >= 65) return 0;
  if (v < 19.6) return 254;
  return 205;
}

std::string formatPgm(const OccupancyGridData& g) {
  std::string out = "P5\n# laser_dpslam map\n" + std::to_string(g.width) + " " + std::to_string(g.height) + "\n255\n";
  const std::size_t header = out.size();
  out.resize(header + static_cast<std::size_t>(g.width) * g.height);
  for (int row = 0; row < g.height; ++row) {
    const int iy = g.height - 1 - row;
    for (int ix = 0; ix < g.width; ++ix) {
      out[header + static_cast<std::size_t>(row) * g.width + ix] = static_cast<char>(pgmValue(g.at(ix, iy)));
    }
  }
  return out;
}

std::string formatMapYaml(const OccupancyGridData& g, const std::string& image) {
  char buf[512];
  std::snprintf(buf, sizeof(buf),
                "image: %s\nresolution: %.6f\norigin: [%.6f, %.6f, 0.0]\nnegate: 0\noccupied_thresh: 0.65\n"
                "free_thresh: 0.196\n",
                image.c_str(), g.resolution, g.origin_x, g.origin_y);
  return buf;
}

void writeMapServerFiles(const OccupancyGridData& grid, const std::string& yaml_path) {
  std::string stem = yaml_path;
  const auto slash = stem.find_last_of('/');
  const auto dot = stem.find_last_of('.');
  if (dot != std::string::npos && (slash == std::string::npos || dot > slash)) stem = stem.substr(0, dot);
  const std::string pgm_path = stem + ".pgm";
  const std::string image = slash == std::string::npos ? pgm_path : pgm_path.substr(slash + 1);
  // Both written before either replaces anything, so a failure cannot pair a new image with an old YAML
  // (different size and origin); renamed image first: a reader that finds the new YAML finds its image.
  writeFilesAtomically({{pgm_path, formatPgm(grid)}, {yaml_path, formatMapYaml(grid, image)}});
}

// --- PNG -----------------------------------------------------------------------------------------
namespace {

std::uint32_t crc32(const std::string& s, std::size_t begin) {
  static const std::vector<std::uint32_t> table = [] {
    std::vector<std::uint32_t> t(256);
    for (std::uint32_t n = 0; n < 256; ++n) {
      std::uint32_t c = n;
      for (int k = 0; k < 8; ++k) c = (c & 1) ? 0xEDB88320u ^ (c >> 1) : c >> 1;
      t[n] = c;
    }
    return t;
  }();
  std::uint32_t c = 0xFFFFFFFFu;
  for (std::size_t i = begin; i < s.size(); ++i) c = table[(c ^ static_cast<std::uint8_t>(s[i])) & 0xFF] ^ (c >> 8);
  return c ^ 0xFFFFFFFFu;
}

void putBe32(std::string& s, std::uint32_t v) {
  for (int k = 3; k >= 0; --k) s.push_back(static_cast<char>((v >> (8 * k)) & 0xFF));
}

void chunk(std::string& png, const char* type, const std::string& data) {
  putBe32(png, static_cast<std::uint32_t>(data.size()));
  const std::size_t start = png.size();
  png += type;
  png += data;
  putBe32(png, crc32(png, start));
}

class BitWriter {
 public:
  explicit BitWriter(std::string& out) : out_(out) {}
  void put(std::uint32_t bits, int n) {  // LSB first
    acc_ |= static_cast<std::uint64_t>(bits) << count_;
    count_ += n;
    while (count_ >= 8) {
      out_.push_back(static_cast<char>(acc_ & 0xFF));
      acc_ >>= 8;
      count_ -= 8;
    }
  }
  void putHuffman(std::uint32_t code, int n) {  // Huffman codes go MSB first
    std::uint32_t r = 0;
    for (int i = 0; i < n; ++i) r |= ((code >> i) & 1u) << (n - 1 - i);
    put(r, n);
  }
  void flush() {
    if (count_ > 0) out_.push_back(static_cast<char>(acc_ & 0xFF));
    acc_ = 0;
    count_ = 0;
  }

 private:
  std::string& out_;
  std::uint64_t acc_ = 0;
  int count_ = 0;
};

void fixedLiteral(BitWriter& bw, int sym) {
  if (sym < 144) bw.putHuffman(0x30 + sym, 8);
  else if (sym < 256) bw.putHuffman(0x190 + (sym - 144), 9);
  else if (sym < 280) bw.putHuffman(sym - 256, 7);
  else bw.putHuffman(0xC0 + (sym - 280), 8);
}

const int kLenBase[29] = {3, 4, 5, 6, 7, 8, 9, 10, 11, 13, 15, 17, 19, 23, 27, 31, 35, 43, 51, 59, 67, 83, 99, 115, 131, 163, 195, 227, 258};
const int kLenExtra[29] = {0, 0, 0, 0, 0, 0, 0, 0, 1, 1, 1, 1, 2, 2, 2, 2, 3, 3, 3, 3, 4, 4, 4, 4, 5, 5, 5, 5, 0};
const int kDistBase[30] = {1, 2, 3, 4, 5, 7, 9, 13, 17, 25, 33, 49, 65, 97, 129, 193, 257, 385, 513, 769, 1025, 1537, 2049, 3073, 4097, 6145, 8193, 12289, 16385, 24577};
const int kDistExtra[30] = {0, 0, 0, 0, 1, 1, 2, 2, 3, 3, 4, 4, 5, 5, 6, 6, 7, 7, 8, 8, 9, 9, 10, 10, 11, 11, 12, 12, 13, 13};

/// zlib stream (one fixed-Huffman deflate block, greedy LZ77 with a 3-byte hash).
std::string zlibCompress(const std::string& in) {
  std::string out;
  out.push_back(0x78);
  out.push_back(0x01);
  BitWriter bw(out);
  bw.put(1, 1);  // BFINAL
  bw.put(1, 2);  // fixed Huffman
  const std::size_t n = in.size();
  const auto* d = reinterpret_cast<const std::uint8_t*>(in.data());
  std::vector<std::int64_t> head(1 << 15, -1);
  auto hash = [&](std::size_t i) { return ((d[i] << 10) ^ (d[i + 1] << 5) ^ d[i + 2]) & 0x7FFF; };
  std::size_t i = 0;
  while (i < n) {
    int best_len = 0;
    std::size_t best_dist = 0;
    if (i + 3 <= n) {
      const int h = hash(i);
      const std::int64_t cand = head[h];
      head[h] = static_cast<std::int64_t>(i);
      std::int64_t cands[2] = {cand, static_cast<std::int64_t>(i) - 1};
      for (std::int64_t c : cands) {
        if (c < 0 || static_cast<std::size_t>(c) >= i || i - c > 32768) continue;
        int len = 0;
        while (len < 258 && i + len < n && d[c + len] == d[i + len]) ++len;
        if (len > best_len) {
          best_len = len;
          best_dist = i - c;
        }
      }
    }
    if (best_len >= 3) {
      int li = 28;
      while (kLenBase[li] > best_len) --li;
      fixedLiteral(bw, 257 + li);
      bw.put(best_len - kLenBase[li], kLenExtra[li]);
      int di = 29;
      while (kDistBase[di] > static_cast<int>(best_dist)) --di;
      bw.putHuffman(di, 5);
      bw.put(static_cast<std::uint32_t>(best_dist - kDistBase[di]), kDistExtra[di]);
      for (std::size_t k = i + 1; k < i + best_len && k + 3 <= n; ++k) head[hash(k)] = static_cast<std::int64_t>(k);
      i += best_len;
    } else {
      fixedLiteral(bw, d[i]);
      ++i;
    }
  }
  fixedLiteral(bw, 256);
  bw.flush();
  std::uint32_t a = 1, b = 0;
  for (std::size_t k = 0; k < n; ++k) {
    a = (a + d[k]) % 65521;
    b = (b + a) % 65521;
  }
  putBe32(out, (b << 16) | a);
  return out;
}

}  // namespace

std::string encodePalettePng(int width, int height, const std::vector<std::uint8_t>& idx,
                             const std::vector<std::uint8_t>& palette) {
  if (width <= 0 || height <= 0 || idx.size() != static_cast<std::size_t>(width) * height || palette.empty() ||
      palette.size() % 3 != 0 || palette.size() > 768) {
    throw std::invalid_argument("encodePalettePng: bad image");
  }
  std::string png("\x89PNG\r\n\x1a\n", 8);
  std::string ihdr;
  putBe32(ihdr, static_cast<std::uint32_t>(width));
  putBe32(ihdr, static_cast<std::uint32_t>(height));
  ihdr += std::string("\x08\x03\x00\x00\x00", 5);  // 8 bits, palette, deflate, no filter, no interlace
  chunk(png, "IHDR", ihdr);
  chunk(png, "PLTE", std::string(palette.begin(), palette.end()));
  std::string raw;
  raw.reserve(static_cast<std::size_t>(width + 1) * height);
  for (int r = 0; r < height; ++r) {
    raw.push_back(0);  // filter: none
    raw.append(reinterpret_cast<const char*>(idx.data()) + static_cast<std::size_t>(r) * width, width);
  }
  chunk(png, "IDAT", zlibCompress(raw));
  chunk(png, "IEND", std::string());
  return png;
}

void writeMapPng(const OccupancyGridData& g, const std::vector<StampedPose>& trajectory, const std::string& png_path) {
  constexpr std::uint8_t kUnknown = 101, kPath = 102, kStart = 103, kEnd = 104;
  std::vector<std::uint8_t> pal;
  for (int v = 0; v <= 100; ++v) {
    const auto grey = static_cast<std::uint8_t>(std::lround(255.0 * (1.0 - v / 100.0)));
    pal.insert(pal.end(), {grey, grey, grey});
  }
  pal.insert(pal.end(), {200, 212, 228});  // unknown
  pal.insert(pal.end(), {220, 30, 30});    // trajectory
  pal.insert(pal.end(), {20, 170, 40});    // start
  pal.insert(pal.end(), {30, 60, 220});    // end
  const int w = std::max(1, g.width), h = std::max(1, g.height);
  std::vector<std::uint8_t> img(static_cast<std::size_t>(w) * h, kUnknown);
  for (int iy = 0; iy < g.height; ++iy) {
    for (int ix = 0; ix < g.width; ++ix) {
      const std::int8_t v = g.at(ix, iy);
      img[static_cast<std::size_t>(g.height - 1 - iy) * w + ix] = v < 0 ? kUnknown : static_cast<std::uint8_t>(v);
    }
  }
  auto pixel = [&](double x, double y, int* px, int* py) {
    *px = static_cast<int>(std::floor((x - g.origin_x) / g.resolution));
    *py = h - 1 - static_cast<int>(std::floor((y - g.origin_y) / g.resolution));
  };
  auto set = [&](int px, int py, std::uint8_t c) {
    if (px >= 0 && py >= 0 && px < w && py < h) img[static_cast<std::size_t>(py) * w + px] = c;
  };
  for (std::size_t k = 1; k < trajectory.size(); ++k) {
    int ax, ay, bx, by;
    pixel(trajectory[k - 1].pose.x, trajectory[k - 1].pose.y, &ax, &ay);
    pixel(trajectory[k].pose.x, trajectory[k].pose.y, &bx, &by);
    const int steps = std::max(std::abs(bx - ax), std::abs(by - ay));
    if (steps > 4 * (w + h)) continue;  // a wild jump: not worth drawing
    for (int s = 0; s <= steps; ++s) {
      const double f = steps ? static_cast<double>(s) / steps : 0.0;
      set(static_cast<int>(std::lround(ax + f * (bx - ax))), static_cast<int>(std::lround(ay + f * (by - ay))), kPath);
    }
  }
  auto marker = [&](const StampedPose& p, std::uint8_t c) {
    int px, py;
    pixel(p.pose.x, p.pose.y, &px, &py);
    for (int dy = -2; dy <= 2; ++dy) {
      for (int dx = -2; dx <= 2; ++dx) set(px + dx, py + dy, c);
    }
  };
  if (!trajectory.empty()) {
    marker(trajectory.front(), kStart);
    marker(trajectory.back(), kEnd);
  }
  writeFileAtomically(png_path, encodePalettePng(w, h, img, pal));
}

}  // namespace laser_dpslam
