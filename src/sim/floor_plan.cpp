#include "laser_dpslam/sim/floor_plan.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace laser_dpslam {

namespace {

namespace fs = std::filesystem;

struct GreyImage {
  int width = 0;
  int height = 0;
  std::vector<std::uint8_t> pixels;  ///< row-major, row 0 = top, scaled to 0..255
};

[[noreturn]] void fail(const std::string& file, const std::string& what) {
  throw std::runtime_error(file + ": " + what);
}

/// Reads the next header token of a PNM file, skipping whitespace and '#' comments.
std::string nextToken(const std::string& data, std::size_t& pos) {
  while (pos < data.size()) {
    const unsigned char c = static_cast<unsigned char>(data[pos]);
    if (std::isspace(c)) {
      ++pos;
    } else if (c == '#') {
      while (pos < data.size() && data[pos] != '\n' && data[pos] != '\r') ++pos;
    } else {
      break;
    }
  }
  const std::size_t start = pos;
  while (pos < data.size() && !std::isspace(static_cast<unsigned char>(data[pos])) && data[pos] != '#')
    ++pos;
  return data.substr(start, pos - start);
}

long parseHeaderInt(const std::string& file, const std::string& token, const char* what) {
  if (token.empty()) fail(file, std::string("malformed PGM: missing ") + what);
  if (!std::all_of(token.begin(), token.end(), [](char c) { return std::isdigit(static_cast<unsigned char>(c)); }) ||
      token.size() > 9)
    fail(file, std::string("malformed PGM: bad ") + what + " '" + token + "'");
  return std::stol(token);
}

GreyImage readPgm(const std::string& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) fail(file, "cannot open the floor-plan image (missing or unreadable)");
  std::ostringstream buf;
  buf << in.rdbuf();
  const std::string data = buf.str();

  std::size_t pos = 0;
  const std::string magic = nextToken(data, pos);
  if (magic != "P5" && magic != "P2") {
    fail(file, "not a grey PGM image (magic '" + magic.substr(0, 8) +
                   "'; only 8-bit P5 binary or P2 ascii PGM is supported)");
  }
  const long width = parseHeaderInt(file, nextToken(data, pos), "width");
  const long height = parseHeaderInt(file, nextToken(data, pos), "height");
  const long maxval = parseHeaderInt(file, nextToken(data, pos), "maxval");
  if (width <= 0 || height <= 0) fail(file, "malformed PGM: empty image");
  if (width > 100000 || height > 100000) fail(file, "malformed PGM: image too large");
  if (maxval <= 0 || maxval > 65535) fail(file, "malformed PGM: maxval " + std::to_string(maxval) + " out of range");
  if (maxval > 255) fail(file, "16-bit PGM (maxval " + std::to_string(maxval) + ") is not supported; use 8-bit");

  GreyImage img;
  img.width = static_cast<int>(width);
  img.height = static_cast<int>(height);
  const std::size_t n = static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
  img.pixels.resize(n);
  auto scale = [maxval](long v) {
    return static_cast<std::uint8_t>(maxval == 255 ? v : std::lround(v * 255.0 / maxval));
  };

  if (magic == "P5") {
    // Exactly one whitespace character separates maxval from the raster.
    if (pos >= data.size()) fail(file, "malformed PGM: truncated after the header");
    ++pos;
    if (data.size() - pos < n) {
      fail(file, "malformed PGM: truncated raster (" + std::to_string(data.size() - pos) + " of " +
                     std::to_string(n) + " bytes)");
    }
    for (std::size_t i = 0; i < n; ++i) {
      const long v = static_cast<unsigned char>(data[pos + i]);
      if (v > maxval) fail(file, "malformed PGM: pixel value " + std::to_string(v) + " above maxval");
      img.pixels[i] = scale(v);
    }
  } else {
    for (std::size_t i = 0; i < n; ++i) {
      const std::string tok = nextToken(data, pos);
      if (tok.empty()) {
        fail(file, "malformed PGM: truncated raster (" + std::to_string(i) + " of " + std::to_string(n) +
                       " values)");
      }
      const long v = parseHeaderInt(file, tok, "pixel value");
      if (v > maxval) fail(file, "malformed PGM: pixel value " + std::to_string(v) + " above maxval");
      img.pixels[i] = scale(v);
    }
  }
  return img;
}

double yamlDouble(const YAML::Node& root, const std::string& key, const std::string& file) {
  const YAML::Node node = root[key];
  if (!node) fail(file, "missing key '" + key + "'");
  try {
    return node.as<double>();
  } catch (const YAML::Exception&) {
    fail(file, "key '" + key + "' is not a number");
  }
}

