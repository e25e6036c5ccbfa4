#include "hglasm_odometry/evaluation/trajectory.h"

#include <cmath>
#include <cstdio>
#include <fstream>

#include "hglasm_odometry/evaluation/gnuplot.h"
#include "hglasm_odometry/evaluation/relations.h"

namespace hglasm {

std::vector<StampedPose> trajectoryAt(const OdometryBuffer& odometry, const std::vector<double>& stamps,
                                      double max_extrapolation, double shift) {
  std::vector<StampedPose> trajectory;
  for (double stamp : stamps) {
    StampedPose pose;
    pose.stamp = stamp;
    if (odometry.poseAt(stamp + shift, max_extrapolation, &pose.pose)) trajectory.push_back(pose);
  }
  return trajectory;
}

std::vector<StampedPose> followedBy(std::vector<StampedPose> trajectory, const Pose2D& offset) {
  for (auto& stamped : trajectory) stamped.pose = stamped.pose * offset;
  return trajectory;
}

std::vector<StampedPose> blendedWithWheels(const std::vector<StampedPose>& estimate,
                                           const std::vector<StampedPose>& wheels, double weight_xy,
                                           double weight_theta) {
  constexpr double kStampTolerance = 1e-3;  // as the relations match their stamps
  std::vector<StampedPose> blended;
  if (estimate.empty()) return blended;
  blended.reserve(estimate.size());
  blended.push_back(estimate.front());
  long wheel_before = findStamp(wheels, estimate.front().stamp, kStampTolerance);
  for (std::size_t i = 1; i < estimate.size(); ++i) {
    const long wheel_after = findStamp(wheels, estimate[i].stamp, kStampTolerance);
    Pose2D step = relativePose(estimate[i - 1].pose, estimate[i].pose);
    if (wheel_before >= 0 && wheel_after >= 0) {
      const Pose2D wheel_step = relativePose(wheels[wheel_before].pose, wheels[wheel_after].pose);
      step = Pose2D((1.0 - weight_xy) * step.x + weight_xy * wheel_step.x,
                    (1.0 - weight_xy) * step.y + weight_xy * wheel_step.y,
                    (1.0 - weight_theta) * step.theta + weight_theta * wheel_step.theta);
    }
    blended.push_back({estimate[i].stamp, blended.back().pose * step});
    wheel_before = wheel_after;
  }
  return blended;
}

std::vector<StampedPose> startedAt(std::vector<StampedPose> trajectory, const Pose2D& start) {
  if (trajectory.empty()) return trajectory;
  const Pose2D move = start * trajectory.front().pose.inverse();
  for (auto& stamped : trajectory) stamped.pose = move * stamped.pose;
  return trajectory;
}

bool writeTrajectory(const std::string& path, const std::vector<StampedPose>& trajectory,
                     const std::vector<Eigen::Matrix3d>* increment_covariances) {
  std::FILE* file = std::fopen(path.c_str(), "w");
  if (!file) return false;
  for (std::size_t i = 0; i < trajectory.size(); ++i) {
    const StampedPose& pose = trajectory[i];
    std::fprintf(file, "%.6f %.6f %.6f %.6f", pose.stamp, pose.pose.x, pose.pose.y, pose.pose.theta);
    if (increment_covariances && i < increment_covariances->size()) {
      const Eigen::Matrix3d& c = (*increment_covariances)[i];
      std::fprintf(file, " %.6g %.6g %.6g %.6g %.6g %.6g", c(0, 0), c(0, 1), c(0, 2), c(1, 1), c(1, 2),
                   c(2, 2));
    }
    std::fprintf(file, "\n");
  }
  return std::fclose(file) == 0;
}

namespace {

/// Each relation's error under `trajectory`, or none where it lacks one of the relation's stamps.
std::vector<const RelationError*> errorsByRelation(const std::vector<RelationError>& errors,
                                                   std::size_t relation_count) {
  std::vector<const RelationError*> by_relation(relation_count, nullptr);
  for (const RelationError& error : errors) by_relation[error.index] = &error;
  return by_relation;
}

void printRelationError(std::FILE* file, const RelationError* error) {
  if (!error) {
    std::fprintf(file, " nan nan nan nan nan");
    return;
  }
  std::fprintf(file, " %.5f %.5f %.4f %.5f %.4f", error->residual.x, error->residual.y,
               normalizeAngle(error->residual.theta) * kRadToDeg, error->trans(), error->rotDeg());
}

}  // namespace

bool writeRelationErrors(const std::string& path, const std::vector<Relation>& relations,
                         const std::vector<StampedPose>& laser, const std::vector<StampedPose>& wheels) {
  std::FILE* file = std::fopen(path.c_str(), "w");
  if (!file) return false;
  std::fprintf(file,
               "# t1 span reference_x reference_y reference_theta_deg laser_dx laser_dy laser_dtheta_deg "
               "laser_m laser_deg wheel_dx wheel_dy wheel_dtheta_deg wheel_m wheel_deg\n");
  constexpr double kAllSpans = 0.0;
  const std::vector<RelationError> laser_errors = relationErrors(relations, laser, kAllSpans);
  const std::vector<RelationError> wheel_errors = relationErrors(relations, wheels, kAllSpans);
  const auto laser_by_relation = errorsByRelation(laser_errors, relations.size());
  const auto wheel_by_relation = errorsByRelation(wheel_errors, relations.size());
  for (std::size_t k = 0; k < relations.size(); ++k) {
    const Relation& relation = relations[k];
    std::fprintf(file, "%.6f %.3f %.5f %.5f %.4f", relation.t1, relation.t2 - relation.t1, relation.motion.x,
                 relation.motion.y, normalizeAngle(relation.motion.theta) * kRadToDeg);
    printRelationError(file, laser_by_relation[k]);
    printRelationError(file, wheel_by_relation[k]);
    std::fprintf(file, "\n");
  }
  return std::fclose(file) == 0;
}

bool writeTrackerTrace(const std::string& path, const std::vector<TrackerUpdate>& updates) {
  std::FILE* file = std::fopen(path.c_str(), "w");
  if (!file) return false;
  std::fprintf(
      file,
      "# stamp x y theta prediction matched fallback doubted leap rejected keyframe map_keyframes "
      "box_x box_y box_theta population mahalanobis fitness status mbicp_iterations noise_xy "
      "noise_theta guess_x guess_y guess_theta leap_probability vx vy wz time_offset scan_noise_weakest "
      "scan_noise_middle scan_noise_strongest degeneracy weakest_x weakest_y weakest_theta turn_scale "
      "laser_offset_x laser_offset_y prior_weight\n");
  for (const auto& u : updates) {
    const TrackerDiagnostics& d = u.diagnostics;
    std::fprintf(
        file,
        "%.6f %.4f %.4f %.5f %s %d %d %d %d %d %d %d %.3f %.3f %.3f %d %.2f %.3f %s %d %.3g %.3g "
        "%.4f %.4f %.5f %.3g %.4f %.4f %.4f %.3f %.3g %.3g %.3g %.3g %.3f %.3f %.3f %.5f %.4f %.4f %.3g\n",
        u.stamp, u.pose.x, u.pose.y, u.pose.theta, toString(d.prediction), u.matched, u.fallback,
        d.prediction_doubted, u.leap, d.jump_rejected, u.new_keyframe, d.map_keyframes, d.search.box.half_x,
        d.search.box.half_y, d.search.box.half_theta, d.search.population, d.prior_mahalanobis,
        d.fitness_ratio, toString(d.match.status), d.match.iterations, d.learned.wheel_noise.xy,
        d.learned.wheel_noise.theta, d.guess.x, d.guess.y, d.guess.theta, d.leap_probability, u.velocity.x(),
        u.velocity.y(), u.velocity.z(), d.odometry_time_offset, d.learned.scan_noise[0],
        d.learned.scan_noise[1], d.learned.scan_noise[2], d.degeneracy, d.weakest_direction.x(),
        d.weakest_direction.y(), d.weakest_direction.z(), d.learned.wheel_turn_scale,
        d.learned.laser_offset.x(), d.learned.laser_offset.y(), d.prior_weight);
  }
  return std::fclose(file) == 0;
}

std::string trajectoryPlotScript(const std::string& png, const std::string& title,
                                 const std::string& laser_data, const std::string& wheel_data) {
  std::string script = "set terminal pngcairo size 1200,1000 font ',10'\nset output " + gnuplotQuote(png) +
                       "\nset title " + gnuplotQuote(title) +
                       " noenhanced\nset size ratio -1\nset grid\nset key top left box opaque Left\n"
                       "set xlabel 'x (m)'\nset ylabel 'y (m)'\nplot ";
  if (!wheel_data.empty()) {
    script += gnuplotQuote(wheel_data) + " using 2:3 with lines lw 1 lc rgb '#d62728' title 'wheel odometry'";
  }
  if (!laser_data.empty()) {
    script += std::string(wheel_data.empty() ? "" : ", ") + gnuplotQuote(laser_data) +
              " using 2:3 with lines lw 1 lc rgb '#1f77b4' title 'laser odometry', " +
              gnuplotQuote(laser_data) +
              " every ::0::0 using 2:3 with points pt 7 ps 1.5 lc rgb 'black' title 'start'";
  }
  return script + "\n";
}

bool plotTrajectories(const std::string& png, const std::string& title, const std::vector<StampedPose>& laser,
                      const std::vector<StampedPose>& wheel, std::string* error) {
  if (laser.empty() && wheel.empty()) {
    if (error) *error = "no trajectory to plot into " + png;
    return false;
  }
  const std::string laser_data = png + ".laser.txt", wheel_data = png + ".wheel.txt",
                    script = png + ".gnuplot";
  const std::vector<StampedPose> aligned_wheel = laser.empty() ? wheel : startedAt(wheel, laser.front().pose);
  std::string unwritten;  // the first file that could not be written
  if (!writeTrajectory(laser_data, laser)) {
    unwritten = laser_data;
  } else if (!writeTrajectory(wheel_data, aligned_wheel)) {
    unwritten = wheel_data;
  } else {
    std::ofstream out(script);
    out << trajectoryPlotScript(png, title, laser.empty() ? "" : laser_data, wheel.empty() ? "" : wheel_data);
    out.close();
    if (out.fail()) unwritten = script;
  }
  const bool plotted = unwritten.empty() && runGnuplot(script);
  for (const std::string& file : {script, laser_data, wheel_data}) std::remove(file.c_str());
  if (!plotted && error) {
    *error = unwritten.empty() ? "gnuplot failed for " + png : "cannot write " + unwritten;
  }
  return plotted;
}

}  // namespace hglasm
