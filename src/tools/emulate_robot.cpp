// emulate_robot: an iRobot Create (1) and a Hokuyo URG-04LX on two pseudo-terminals, for running
// robot.launch's real drivers (create_driver, urg_node) without hardware. No ROS.
//
//   emulate_robot --floorplan PLAN.yaml --laser-port PATH --create-port PATH [--truth FILE.tum]
//                 [--x M --y M --theta RAD] [--seed N] [--laser-x M --laser-y M --laser-yaw RAD]
//                 [--wheel-scale-noise F] [--wheel-slip-noise F] [--no-noise]
//
// PATH are symlinks to the pseudo-terminals (pass them to urg_node's serial_port and create_driver's
// dev). The Create's wheels, commanded over the Open Interface, move the emulated robot through the
// plan: each wheel's travel is off by a fixed scale error and a random slip, both seeded, while the
// Create reports the commanded travel (its encoders do not see the slip). The URG-04LX, over SCIP 2.0,
// streams scans ray-cast by ScanSimulator from the laser's true pose. The true base pose is written to
// FILE.tum (stamp x y z qx qy qz qw, stamps in wall-clock seconds, the time base of the drivers' ROS
// stamps) at 100 Hz. doc/emulators.md describes both devices.
#include <fcntl.h>
#include <poll.h>
#include <termios.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "laser_dpslam/sim/create_oi.h"
#include "laser_dpslam/sim/floor_plan.h"
#include "laser_dpslam/sim/scan_simulator.h"
#include "laser_dpslam/sim/scip_device.h"

using namespace laser_dpslam;

namespace {

const char* const kUsage =
    "usage: emulate_robot --floorplan PLAN.yaml --laser-port PATH --create-port PATH [options]\n"
    "  --truth FILE          write the true base pose (TUM, wall-clock stamps) at 100 Hz\n"
    "  --x M --y M --theta RAD   start pose in the plan (default 2 6 0: the office's west corridor)\n"
    "  --seed N              random seed of the wheel errors and the laser noise (default 1)\n"
    "  --laser-x M --laser-y M --laser-yaw RAD   laser mount on the base (default 0.1 0 0, robot.launch's)\n"
    "  --wheel-scale-noise F σ of each wheel's fixed scale error (default 0.01)\n"
    "  --wheel-slip-noise F  σ of each wheel's slip per metre travelled, as a fraction (default 0.02)\n"
    "  --no-noise            exact wheels and exact ranges\n";

volatile std::sig_atomic_t g_stop = 0;
void onSignal(int) { g_stop = 1; }

struct Options {
  std::string floorplan, laser_port, create_port, truth;
  double x = 2.0, y = 6.0, theta = 0.0;
  double laser_x = 0.1, laser_y = 0.0, laser_yaw = 0.0;
  double scale_noise = 0.01, slip_noise = 0.02;
  bool no_noise = false;
  unsigned long seed = 1;
};

Options parseArgs(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string flag = argv[i];
    if (flag == "-h" || flag == "--help") { std::cout << kUsage; std::exit(0); }
    if (flag == "--no-noise") { o.no_noise = true; continue; }
    if (flag.rfind("__", 0) == 0 && flag.find(":=") != std::string::npos) continue;  // roslaunch's __name:= etc.
    if (i + 1 >= argc) throw std::invalid_argument(flag + " needs a value");
    const std::string v = argv[++i];
    if (flag == "--floorplan") o.floorplan = v;
    else if (flag == "--laser-port") o.laser_port = v;
    else if (flag == "--create-port") o.create_port = v;
    else if (flag == "--truth") o.truth = v;
    else if (flag == "--x") o.x = std::stod(v);
    else if (flag == "--y") o.y = std::stod(v);
    else if (flag == "--theta") o.theta = std::stod(v);
    else if (flag == "--laser-x") o.laser_x = std::stod(v);
    else if (flag == "--laser-y") o.laser_y = std::stod(v);
    else if (flag == "--laser-yaw") o.laser_yaw = std::stod(v);
    else if (flag == "--wheel-scale-noise") o.scale_noise = std::stod(v);
    else if (flag == "--wheel-slip-noise") o.slip_noise = std::stod(v);
    else if (flag == "--seed") o.seed = std::stoul(v);
    else throw std::invalid_argument("unknown option " + flag);
  }
  if (o.floorplan.empty() || o.laser_port.empty() || o.create_port.empty())
    throw std::invalid_argument("--floorplan, --laser-port and --create-port are required");
  if (o.scale_noise < 0.0 || o.slip_noise < 0.0) throw std::invalid_argument("noise must be >= 0");
  return o;
}