YAML::Node loadYaml(const std::string& yaml_path) {
  YAML::Node root;
  try {
    root = YAML::LoadFile(yaml_path);
  } catch (const YAML::BadFile&) {
    fail(yaml_path, "cannot open the floor-plan YAML (missing or unreadable)");
  } catch (const YAML::Exception& e) {
    fail(yaml_path, std::string("malformed YAML: ") + e.what());
  }
  if (!root.IsMap()) fail(yaml_path, "malformed floor-plan YAML: expected a map_server mapping (image, resolution, origin, ...)");
  return root;
}

std::string imageName(const YAML::Node& root, const std::string& yaml_path) {
  const YAML::Node image_node = root["image"];
  if (!image_node) fail(yaml_path, "missing key 'image'");
  std::string image;
  try {
    image = image_node.as<std::string>();
  } catch (const YAML::Exception&) {
    fail(yaml_path, "key 'image' is not a string");
  }
  if (image.empty()) fail(yaml_path, "key 'image' is empty");
  return image;
}

/// The origin's x and y (its yaw must be 0).
Eigen::Vector2d originOf(const YAML::Node& root, const std::string& yaml_path) {
  const YAML::Node origin_node = root["origin"];
  if (!origin_node) fail(yaml_path, "missing key 'origin'");
  if (!origin_node.IsSequence() || origin_node.size() != 3) fail(yaml_path, "origin must be [x, y, yaw]");
  double origin[3];
  for (int i = 0; i < 3; ++i) {
    try {
      origin[i] = origin_node[i].as<double>();
    } catch (const YAML::Exception&) {
      fail(yaml_path, "origin must be [x, y, yaw] numbers");
    }
    if (!std::isfinite(origin[i])) fail(yaml_path, "origin must be finite");
  }
  if (std::abs(origin[2]) > 1e-9) {
    fail(yaml_path, "origin yaw " + std::to_string(origin[2]) + " is not supported (only 0)");
  }
  return Eigen::Vector2d(origin[0], origin[1]);
}

bool negateOf(const YAML::Node& root, const std::string& yaml_path) {
  bool negate = false;
  if (const YAML::Node n = root["negate"]) {
    try {
      negate = n.as<int>() != 0;
    } catch (const YAML::Exception&) {
      try {
        negate = n.as<bool>();
      } catch (const YAML::Exception&) {
        fail(yaml_path, "key 'negate' must be 0 or 1");
      }
    }
  }
  return negate;
}

/// occupied_thresh and free_thresh (map_server's defaults when absent); checks the mode too.
void readThresholds(const YAML::Node& root, const std::string& yaml_path, double* occupied_thresh,
                    double* free_thresh) {
  *occupied_thresh = root["occupied_thresh"] ? yamlDouble(root, "occupied_thresh", yaml_path) : 0.65;
  *free_thresh = root["free_thresh"] ? yamlDouble(root, "free_thresh", yaml_path) : 0.196;
  if (!(*occupied_thresh >= 0.0 && *occupied_thresh <= 1.0) || !(*free_thresh >= 0.0 && *free_thresh <= 1.0) ||
      *free_thresh > *occupied_thresh) {
    fail(yaml_path, "need 0 <= free_thresh <= occupied_thresh <= 1");
  }
  if (const YAML::Node m = root["mode"]) {
    std::string mode;
    try {
      mode = m.as<std::string>();
    } catch (const YAML::Exception&) {
      fail(yaml_path, "key 'mode' is not a string");
    }
    if (mode != "trinary" && mode != "scale") fail(yaml_path, "mode '" + mode + "' is not supported (trinary or scale)");
  }
}

/// The image's path (relative to the YAML's folder unless absolute); it must be a .pgm.
std::string imageFile(const std::string& image, const std::string& yaml_path) {
  fs::path image_path(image);
  if (image_path.is_relative()) image_path = fs::path(yaml_path).parent_path() / image_path;
  const std::string image_file = image_path.string();
  const std::string ext = image_path.extension().string();
  std::string ext_lower = ext;
  std::transform(ext_lower.begin(), ext_lower.end(), ext_lower.begin(), ::tolower);
  if (ext_lower != ".pgm") {
    fail(yaml_path, "image '" + image + "' is not a .pgm file (only PGM images are supported)");
  }
  return image_file;
}

}  // namespace

