// Motion compensation of a scan taken from a moving base, beside scan.h: a sweep taken while moving is
// sheared (the last beam is milliseconds younger than the first), and a match reads the shear as a small
// turn of one sign per metre.
#pragma once

#include <Eigen/Core>
#include <functional>
#include <optional>

#include "hglasm_odometry/core/pose2d.h"
#include "hglasm_odometry/core/scan.h"

namespace hglasm {

/// The laser's velocity (vx, vy, omega in the laser frame) from the base's (base frame): the lever arm of
/// the mount adds omega x t to the translation.
Eigen::Vector3d laserVelocity(const Pose2D& mount, const Eigen::Vector3d& base_velocity);

/// What is known of the base's motion during a sweep.
struct SweepMotion {
  /// vx, vy, wz of the base in its frame; none: not known.
  std::optional<Eigen::Vector3d> base_velocity;
  /// The base's rotation (rad) from `from` to `to` (seconds, from <= to), as an IMU measured it; false (or
  /// empty) where that is not known.
  std::function<bool(double from, double to, double* angle)> base_rotation;
};

/// The base's rotation during a sweep is sampled this often (then linear in between).
constexpr int kDeskewKnots = 16;

/// `scan` (stamped `stamp`, taken by a laser at `mount` on the base) with every point moved to where the
/// laser saw it at the stamp. The turn comes from motion.base_rotation when it covers the sweep (a turn
/// rate that changes within it, as when a spin starts) and the translation from the velocity (none if it
/// is not known); else both from the velocity. False, *compensated untouched: the beams' times or the
/// motion are not known.
bool deskewSweep(const Scan& scan, double stamp, const Pose2D& mount, const SweepMotion& motion,
                 Scan* compensated);

}  // namespace hglasm
