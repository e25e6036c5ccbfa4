#include "hglasm_odometry/core/pose2d.h"

namespace hglasm {

double normalizeAngle(double angle) {
  if (!std::isfinite(angle)) return angle;
  if (angle > -M_PI && angle <= M_PI) return angle;
  double wrapped = std::fmod(angle + M_PI, 2.0 * M_PI);  // (-2pi, 2pi)
  if (wrapped <= 0.0) wrapped += 2.0 * M_PI;             // (0, 2pi]
  return wrapped - M_PI;
}

Pose2D Pose2D::operator*(const Pose2D& other) const {
  const double c = std::cos(theta), s = std::sin(theta);
  return Pose2D(x + c * other.x - s * other.y, y + s * other.x + c * other.y, theta + other.theta);
}

Eigen::Vector2d Pose2D::operator*(const Eigen::Vector2d& point) const {
  const double c = std::cos(theta), s = std::sin(theta);
  return Eigen::Vector2d(x + c * point.x() - s * point.y(), y + s * point.x() + c * point.y());
}

Pose2D Pose2D::inverse() const {
  const double c = std::cos(theta), s = std::sin(theta);
  return Pose2D(-c * x - s * y, s * x - c * y, -theta);
}

Pose2D relativePose(const Pose2D& a, const Pose2D& b) { return a.inverse() * b; }

Pose2D interpolate(const Pose2D& a, const Pose2D& b, double t) {
  const double dtheta = normalizeAngle(b.theta - a.theta);
  return Pose2D(a.x + t * (b.x - a.x), a.y + t * (b.y - a.y), a.theta + t * dtheta);
}

Eigen::Matrix3d adjoint(const Pose2D& pose) {
  const double c = std::cos(pose.theta), s = std::sin(pose.theta);
  Eigen::Matrix3d ad;
  ad << c, -s, pose.y,  //
      s, c, -pose.x,    //
      0, 0, 1;
  return ad;
}

Eigen::Matrix3d composeCovariance(const Pose2D& a, const Eigen::Matrix3d& cov_a, const Pose2D& b,
                                  const Eigen::Matrix3d& cov_b) {
  const Pose2D ab = a * b;
  Eigen::Matrix3d j_a = Eigen::Matrix3d::Identity();
  j_a(0, 2) = -(ab.y - a.y);
  j_a(1, 2) = ab.x - a.x;
  Eigen::Matrix3d j_b = Eigen::Matrix3d::Identity();
  const double c = std::cos(a.theta), s = std::sin(a.theta);
  j_b.topLeftCorner<2, 2>() << c, -s, s, c;
  const Eigen::Matrix3d covariance = j_a * cov_a * j_a.transpose() + j_b * cov_b * j_b.transpose();
  return 0.5 * (covariance + covariance.transpose());
}

}  // namespace hglasm