FloorPlan FloorPlan::load(const std::string& yaml_path) {
  const YAML::Node root = loadYaml(yaml_path);
  const std::string image = imageName(root, yaml_path);
  const double resolution = yamlDouble(root, "resolution", yaml_path);
  if (!(resolution > 0.0) || !std::isfinite(resolution)) fail(yaml_path, "resolution must be positive");
  const Eigen::Vector2d origin = originOf(root, yaml_path);
  const bool negate = negateOf(root, yaml_path);
  double occupied_thresh, free_thresh;
  readThresholds(root, yaml_path, &occupied_thresh, &free_thresh);
  const GreyImage img = readPgm(imageFile(image, yaml_path));

  FloorPlan plan;
  plan.width_ = img.width;
  plan.height_ = img.height;
  plan.resolution_ = resolution;
  plan.origin_ = origin;
  plan.source_ = yaml_path;
  plan.cells_.assign(static_cast<std::size_t>(img.width) * img.height, kUnknown);
  for (int row = 0; row < img.height; ++row) {
    const int iy = img.height - 1 - row;  // image row 0 is the top of the map
    for (int ix = 0; ix < img.width; ++ix) {
      const double v = img.pixels[static_cast<std::size_t>(row) * img.width + ix];
      const double p = negate ? v / 255.0 : (255.0 - v) / 255.0;
      Cell c = kUnknown;
      if (p > occupied_thresh) {
        c = kOccupied;
      } else if (p < free_thresh) {
        c = kFree;
      }
      plan.cells_[static_cast<std::size_t>(iy) * img.width + ix] = c;
    }
  }
  return plan;
}

FloorPlan FloorPlan::fromOccupancy(int width, int height, double resolution, Eigen::Vector2d origin,
                                   std::vector<std::uint8_t> occupied) {
  if (width <= 0 || height <= 0) throw std::invalid_argument("FloorPlan::fromOccupancy: empty grid");
  if (!(resolution > 0.0)) throw std::invalid_argument("FloorPlan::fromOccupancy: resolution must be positive");
  if (occupied.size() != static_cast<std::size_t>(width) * static_cast<std::size_t>(height)) {
    throw std::invalid_argument("FloorPlan::fromOccupancy: " + std::to_string(occupied.size()) +
                                " cells given for a " + std::to_string(width) + "x" + std::to_string(height) +
                                " grid");
  }
  FloorPlan plan;
  plan.width_ = width;
  plan.height_ = height;
  plan.resolution_ = resolution;
  plan.origin_ = origin;
  plan.cells_.resize(occupied.size());
  for (std::size_t i = 0; i < occupied.size(); ++i) plan.cells_[i] = occupied[i] ? kOccupied : kFree;
  return plan;
}

void FloorPlan::save(const std::string& yaml_path) const {
  const fs::path yaml(yaml_path);
  fs::path pgm = yaml;
  pgm.replace_extension(".pgm");
  {
    std::ofstream out(pgm, std::ios::binary);
    if (!out) fail(pgm.string(), "cannot write the floor-plan image");
    out << "P5\n# laser_dpslam floor plan\n" << width_ << " " << height_ << "\n255\n";
    std::string row(static_cast<std::size_t>(width_), '\0');
    for (int r = 0; r < height_; ++r) {
      const int iy = height_ - 1 - r;
      for (int ix = 0; ix < width_; ++ix) {
        const Cell c = cell(ix, iy);
        row[ix] = static_cast<char>(c == kOccupied ? 0 : (c == kFree ? 254 : 205));
      }
      out.write(row.data(), static_cast<std::streamsize>(row.size()));
    }
    if (!out) fail(pgm.string(), "error while writing the floor-plan image");
  }
  std::ofstream out(yaml);
  if (!out) fail(yaml_path, "cannot write the floor-plan YAML");
  out << std::setprecision(12);
  out << "image: " << pgm.filename().string() << "\n"
      << "resolution: " << resolution_ << "\n"
      << "origin: [" << origin_.x() << ", " << origin_.y() << ", 0.0]\n"
      << "negate: 0\n"
      << "occupied_thresh: 0.65\n"
      << "free_thresh: 0.196\n";
  if (!out) fail(yaml_path, "error while writing the floor-plan YAML");
}

FloorPlan::Cell FloorPlan::cell(int ix, int iy) const {
  if (ix < 0 || iy < 0 || ix >= width_ || iy >= height_) return kUnknown;
  return static_cast<Cell>(cells_[static_cast<std::size_t>(iy) * width_ + ix]);
}

bool FloorPlan::occupied(double x, double y) const {
  const double gx = std::floor((x - origin_.x()) / resolution_);
  const double gy = std::floor((y - origin_.y()) / resolution_);
  if (!(gx >= 0 && gy >= 0 && gx < width_ && gy < height_)) return false;
  return cellOccupied(static_cast<int>(gx), static_cast<int>(gy));
}

bool FloorPlan::isFree(double x, double y) const {
  const double gx = std::floor((x - origin_.x()) / resolution_);
  const double gy = std::floor((y - origin_.y()) / resolution_);
  if (!(gx >= 0 && gy >= 0 && gx < width_ && gy < height_)) return false;
  return cell(static_cast<int>(gx), static_cast<int>(gy)) == kFree;
}

