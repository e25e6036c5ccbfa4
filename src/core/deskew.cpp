#include "hglasm_odometry/core/deskew.h"

#include <algorithm>
#include <array>
#include <cmath>

namespace hglasm {

Eigen::Vector3d laserVelocity(const Pose2D& mount, const Eigen::Vector3d& base_velocity) {
  const double omega = base_velocity.z();
  const Eigen::Vector2d at_laser(base_velocity.x() - omega * mount.y, base_velocity.y() + omega * mount.x);
  const double c = std::cos(mount.theta), s = std::sin(mount.theta);
  return Eigen::Vector3d(c * at_laser.x() + s * at_laser.y(), -s * at_laser.x() + c * at_laser.y(), omega);
}

bool deskewSweep(const Scan& scan, double stamp, const Pose2D& mount, const SweepMotion& motion,
                 Scan* compensated) {
  if (!scan.hasBeamTimes()) return false;
  const Eigen::Vector3d velocity = motion.base_velocity.value_or(Eigen::Vector3d::Zero());
  const double sweep = (scan.beam_count - 1) * scan.time_increment;
  std::array<double, kDeskewKnots + 1> turned{};
  bool measured = motion.base_rotation && scan.beam_count > 1;
  for (int k = 1; measured && k <= kDeskewKnots; ++k) {
    const double t = sweep * k / kDeskewKnots;
    double angle = 0.0;
    measured = t >= 0.0 ? motion.base_rotation(stamp, stamp + t, &angle)
                        : motion.base_rotation(stamp + t, stamp, &angle);
    turned[k] = t >= 0.0 ? angle : -angle;
  }
  if (!measured) {
    if (!motion.base_velocity) return false;
    *compensated = deskewScan(scan, laserVelocity(mount, velocity));
    return true;
  }
  *compensated = deskewScan(scan, [&](double t) {
    const double knot = std::clamp(t / sweep * kDeskewKnots, 0.0, static_cast<double>(kDeskewKnots));
    const int below = std::min(static_cast<int>(knot), kDeskewKnots - 1);
    const double angle = turned[below] + (knot - below) * (turned[below + 1] - turned[below]);
    return mount.inverse() * Pose2D(velocity.x() * t, velocity.y() * t, angle) * mount;
  });
  return true;
}

}  // namespace hglasm
