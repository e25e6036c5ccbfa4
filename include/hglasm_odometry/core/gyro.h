// The rotation of the base between two stamps from an IMU: its yaw rate integrated, or the difference of
// its yaw; how far that rotation may be off; and the gyro's bias, learned from the scan matches.
#pragma once

#include <cstddef>
#include <deque>

namespace hglasm {

struct GyroOptions {
  /// Take the rotation from the IMU's orientation (the difference of its yaw) instead of integrating its
  /// yaw rate: for IMUs whose own filter estimates the gyro's bias.
  bool use_orientation = false;
  /// Seconds: a gap between IMU samples longer than this, or a stamp farther than this beyond the
  /// samples, makes the IMU stale for that interval (the wheels predict the rotation instead).
  double max_gap = 0.1;
  /// The rotation's noise: white rate noise (angle random walk, rad per sqrt(s); 0.002 is 0.11 deg/s per
  /// sqrt(Hz), ten times a consumer MEMS gyro's datasheet figure, for a robot's vibration); ...
  double angle_random_walk = 0.002;
  /// ... an unknown bias, of this standard deviation (rad/s) before the matches have taught its value
  /// (estimate_bias); its error grows with the interval; ...
  double bias_sigma = 0.005;
  /// ... and an error proportional to the rotation (scale factor, and stamps of the IMU and the laser a
  /// few milliseconds apart): the fraction of the rotation it reaches (standard deviation).
  double scale_error = 0.02;
  /// Learn the bias from the matches: every matched step compares the IMU's rotation with the scans'.
  bool estimate_bias = true;
  /// How fast the bias wanders (temperature, time): rad/s per sqrt(s), a random walk.
  double bias_random_walk = 1e-4;
};

/// Its parameters and their valid ranges, for OptionReader and OptionWriter (parameter_source.h).
template <typename Visitor>
void visitOptions(Visitor& visitor, GyroOptions* options) {
  visitor.boolean("imu/use_orientation", &options->use_orientation);
  visitor.number("imu/max_gap", &options->max_gap, 0.0, 10.0, true);
  visitor.nonNegativeNumber("imu/noise/angle_random_walk", &options->angle_random_walk);
  visitor.nonNegativeNumber("imu/noise/bias_sigma", &options->bias_sigma);
  visitor.nonNegativeNumber("imu/noise/scale_error", &options->scale_error);
  visitor.boolean("imu/noise/estimate_bias", &options->estimate_bias);
  visitor.nonNegativeNumber("imu/noise/bias_random_walk", &options->bias_random_walk);
}

/// Variance (rad^2) of a gyro rotation of `angle` radians over `dt` seconds under `options`' noise model,
/// with a bias known to `bias_variance` ((rad/s)^2; bias_sigma squared before anything is learned).
double gyroRotationVariance(const GyroOptions& options, double angle, double dt, double bias_variance);

/// The gyro's bias as a scalar Kalman filter: a random walk (bias_random_walk) observed by each matched
/// step, the IMU's rotation against the scans'. Not thread-safe per instance.
class GyroBiasEstimator {
 public:
  explicit GyroBiasEstimator(const GyroOptions& options = {});

  /// One step of `dt` s ending at `stamp`: `predicted` is the IMU's rotation corrected by bias() (as the
  /// prediction used it), `measured` the scans' rotation over the same step, with variance
  /// `measured_variance`. The bias wanders over the whole time since the previous update (the IMU may
  /// have been stale, matches may have failed). A difference beyond kGate standard deviations of what the
  /// filter expects counts as kGate, so one bad match moves the estimate little. Differences that keep
  /// leaning one way (a bias that changed faster than the model allows) widen the variance, and the
  /// estimate follows within a few steps. Ignored (false) without estimate_bias, or for non-finite,
  /// negative or zero-length input.
  bool update(double predicted, double measured, double measured_variance, double dt, double stamp);

  double bias() const { return bias_; }          ///< rad/s
  double variance() const { return variance_; }  ///< (rad/s)^2
  /// Back to no knowledge: zero with bias_sigma's variance.
  void reset();

  static constexpr double kGate = 4.0;
  /// The innovations' running mean (in standard deviations) over about kInnovationMemory steps: under
  /// the model its standard deviation is 0.23, so beyond kDriftSigmas (5.4 of those) it is a drift, not
  /// noise: none in 10^5 steps of noise alone.
  static constexpr double kInnovationMemory = 10.0;
  static constexpr double kDriftSigmas = 1.25;

 private:
  GyroOptions options_;
  double bias_ = 0.0;
  double variance_ = 0.0;
  double last_stamp_ = 0.0;
  bool have_stamp_ = false;
  double mean_sigmas_ = 0.0;      // running mean of the innovations in standard deviations
  double mean_bias_error_ = 0.0;  // running mean of innovation / dt: the bias error they show, rad/s
};

/// A short history of IMU samples: the base's yaw rate (rad/s), or its yaw (rad) when
/// options.use_orientation. Not thread-safe per instance.
class GyroBuffer {
 public:
  explicit GyroBuffer(const GyroOptions& options = {});

  /// Adds a sample (out-of-order samples are inserted in place); non-finite ones are rejected (false).
  bool add(double stamp, double value);

  /// The rotation of the base from `from` to `to` (from <= to): the rate integrated along its linear
  /// interpolation between samples (held beyond the ends), or the yaw at `to` minus the yaw at `from`
  /// along the samples between (so several turns between two scans count; beyond the ends the yaw goes on
  /// at the end segment's rate). False when the samples do not cover the interval: a gap longer than
  /// max_gap, or an end farther than max_gap beyond the samples.
  bool rotation(double from, double to, double* angle) const;

  /// Drops the samples before `stamp` (all but the last of them: it bounds the next interval). Callers
  /// prune behind the scans they process, not behind the newest sample: one sample stamped far in the
  /// future must not evict the rest.
  void forgetBefore(double stamp);

  void clear() { samples_.clear(); }
  bool empty() const { return samples_.empty(); }
  const GyroOptions& options() const { return options_; }

  static constexpr std::size_t kMaxSamples = 20000;  // 20 s at 1 kHz: a bound if nobody prunes

 private:
  struct Sample {
    double stamp;
    double value;
  };
  /// The value at `stamp`, linear between the samples around it (yaw along the shorter arc); beyond them
  /// the end sample's rate, or the yaw extrapolated along the end segment.
  double valueAt(double stamp) const;

  GyroOptions options_;
  std::deque<Sample> samples_;
};

}  // namespace hglasm