double FloorPlan::clearance(const Eigen::Vector2d& p, double max_radius) const {
  if (width_ == 0 || !(max_radius > 0.0)) return std::max(0.0, max_radius);
  const int ix0 = std::max(0, static_cast<int>(std::floor((p.x() - max_radius - origin_.x()) / resolution_)));
  const int ix1 = std::min(width_ - 1, static_cast<int>(std::floor((p.x() + max_radius - origin_.x()) / resolution_)));
  const int iy0 = std::max(0, static_cast<int>(std::floor((p.y() - max_radius - origin_.y()) / resolution_)));
  const int iy1 = std::min(height_ - 1, static_cast<int>(std::floor((p.y() + max_radius - origin_.y()) / resolution_)));
  double best = max_radius;
  for (int iy = iy0; iy <= iy1; ++iy) {
    for (int ix = ix0; ix <= ix1; ++ix) {
      if (!cellOccupied(ix, iy)) continue;
      const double cx0 = origin_.x() + ix * resolution_, cy0 = origin_.y() + iy * resolution_;
      const double dx = std::max({cx0 - p.x(), 0.0, p.x() - (cx0 + resolution_)});
      const double dy = std::max({cy0 - p.y(), 0.0, p.y() - (cy0 + resolution_)});
      best = std::min(best, std::hypot(dx, dy));
    }
  }
  return best;
}

double FloorPlan::raycast(const Eigen::Vector2d& from, double angle, double max_range) const {
  return raycast(from, angle, max_range, nullptr);
}

double FloorPlan::raycast(const Eigen::Vector2d& from, double angle, double max_range, int* hit_axis) const {
  constexpr double kInf = std::numeric_limits<double>::infinity();
  if (hit_axis) *hit_axis = -1;
  if (width_ == 0 || height_ == 0 || !std::isfinite(angle) || !from.allFinite() || !(max_range >= 0.0)) return kInf;

  const double d[2] = {std::cos(angle), std::sin(angle)};
  const double p[2] = {from.x(), from.y()};
  const double lo[2] = {origin_.x(), origin_.y()};
  const int n[2] = {width_, height_};

  // Clip the ray to the grid's box (slab method); remember through which face it enters.
  double t_enter = 0.0, t_exit = max_range;
  int enter_axis = -1;
  for (int a = 0; a < 2; ++a) {
    const double hi = lo[a] + n[a] * resolution_;
    if (d[a] == 0.0) {
      if (p[a] < lo[a] || p[a] >= hi) return kInf;
      continue;
    }
    double t1 = (lo[a] - p[a]) / d[a], t2 = (hi - p[a]) / d[a];
    if (t1 > t2) std::swap(t1, t2);
    if (t1 > t_enter) {
      t_enter = t1;
      enter_axis = a;
    }
    t_exit = std::min(t_exit, t2);
  }
  if (t_enter > t_exit) return kInf;

  // Starting cell: the cell containing the entry point (clamped for points on the grid's far faces).
  int cell_idx[2], step[2];
  for (int a = 0; a < 2; ++a) {
    const double q = p[a] + t_enter * d[a];
    double g = std::floor((q - lo[a]) / resolution_);
    if (a == enter_axis) g = d[a] > 0 ? 0 : n[a] - 1;  // entered through this axis' face
    g = std::min(std::max(g, 0.0), static_cast<double>(n[a] - 1));
    cell_idx[a] = static_cast<int>(g);
    step[a] = d[a] > 0 ? 1 : (d[a] < 0 ? -1 : 0);
  }

  double t = t_enter;
  int axis = enter_axis;
  for (;;) {
    if (cellOccupied(cell_idx[0], cell_idx[1])) {
      if (t > max_range) return kInf;
      if (hit_axis) *hit_axis = axis;
      return std::max(t, 0.0);
    }
    // Distance to the next cell face along each axis, from the face's exact coordinate (no accumulated
    // increments, so the hit distance is exact up to rounding).
    double t_next[2];
    for (int a = 0; a < 2; ++a) {
      if (step[a] == 0) {
        t_next[a] = kInf;
      } else {
        const double face = lo[a] + (cell_idx[a] + (step[a] > 0 ? 1 : 0)) * resolution_;
        t_next[a] = (face - p[a]) / d[a];
      }
    }
    axis = t_next[0] < t_next[1] ? 0 : 1;
    t = t_next[axis];
    cell_idx[axis] += step[axis];
    if (t > max_range) return kInf;
    if (cell_idx[axis] < 0 || cell_idx[axis] >= n[axis]) return kInf;
  }
}

}  // namespace laser_dpslam
