// The one simulated robot of the tests: a truth path in a polygonal world, a laser (spec, sweep, mount),
// wheels (error model, delay, a jump, a clock offset) and a gyro (rate, bias, noise, seed). It produces
// the inputs in time order through a sink; the core tests feed them to an OdometryTracker or an
// OdometryPipeline, the rostests publish them. Header-only, ROS-free, built on test_util.h.
#pragma once

#include <cmath>
#include <functional>
#include <limits>
#include <optional>
#include <random>
#include <utility>

#include "test_util.h"

namespace hglasm_test {

using Path = std::function<hglasm::Pose2D(double)>;

/// Where the robot's samples go; an unset callback drops its samples (time goes on). Stamps are the
/// simulated time plus the robot's stamp offset.
struct RobotSink {
  std::function<void(double stamp, const hglasm::Pose2D& pose)> wheels;
  std::function<void(double stamp, double yaw_rate)> gyro;
};

/// A yaw-rate gyro: the true rate plus a constant bias and seeded white noise.
struct GyroSpec {
  double period = 0.005;       ///< s (200 Hz)
  double bias = 0.0;           ///< rad/s
  double noise_density = 0.0;  ///< rad/s per sqrt(Hz)
  unsigned seed = 0;
  /// libstdc++'s normal distribution draws in pairs. The tracker tests take one value of each pair (false),
  /// the IMU rostest both within one advanceGyro() call (true); kept so each test sees its old samples.
  bool pairs_within_call = false;
};

class SimulatedRobot {
 public:
  /// Wheel samples are taken every SimulatedWheels::kPeriod after `wheel_start`.
  explicit SimulatedRobot(Path path, World world = room(), LaserSpec laser = halfCircleLaser(),
                          double wheel_start = 0.0)
      : path_(path), world_(std::move(world)), laser_(laser), wheels_(std::move(path), wheel_start) {}

  // ---------------------------------------------------------------- truth and laser
  hglasm::Pose2D truth(double t) const { return path_(t); }
  const Path& path() const { return path_; }
  const World& world() const { return world_; }

  void setLaser(const LaserSpec& laser) { laser_ = laser; }
  const LaserSpec& laser() const { return laser_; }
  /// base -> laser. Without one the laser is the base itself (no rounding through a composition).
  void setMount(const hglasm::Pose2D& mount) { mount_ = mount; }
  hglasm::Pose2D mount() const { return mount_.value_or(hglasm::Pose2D()); }
  /// The laser's sweep from the first beam to the last (0: all beams at once); scanAt only.
  void setSweepTime(double seconds) { sweep_time_ = seconds; }
  double sweepTime() const { return sweep_time_; }

  hglasm::Pose2D laserPose(double t) const { return mount_ ? composeByHand(path_(t), *mount_) : path_(t); }

  /// The scan at t as points: each beam leaves from where the laser is when it is measured.
  hglasm::Scan scanAt(double t) const {
    const double time_increment = sweep_time_ > 0.0 ? sweep_time_ / (laser_.beams - 1) : 0.0;
    hglasm::Scan scan = simulateSweep(
        world_, [&](int beam) { return laserPose(t + beam * time_increment); }, laser_);
    scan.time_increment = time_increment;
    return scan;
  }
  /// The scan at t as a driver publishes it (every beam at t).
  hglasm::RangeScan rangesAt(double t) const { return simulateRanges(world_, laserPose(t), laser_); }

  // ---------------------------------------------------------------- clock
  /// The sensors' clock is ahead of the simulated time by `offset` (scan, wheel and gyro stamps).
  void setStampOffset(double offset) { stamp_offset_ = offset; }
  double stampOffset() const { return stamp_offset_; }
  double stampOf(double t) const { return t + stamp_offset_; }

  // ---------------------------------------------------------------- wheels
  /// The wheels sample only once enabled (integrated wheels start from their pose then).
  void enableWheels() { wheels_on_ = true; }
  bool wheelsEnabled() const { return wheels_on_; }
  /// Their error model, path and restarts (see SimulatedWheels).
  SimulatedWheels& wheels() { return wheels_; }
  const SimulatedWheels& wheels() const { return wheels_; }
  /// Samples reach the sink `delay` seconds after their simulated time.
  void setWheelDelay(double delay) { wheel_delay_ = delay; }
  /// Samples taken at or after `time` are offset by `jump` (the wheel-odometry frame re-initialised).
  void setWheelJump(double time, const hglasm::Pose2D& jump) {
    jump_time_ = time;
    jump_ = jump;
  }

  /// The wheel samples available at t.
  void advanceWheels(double t, const RobotSink& sink) {
    if (!wheels_on_) return;
    wheels_.advance(t - wheel_delay_, [&](double time, const hglasm::Pose2D& pose) {
      if (sink.wheels) sink.wheels(stampOf(time), time >= jump_time_ ? composeByHand(jump_, pose) : pose);
    });
  }

  // ---------------------------------------------------------------- gyro
  void enableGyro(const GyroSpec& spec) {
    gyro_on_ = true;
    gyro_ = spec;
    gyro_time_ = -spec.period;
    gyro_random_.seed(spec.seed);
  }
  /// The gyro stops (no samples, its clock stands).
  void disableGyro() { gyro_on_ = false; }
  bool gyroEnabled() const { return gyro_on_; }

  /// The gyro samples up to `until` (1 ns tolerance).
  void advanceGyro(double until, const RobotSink& sink) {
    if (!gyro_on_) return;
    const bool noisy = gyro_.noise_density > 0.0;
    std::normal_distribution<double> noise(0.0, noisy ? gyro_.noise_density / std::sqrt(gyro_.period) : 1.0);
    while (gyro_time_ + gyro_.period <= until + 1e-9) {
      gyro_time_ += gyro_.period;
      if (!gyro_.pairs_within_call) noise.reset();
      const double rate = yawRate(path_, gyro_time_) + gyro_.bias + (noisy ? noise(gyro_random_) : 0.0);
      if (sink.gyro) sink.gyro(stampOf(gyro_time_), rate);
    }
  }

  /// What is there when the scan of t is processed (once its sweep is over): the wheels, then the gyro.
  void advanceTo(double t, const RobotSink& sink) {
    advanceWheels(t, sink);
    advanceGyro(t + sweep_time_, sink);
  }

 private:
  Path path_;
  World world_;
  LaserSpec laser_;
  std::optional<hglasm::Pose2D> mount_;
  double sweep_time_ = 0.0;
  double stamp_offset_ = 0.0;
  SimulatedWheels wheels_;
  bool wheels_on_ = false;
  double wheel_delay_ = 0.0;
  double jump_time_ = std::numeric_limits<double>::infinity();
  hglasm::Pose2D jump_;
  bool gyro_on_ = false;
  GyroSpec gyro_;
  double gyro_time_ = 0.0;
  std::mt19937 gyro_random_;
};

}  // namespace hglasm_test
