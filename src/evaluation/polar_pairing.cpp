#include "hglasm_odometry/evaluation/polar_pairing.h"

#include "hglasm_odometry/core/fast_math.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace hglasm {
namespace {

constexpr double kTwoPi = 2.0 * M_PI;
// A step narrower than this (radians) would mean millions of steps: a reference of coincident angles.
constexpr double kMinStep = 1e-4;
// Reference points this close to the sensor have no meaningful polar angle.
constexpr double kMinRange = 1e-6;

}  // namespace

double medianAngularSpacing(const ReferencePoints& reference) {
  const std::vector<std::uint8_t> joined = reference.sameScanAsNext();
  std::vector<double> spacings;
  for (std::size_t i = 0; i + 1 < reference.size(); ++i) {
    if (!joined[i]) continue;
    const Eigen::Vector2d& a = reference.points[i];
    const Eigen::Vector2d& b = reference.points[i + 1];
    if (!a.allFinite() || !b.allFinite() || a.norm() < kMinRange || b.norm() < kMinRange) continue;
    const double spacing = std::abs(normalizeAngle(std::atan2(b.y(), b.x()) - std::atan2(a.y(), a.x())));
    if (spacing > 0.0) spacings.push_back(spacing);
  }
  if (spacings.empty()) return 0.0;
  const auto middle = spacings.begin() + static_cast<std::ptrdiff_t>(spacings.size() / 2);
  std::nth_element(spacings.begin(), middle, spacings.end());
  return *middle;
}

PolarPairing::PolarPairing(const PolarPairingOptions& options) : options_(options) {}

long PolarPairing::stepOf(double angle) const {
  if (!std::isfinite(angle)) return -1;
  const long count = static_cast<long>(stepCount());
  // Angle from the first reference beam, wrapped into [-step/2, 2 pi - step/2).
  double relative = angle - first_angle_;
  relative -= kTwoPi * std::floor((relative + 0.5 * step_) / kTwoPi);
  const long step = static_cast<long>(std::floor(relative / step_ + 0.5));
  return std::clamp(step, 0L, count - 1);
}

void PolarPairing::build(const ReferencePoints& reference) {
  sorted_.clear();
  step_starts_.clear();
  step_ = options_.angular_step > 0.0 ? options_.angular_step : medianAngularSpacing(reference);
  if (!(step_ >= kMinStep)) step_ = std::max(kMinStep, std::isfinite(step_) ? step_ : kMinStep);
  step_ = std::min(step_, kTwoPi);
  std::vector<std::pair<long, Eigen::Vector2f>> keyed;
  keyed.reserve(reference.size());
  bool have_first = false;
  const long count = static_cast<long>(std::ceil(kTwoPi / step_ - 1e-9));
  step_starts_.assign(static_cast<std::size_t>(count) + 1, 0);  // stepCount() needs the size
  for (const Eigen::Vector2d& point : reference.points) {
    if (!point.allFinite() || point.norm() < kMinRange) continue;
    const double angle = std::atan2(point.y(), point.x());
    if (!have_first) {
      first_angle_ = angle;
      have_first = true;
    }
    keyed.emplace_back(stepOf(angle), point.cast<float>());
  }
  if (keyed.empty()) {
    step_starts_.clear();
    return;
  }
  std::stable_sort(keyed.begin(), keyed.end(),
                   [](const auto& a, const auto& b) { return a.first < b.first; });
  sorted_.reserve(keyed.size());
  for (const auto& [step, point] : keyed) {
    sorted_.push_back(point);
    ++step_starts_[static_cast<std::size_t>(step) + 1];
  }
  for (std::size_t k = 1; k < step_starts_.size(); ++k) step_starts_[k] += step_starts_[k - 1];
}

