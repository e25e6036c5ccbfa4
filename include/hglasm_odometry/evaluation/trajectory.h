// Trajectories in the evaluation: wheel odometry at the scan stamps, moved to another frame or start,
// written as text (the tools' --out and --trace files) and plotted with gnuplot.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "hglasm_odometry/core/odometry_buffer.h"
#include "hglasm_odometry/core/odometry_tracker.h"
#include "hglasm_odometry/core/pose2d.h"
#include "hglasm_odometry/evaluation/relations.h"

namespace hglasm {

/// The poses of `odometry` at each of `stamps` plus `shift`, stamped with the stamp, where it has them
/// (interpolated, or at most `max_extrapolation` s beyond its samples).
std::vector<StampedPose> trajectoryAt(const OdometryBuffer& odometry, const std::vector<double>& stamps,
                                      double max_extrapolation, double shift = 0.0);

/// Each pose followed by `offset` (pose * offset): the laser's trajectory from the base's and the mount.
std::vector<StampedPose> followedBy(std::vector<StampedPose> trajectory, const Pose2D& offset);

/// A trajectory whose step between consecutive poses of `estimate` is the weighted mean of that step and
/// the step of `wheels` between the same stamps (matched within 1 ms): (1 - weight_xy) times the estimate's
/// translation plus weight_xy times the wheels', and the same for the heading with weight_theta. Steps the
/// wheels do not cover keep the estimate's. It starts at the estimate's first pose. With weights 0 it is
/// `estimate`; with weights 1 it has the wheels' motion at the estimate's stamps.
std::vector<StampedPose> blendedWithWheels(const std::vector<StampedPose>& estimate,
                                           const std::vector<StampedPose>& wheels, double weight_xy,
                                           double weight_theta);

/// `trajectory` moved rigidly so that its first pose is `start`.
std::vector<StampedPose> startedAt(std::vector<StampedPose> trajectory, const Pose2D& start);

/// 'stamp x y theta' per pose; with `increment_covariances` (one per pose) also the covariance of the
/// motion since the previous pose, in that pose's frame: 'xx xy xtheta yy ytheta thetatheta'.
bool writeTrajectory(const std::string& path, const std::vector<StampedPose>& trajectory,
                     const std::vector<Eigen::Matrix3d>* increment_covariances = nullptr);

/// One line per relation (the first line names the columns): its stamp, span, reference motion, and the
/// signed residual (estimated ⊖ reference: x, y in metres, heading in degrees) and absolute errors of
/// `laser` and of `wheels` on it; "nan" where a trajectory lacks a stamp of the relation. For finding the
/// relations one estimate loses and the other wins (awk, gnuplot), beside the metric's means.
bool writeRelationErrors(const std::string& path, const std::vector<Relation>& relations,
                         const std::vector<StampedPose>& laser, const std::vector<StampedPose>& wheels);

/// One line per scan: what the tracker decided and why (the first line names the columns).
bool writeTrackerTrace(const std::string& path, const std::vector<TrackerUpdate>& updates);

/// The gnuplot script plotting the trajectory files `laser_data` and `wheel_data` (either empty: left out)
/// into `png` with equal axes.
std::string trajectoryPlotScript(const std::string& png, const std::string& title,
                                 const std::string& laser_data, const std::string& wheel_data);

/// Plots both trajectories into `png` (gnuplot), the wheels' started at the laser's first pose. False, and
/// why in *error if given: nothing to plot, a file next to `png` that cannot be written, or gnuplot failed.
bool plotTrajectories(const std::string& png, const std::string& title, const std::vector<StampedPose>& laser,
                      const std::vector<StampedPose>& wheel, std::string* error = nullptr);

}  // namespace hglasm