// A pseudo-terminal in raw mode whose slave is reachable through the symlink `link`. The emulator keeps
// the slave open as well, so that a driver closing and reopening the port does not end the master.
struct Pty {
  int master = -1, slave = -1;
  std::string link;

  explicit Pty(const std::string& path) : link(path) {
    master = posix_openpt(O_RDWR | O_NOCTTY | O_NONBLOCK);
    if (master < 0 || grantpt(master) != 0 || unlockpt(master) != 0)
      throw std::runtime_error("cannot create a pseudo-terminal: " + std::string(std::strerror(errno)));
    const std::string name = ptsname(master);
    slave = open(name.c_str(), O_RDWR | O_NOCTTY);
    termios t{};
    if (slave < 0 || tcgetattr(slave, &t) != 0) throw std::runtime_error("cannot open " + name);
    cfmakeraw(&t);
    tcsetattr(slave, TCSANOW, &t);
    std::remove(link.c_str());
    if (symlink(name.c_str(), link.c_str()) != 0)
      throw std::runtime_error("cannot link " + link + " to " + name + ": " + std::strerror(errno));
  }
  ~Pty() {
    std::remove(link.c_str());
    close(slave);
    close(master);
  }
  std::string read() {
    char buf[512];
    const ssize_t n = ::read(master, buf, sizeof(buf));
    return n > 0 ? std::string(buf, n) : std::string();
  }
  // Non-blocking: a host that does not read loses bytes instead of stalling the emulator.
  void write(const std::string& bytes) {
    if (!bytes.empty() && ::write(master, bytes.data(), bytes.size()) < 0 && errno != EAGAIN)
      std::cerr << "emulate_robot: write to " << link << ": " << std::strerror(errno) << "\n";
  }
};

double wallSeconds() {
  return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
}

// The robot's true motion: the commanded wheel travel with seeded scale errors and slip.
struct Body {
  Pose2D pose;
  double scale_left = 1.0, scale_right = 1.0, slip = 0.0;
  std::mt19937_64 rng;

  // Box–Muller from 53-bit uniforms: the same seed gives the same robot on every platform (the
  // standard library's normal_distribution differs between implementations).
  double normal() {
    const double u1 = ((rng() >> 11) + 1.0) * 0x1.0p-53, u2 = (rng() >> 11) * 0x1.0p-53;
    return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * M_PI * u2);
  }

  void step(double left_mm_s, double right_mm_s, double dt, create_oi::SensorState& sensors) {
    const double dl = left_mm_s * dt / 1000.0, dr = right_mm_s * dt / 1000.0;
    // The encoders count the commanded travel; the ground sees it scaled and slipping.
    sensors.distance_mm += (dl + dr) / 2.0 * 1000.0;
    sensors.angle_deg += (dr - dl) / create_oi::kAxleLength * 180.0 / M_PI;
    const double tl = dl * scale_left + slip * std::sqrt(std::abs(dl)) * normal();  // σ ∝ √distance
    const double tr = dr * scale_right + slip * std::sqrt(std::abs(dr)) * normal();
    const double ds = (tl + tr) / 2.0, dth = (tr - tl) / create_oi::kAxleLength;
    const double mid = pose.theta + dth / 2.0;
    pose = Pose2D(pose.x + ds * std::cos(mid), pose.y + ds * std::sin(mid), normalizeAngle(pose.theta + dth));
  }
};