float PolarPairing::nearestSquared(long step, float x, float y) const {
  float best = std::numeric_limits<float>::infinity();
  if (step < 0) return best;
  const std::uint32_t end = step_starts_[static_cast<std::size_t>(step) + 1];
  for (std::uint32_t i = step_starts_[static_cast<std::size_t>(step)]; i < end; ++i) {
    const float dx = x - sorted_[i].x(), dy = y - sorted_[i].y();
    best = std::min(best, dx * dx + dy * dy);
  }
  return best;
}

std::uint32_t PolarPairing::fitness(const FitnessPoints& points, const Pose2D& pose, double threshold) const {
  if (empty() || !pose.isFinite() || !(threshold > 0.0)) return 0;
  const float c = static_cast<float>(std::cos(pose.theta)), s = static_cast<float>(std::sin(pose.theta));
  const float tx = static_cast<float>(pose.x), ty = static_cast<float>(pose.y);
  const float max_squared = static_cast<float>(threshold * threshold);
  const float inverse_max = 1.0f / max_squared;
  const float first = static_cast<float>(first_angle_), half_step = static_cast<float>(0.5 * step_);
  const float inverse_step = static_cast<float>(1.0 / step_), two_pi = static_cast<float>(kTwoPi);
  const float last_step = static_cast<float>(stepCount() - 1);
  // Blocks: the projection and the angular step are branch-free and vectorise; the pairing follows.
  constexpr std::size_t kBlock = 64;
  float xs[kBlock], ys[kBlock], steps[kBlock];
  double total = 0.0;
  for (std::size_t begin = 0; begin < points.size(); begin += kBlock) {
    const std::size_t count = std::min(kBlock, points.size() - begin);
    const float* px = points.x.data() + begin;
    const float* py = points.y.data() + begin;
    for (std::size_t i = 0; i < count; ++i) {
      const float x = c * px[i] - s * py[i] + tx;
      const float y = s * px[i] + c * py[i] + ty;
      // The step of the point's angle as stepOf() computes it, in single precision.
      float relative = fastAtan2(y, x) - first;
      relative += relative < -half_step ? two_pi : 0.0f;
      relative -= relative >= two_pi - half_step ? two_pi : 0.0f;
      steps[i] = std::min(std::max(relative * inverse_step + 0.5f, 0.0f), last_step);
      xs[i] = x;
      ys[i] = y;
    }
    for (std::size_t i = 0; i < count; ++i) {
      const float squared = nearestSquared(static_cast<long>(steps[i]), xs[i], ys[i]);
      if (squared < max_squared) total += 1.0 - static_cast<double>(squared * inverse_max);
    }
  }
  const double scaled = std::round(total * kPointScore);
  return static_cast<std::uint32_t>(
      std::min(scaled, static_cast<double>(std::numeric_limits<std::uint32_t>::max())));
}

std::size_t PolarPairing::pairedCount(const FitnessPoints& points, const Pose2D& pose,
                                      double threshold) const {
  if (empty() || !pose.isFinite()) return 0;
  std::size_t paired = 0;
  const float max_squared = static_cast<float>(threshold * threshold);
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector2d moved = pose * Eigen::Vector2d(points.x[i], points.y[i]);
    const float x = static_cast<float>(moved.x()), y = static_cast<float>(moved.y());
    paired += nearestSquared(stepOf(fastAtan2(y, x)), x, y) < max_squared ? 1 : 0;
  }
  return paired;
}

FitnessStages polarPairingStages(const PolarPairing& reference, const FitnessPoints& points,
                                 double polish_step) {
  FitnessStages stages;
  const double fine = reference.options().pairing_threshold;
  const double coarse = reference.options().coarse_pairing_threshold;
  stages.fine = [&reference, &points, fine](const Pose2D& pose) {
    return reference.fitness(points, pose, fine);
  };
  if (coarse > 0.0) {
    stages.coarse = [&reference, &points, coarse](const Pose2D& pose) {
      return reference.fitness(points, pose, coarse);
    };
  }
  stages.polish_step = polish_step;
  stages.max_fitness = static_cast<double>(PolarPairing::kPointScore) * static_cast<double>(points.size());
  return stages;
}

}  // namespace hglasm
