// SE(2) poses: compose, inverse, interpolate; angles normalised to (-pi, pi].
#pragma once

#include <Eigen/Core>
#include <cmath>

namespace hglasm {

/// Wraps an angle into (-pi, pi]. Non-finite input is returned unchanged (callers check isFinite()).
double normalizeAngle(double angle);

/// A rigid motion in the plane: rotation by theta, then translation by (x, y).
/// `a * b` composes (b expressed in a's frame), `a * p` maps a point from the local frame into a's parent.
struct Pose2D {
  double x = 0.0;
  double y = 0.0;
  double theta = 0.0;

  Pose2D() = default;
  Pose2D(double x_in, double y_in, double theta_in) : x(x_in), y(y_in), theta(normalizeAngle(theta_in)) {}

  static Pose2D identity() { return Pose2D(); }

  Pose2D operator*(const Pose2D& other) const;
  Eigen::Vector2d operator*(const Eigen::Vector2d& point) const;
  Pose2D inverse() const;

  Eigen::Vector2d translation() const { return Eigen::Vector2d(x, y); }
  double translationNorm() const { return std::hypot(x, y); }
  bool isFinite() const { return std::isfinite(x) && std::isfinite(y) && std::isfinite(theta); }
};

/// A pose at a time (seconds).
struct StampedPose {
  double stamp = 0.0;
  Pose2D pose;
};

/// a^-1 * b: the pose of b expressed in a's frame.
Pose2D relativePose(const Pose2D& a, const Pose2D& b);

/// Linear in translation, shortest-arc in rotation. t = 0 gives a, t = 1 gives b; t outside [0, 1]
/// extrapolates.
Pose2D interpolate(const Pose2D& a, const Pose2D& b, double t);

/// Covariance of the coordinates of a * b from those of a (in a's parent frame) and of b (in a's frame),
/// to first order, a and b independent.
Eigen::Matrix3d composeCovariance(const Pose2D& a, const Eigen::Matrix3d& cov_a, const Pose2D& b,
                                  const Eigen::Matrix3d& cov_b);

/// The adjoint of `pose`: maps a covariance of a small motion expressed in `pose`'s child frame into
/// the parent frame (cov_parent = Ad * cov_child * Ad^T).
Eigen::Matrix3d adjoint(const Pose2D& pose);

}  // namespace hglasm
