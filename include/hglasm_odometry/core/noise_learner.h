// Learns how noisy the two witnesses of each motion are: the wheels (their variance scales for translation
// and heading) and the scan (a variance scale per eigen-direction of its information), from the matches.
#pragma once

#include <Eigen/Core>
#include <array>
#include <string>
#include <vector>

#include "hglasm_odometry/core/motion_model.h"
#include "hglasm_odometry/core/pose2d.h"
#include "hglasm_odometry/core/scan_information.h"

namespace hglasm {

struct NoiseLearnerOptions {
  bool learn_wheels = true;  ///< learn the wheels' translation and heading scales
  /// Learn the scan information's scale too (false: as the match states it, which the wheels' noise is
  /// then learned beside). Off by default: measured on the Freiburg logs it trusts the scans more than
  /// they earn (README "Learning both noises").
  bool learn_scan = false;
  bool directional = true;        ///< one scan scale per eigen-direction (false: one for all directions)
  double half_life = 200.0;       ///< matched scans after which an old comparison counts half
  int lags = 6;                   ///< each scan is compared with this many scans before it
  double min_wheel_scale = 1e-4;  ///< bounds of the wheels' learned variance scales
  double max_wheel_scale = 100.0;
  double min_scan_scale = 0.01;  ///< bounds of the scan's learned variance scales
  double max_scan_scale = 1e4;
};

/// Its parameters and their valid ranges, for OptionReader and OptionWriter (parameter_source.h).
template <typename Visitor>
void visitOptions(Visitor& visitor, NoiseLearnerOptions* options) {
  visitor.boolean("odometry/noise/learn", &options->learn_wheels);
  visitor.positiveNumber("odometry/noise/learn_half_life", &options->half_life);
  visitor.positiveInteger("odometry/noise/learn_lags", &options->lags);
  visitor.positiveNumber("odometry/noise/min_scale", &options->min_wheel_scale);
  visitor.positiveNumber("odometry/noise/max_scale", &options->max_wheel_scale);
  visitor.boolean("scan_noise/learn", &options->learn_scan);
  visitor.boolean("scan_noise/directional", &options->directional);
  visitor.positiveNumber("scan_noise/min_scale", &options->min_scan_scale);
  visitor.positiveNumber("scan_noise/max_scale", &options->max_scan_scale);
}

/// Constraints between its parameters, checked once every layer is applied: "" if met, else one line
/// naming the parameter after `prefix` ("~").
std::string inconsistency(const NoiseLearnerOptions& options, const std::string& prefix);

/// One matched scan as the learner sees it.
struct NoiseSample {
  Pose2D scan_pose;  ///< where the scan alone put the base (odometry frame)
  /// The covariance of scan_pose that each eigen-direction of the scan's information contributes at unit
  /// scale (weakest first; odometry-frame coordinates).
  std::array<Eigen::Matrix3d, 3> scan_covariance;
  /// The wheels' motion since the previous sample (base frame there) and its covariance: the parts that
  /// scale with the wheels' translation and heading noise (unit scale) and a part that does not (an IMU's).
  Pose2D wheel_motion;
  Eigen::Matrix3d wheel_xy = Eigen::Matrix3d::Zero();
  Eigen::Matrix3d wheel_theta = Eigen::Matrix3d::Zero();
  Eigen::Matrix3d wheel_known = Eigen::Matrix3d::Zero();
};

/// Both noises at once. Comparing the motion between where two scans alone put the base with the wheels'
/// motion measures the sum of both noises; the two are told apart by how they grow with the span: the
/// wheels' error accumulates with every step, the scans' (each against the same local map) does not. So
/// each scan is compared with the last `lags` scans, and the scales are the moment fit of all those
/// innovations (each whitened by the covariance predicted so far, so each counts alike), exponentially
/// forgotten. Not thread-safe per instance.
class NoiseLearner {
 public:
  explicit NoiseLearner(const NoiseLearnerOptions& options = {});

  /// Learns from `sample` against the samples before it since the last breakChain().
  void add(const NoiseSample& sample);
  /// The next sample does not follow the last one (a leap, a failed match, a reset).
  void breakChain() { chain_.clear(); }
  /// Forgets what was learned (the scales return to 1).
  void reset();

  MotionNoiseScale wheelScale() const { return MotionNoiseScale{scales_[0], scales_[1]}; }
  ScanNoiseScale scanScale() const { return ScanNoiseScale(scales_[2], scales_[3], scales_[4]); }
  /// How many times the scan overstates its evidence overall (geometric mean of its scales).
  double scanEvidenceScale() const;
  const NoiseLearnerOptions& options() const { return options_; }

  static constexpr int kParameters = 5;  ///< wheels xy, wheels theta, scan weakest, middle, strongest
  using Vector = Eigen::Matrix<double, kParameters, 1>;
  using Matrix = Eigen::Matrix<double, kParameters, kParameters>;

 private:
  /// The innovation of the span from chain_[first] to the newest sample, and the parts of its covariance
  /// (one per parameter) and the part no parameter scales.
  void compare(std::size_t first, Eigen::Vector3d* innovation,
               std::array<Eigen::Matrix3d, kParameters>* parts, Eigen::Matrix3d* known) const;
  /// Adds the whitened moment equations of one innovation to the normal equations.
  void accumulate(const Eigen::Vector3d& innovation, const std::array<Eigen::Matrix3d, kParameters>& parts,
                  const Eigen::Matrix3d& known);
  bool learned(int parameter) const;
  void solve();

  NoiseLearnerOptions options_;
  std::vector<NoiseSample> chain_;
  Vector scales_ = Vector::Ones();
  Matrix normal_ = Matrix::Zero();  // exponentially forgotten normal equations of the moment fit
  Vector rhs_ = Vector::Zero();
  bool primed_ = false;  // the prior has been added
};

}  // namespace hglasm