int run(const Options& o) {
  const FloorPlan plan = FloorPlan::load(o.floorplan);
  ScanSimulatorConfig sim;
  const scip::UrgParameters urg;
  const double step_rad = 2.0 * M_PI / urg.ares;
  sim.beams = urg.amax - urg.amin + 1;
  sim.angle_min = (urg.amin - urg.afrt) * step_rad;
  sim.angle_max = (urg.amax - urg.afrt) * step_rad;
  if (o.no_noise) sim.noise_min_stddev = sim.noise_range_fraction = sim.dropout_probability = sim.grazing_dropout_probability = 0.0;
  ScanSimulator simulator(plan, sim, o.seed);

  Body body;
  body.pose = Pose2D(o.x, o.y, o.theta);
  body.rng.seed(o.seed * 7919 + 13);
  if (!o.no_noise) {
    body.scale_left = 1.0 + o.scale_noise * body.normal();
    body.scale_right = 1.0 + o.scale_noise * body.normal();
    body.slip = o.slip_noise;
  }
  if (plan.occupied(o.x, o.y)) throw std::runtime_error("the start pose lies in a wall of " + o.floorplan);
  const Pose2D mount(o.laser_x, o.laser_y, o.laser_yaw);

  const auto t0 = std::chrono::steady_clock::now();
  auto sensorMs = [&] {
    return static_cast<std::uint32_t>(
        std::chrono::duration_cast<std::chrono::milliseconds>(std::chrono::steady_clock::now() - t0).count());
  };
  scip::ScipDevice laser([&](int first, int last) {
    const LaserScan scan = simulator.simulate(body.pose * mount, wallSeconds());
    std::vector<std::uint32_t> mm;
    for (int step = first; step <= last; ++step) {
      const int i = step - urg.amin;
      const bool valid = i >= 0 && i < static_cast<int>(scan.ranges.size()) && std::isfinite(scan.ranges[i]);
      mm.push_back(valid ? static_cast<std::uint32_t>(std::lround(scan.ranges[i] * 1000.0)) : 0u);
    }
    return mm;
  });
  create_oi::CreateDevice create;
  create_oi::SensorState sensors;

  Pty laser_pty(o.laser_port), create_pty(o.create_port);
  std::ofstream truth;
  if (!o.truth.empty()) {
    truth.open(o.truth);
    if (!truth) throw std::runtime_error("cannot write " + o.truth);
    truth << std::fixed << std::setprecision(6);
  }
  std::cerr << "emulate_robot: URG-04LX on " << o.laser_port << ", Create on " << o.create_port
            << "; wheel scale errors left " << body.scale_left - 1.0 << ", right " << body.scale_right - 1.0 << "\n";

  double last = wallSeconds(), last_truth = 0.0;
  while (!g_stop) {
    pollfd fds[2] = {{laser_pty.master, POLLIN, 0}, {create_pty.master, POLLIN, 0}};
    poll(fds, 2, 2);
    const double now = wallSeconds();
    body.step(create.leftVelocity(), create.rightVelocity(), std::max(0.0, now - last), sensors);
    last = now;
    if (fds[0].revents & POLLIN) laser_pty.write(laser.feed(laser_pty.read(), sensorMs()));
    if (fds[1].revents & POLLIN) {
      const std::string in = create_pty.read();
      const auto reply = create.feed(std::vector<std::uint8_t>(in.begin(), in.end()), sensors);
      create_pty.write(std::string(reply.begin(), reply.end()));
    }
    laser_pty.write(laser.tick(sensorMs()));
    const auto frame = create.streamTick(now, sensors);
    create_pty.write(std::string(frame.begin(), frame.end()));
    if (truth.is_open() && now - last_truth >= 0.01) {
      const Pose2D& p = body.pose;
      truth << now << ' ' << p.x << ' ' << p.y << " 0 0 0 " << std::sin(p.theta / 2.0) << ' '
            << std::cos(p.theta / 2.0) << '\n' << std::flush;
      last_truth = now;
    }
  }
  std::cerr << "emulate_robot: " << laser.scansSent() << " scans, " << create.framesSent()
            << " Create frames, final pose " << body.pose.x << " " << body.pose.y << " " << body.pose.theta << "\n";
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  Options options;
  try {
    options = parseArgs(argc, argv);
  } catch (const std::exception& e) {
    std::cerr << "emulate_robot: " << e.what() << "\n\n" << kUsage;
    return 2;
  }
  std::signal(SIGINT, onSignal);
  std::signal(SIGTERM, onSignal);
  try {
    return run(options);
  } catch (const std::exception& e) {
    std::cerr << "emulate_robot: error: " << e.what() << "\n";
    return 1;
  }
}
