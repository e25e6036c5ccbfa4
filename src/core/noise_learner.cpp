#include "hglasm_odometry/core/noise_learner.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

#include "hglasm_odometry/core/parameter_source.h"

namespace hglasm {

std::string inconsistency(const NoiseLearnerOptions& options, const std::string& prefix) {
  const auto number = ParameterValue::ofDouble;
  if (options.max_wheel_scale < options.min_wheel_scale) {
    return constraintError(prefix, "odometry/noise/max_scale", "be at least", "odometry/noise/min_scale",
                           number(options.min_wheel_scale), number(options.max_wheel_scale));
  }
  if (options.max_scan_scale < options.min_scan_scale) {
    return constraintError(prefix, "scan_noise/max_scale", "be at least", "scan_noise/min_scale",
                           number(options.min_scan_scale), number(options.max_scan_scale));
  }
  return "";
}
namespace {

// A whitened innovation may count at most this many times what the model expects, so one bad match (a
// door swinging) does not teach the model that the wheels or the scans are bad.
constexpr double kMaxNormalisedSample = 16.0;
// The scales start at 1 as if this many scans had said so, each parameter weighed as the first scan's
// equations weigh it: a few scans must not move them far.
constexpr double kPriorScans = 20.0;

/// d relativePose(a, b) / d a and / d b, in the coordinates of a's and b's parent frame.
void relativePoseJacobians(const Pose2D& a, const Pose2D& b, Eigen::Matrix3d* d_a, Eigen::Matrix3d* d_b) {
  const double c = std::cos(a.theta), s = std::sin(a.theta);
  const Pose2D r = relativePose(a, b);
  *d_a << -c, -s, r.y, s, -c, -r.x, 0.0, 0.0, -1.0;
  *d_b << c, s, 0.0, -s, c, 0.0, 0.0, 0.0, 1.0;
}

/// W with W E W = I for a covariance E (symmetric inverse square root; tiny eigenvalues floored).
Eigen::Matrix3d whitening(const Eigen::Matrix3d& covariance) {
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(0.5 * (covariance + covariance.transpose()));
  const double floor = 1e-12 * std::max(1.0, solver.eigenvalues().cwiseAbs().maxCoeff());
  const Eigen::Vector3d inverse_root = solver.eigenvalues().cwiseMax(floor).cwiseSqrt().cwiseInverse();
  return solver.eigenvectors() * inverse_root.asDiagonal() * solver.eigenvectors().transpose();
}

}  // namespace

NoiseLearner::NoiseLearner(const NoiseLearnerOptions& options) : options_(options) {}

void NoiseLearner::reset() {
  chain_.clear();
  scales_.setOnes();
  normal_.setZero();
  rhs_.setZero();
  primed_ = false;
}

double NoiseLearner::scanEvidenceScale() const { return std::cbrt(scales_[2] * scales_[3] * scales_[4]); }

bool NoiseLearner::learned(int parameter) const {
  if (parameter < 2) return options_.learn_wheels;
  return options_.learn_scan && (parameter == 2 || options_.directional);
}

void NoiseLearner::compare(std::size_t first, Eigen::Vector3d* innovation,
                           std::array<Eigen::Matrix3d, kParameters>* parts, Eigen::Matrix3d* known) const {
  // The wheels' motion over the span and its covariance, composed step by step (each part on its own: the
  // composition is linear in the covariances).
  Pose2D wheels;
  Eigen::Matrix3d wheel_xy = Eigen::Matrix3d::Zero(), wheel_theta = Eigen::Matrix3d::Zero();
  *known = Eigen::Matrix3d::Zero();
  for (std::size_t i = first + 1; i < chain_.size(); ++i) {
    const NoiseSample& step = chain_[i];
    wheel_xy = composeCovariance(wheels, wheel_xy, step.wheel_motion, step.wheel_xy);
    wheel_theta = composeCovariance(wheels, wheel_theta, step.wheel_motion, step.wheel_theta);
    *known = composeCovariance(wheels, *known, step.wheel_motion, step.wheel_known);
    wheels = wheels * step.wheel_motion;
  }
  const NoiseSample& from = chain_[first];
  const NoiseSample& to = chain_.back();
  const Pose2D scans = relativePose(from.scan_pose, to.scan_pose);
  *innovation =
      Eigen::Vector3d(scans.x - wheels.x, scans.y - wheels.y, normalizeAngle(scans.theta - wheels.theta));
  Eigen::Matrix3d d_from, d_to;
  relativePoseJacobians(from.scan_pose, to.scan_pose, &d_from, &d_to);
  (*parts)[0] = wheel_xy;
  (*parts)[1] = wheel_theta;
  for (int j = 0; j < 3; ++j) {
    (*parts)[2 + j] = d_from * from.scan_covariance[j] * d_from.transpose() +
                      d_to * to.scan_covariance[j] * d_to.transpose();
  }
  if (!options_.directional) {
    (*parts)[2] += (*parts)[3] + (*parts)[4];
    (*parts)[3].setZero();
    (*parts)[4].setZero();
  }
  // What is not learned is known: it counts at its fixed scale.
  for (int p = 0; p < kParameters; ++p) {
    if (!learned(p)) {
      *known += scales_[p] * (*parts)[p];
      (*parts)[p].setZero();
    }
  }
}

void NoiseLearner::accumulate(const Eigen::Vector3d& innovation,
                              const std::array<Eigen::Matrix3d, kParameters>& parts,
                              const Eigen::Matrix3d& known) {
  // Whitened by the covariance expected so far, each of the three equations has unit expectation at the
  // right scales and the same spread (method of moments, iteratively reweighted).
  Eigen::Matrix3d expected = known;
  for (int p = 0; p < kParameters; ++p) expected += scales_[p] * parts[p];
  const Eigen::Matrix3d w = whitening(expected);
  const Eigen::Vector3d z = w * innovation;
  const Eigen::Matrix3d known_white = w * known * w;
  std::array<Eigen::Matrix3d, kParameters> parts_white;
  for (int p = 0; p < kParameters; ++p) parts_white[p] = w * parts[p] * w;
  for (int i = 0; i < 3; ++i) {
    Vector regressors;
    for (int p = 0; p < kParameters; ++p) regressors[p] = parts_white[p](i, i);
    const double observed = std::min(z[i] * z[i], kMaxNormalisedSample);
    normal_ += regressors * regressors.transpose();
    rhs_ += regressors * (observed - known_white(i, i));
  }
}

void NoiseLearner::add(const NoiseSample& sample) {
  // A vector, not a deque: its memory is reused once the window is full (samples are a few hundred bytes).
  const std::size_t window = static_cast<std::size_t>(std::max(1, options_.lags)) + 1;
  if (chain_.size() >= window)
    chain_.erase(chain_.begin(), chain_.end() - static_cast<std::ptrdiff_t>(window - 1));
  chain_.push_back(sample);
  if (chain_.size() < 2 || !(options_.learn_wheels || options_.learn_scan)) return;
  const double forget = std::exp2(-1.0 / std::max(1.0, options_.half_life));
  normal_ *= forget;
  rhs_ *= forget;
  const Matrix before = normal_;
  for (std::size_t first = 0; first + 1 < chain_.size(); ++first) {
    Eigen::Vector3d innovation;
    std::array<Eigen::Matrix3d, kParameters> parts;
    Eigen::Matrix3d known;
    compare(first, &innovation, &parts, &known);
    if (innovation.allFinite()) accumulate(innovation, parts, known);
  }
  if (!primed_ && normal_ != before) {
    const Vector weight = kPriorScans * (normal_ - before).diagonal().cwiseMax(1e-12);
    normal_ += weight.asDiagonal();
    rhs_ += weight.cwiseProduct(scales_);
    primed_ = true;
  }
  solve();
}

void NoiseLearner::solve() {
  // Bounded least squares by projected Gauss-Seidel (the normal matrix is positive definite: the prior and
  // a whisker of damping towards the current scales keep parameters nothing has measured where they are).
  const double damping = 1e-6 * normal_.diagonal().maxCoeff() + 1e-12;
  const Vector previous = scales_;
  for (int sweep = 0; sweep < 100; ++sweep) {
    double change = 0.0;
    for (int p = 0; p < kParameters; ++p) {
      if (!learned(p)) continue;
      const double low = p < 2 ? options_.min_wheel_scale : options_.min_scan_scale;
      const double high = p < 2 ? options_.max_wheel_scale : options_.max_scan_scale;
      const double residual =
          rhs_[p] + damping * previous[p] - normal_.row(p).dot(scales_) + normal_(p, p) * scales_[p];
      const double value = std::clamp(residual / (normal_(p, p) + damping), low, high);
      change = std::max(change, std::abs(value - scales_[p]) / std::max(scales_[p], 1e-12));
      scales_[p] = value;
    }
    if (change < 1e-6) break;
  }
  if (!options_.directional) scales_[3] = scales_[4] = scales_[2];
}

}  // namespace hglasm
