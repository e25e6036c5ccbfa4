// PGA's fitness (Martinez et al., J. Field Robotics 23(1), 2006): the new scan is projected into the
// reference frame at the candidate pose and its points are paired with the reference points by polar
// angle (seen from the reference sensor); the fitness is built from the paired distances.
// No lookup table: preparing a reference is sorting its points into angular steps.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "hglasm_odometry/core/genetic_aligner.h"
#include "hglasm_odometry/core/lookup_table.h"
#include "hglasm_odometry/core/pose2d.h"
#include "hglasm_odometry/core/scan.h"

namespace hglasm {

struct PolarPairingOptions {
  /// Width of an angular step, radians; 0 = the reference's own beam spacing (the median angle between
  /// consecutive reference points, so invalid beams do not widen it).
  double angular_step = 0.0;
  /// Points farther apart than this are not paired (metres). The same reach as GLASM-g's table (its
  /// cells are non-zero out to 0.30 m), so both fitnesses see the same neighbourhood of the truth.
  double pairing_threshold = 0.30;
  /// Threshold of the GA's first coarse_generations generations (the role GLASM's coarse table plays):
  /// a wider basin while the population is still spread over the box. <= 0: no coarse stage.
  double coarse_pairing_threshold = 0.60;
};

/// The reference scan sorted into angular steps of the reference sensor's polar angle. Step k covers
/// [first + (k - 1/2) step, first + (k + 1/2) step), `first` the first reference point's angle, so each
/// reference beam lies in the middle of its own step; the steps go round the full circle (360-degree
/// scanners wrap at +-pi). Traversing the projected points and the reference in increasing angle and
/// pairing those in the same step is the same as looking up each projected point's step, which is what
/// fitness() does (no sort per evaluation).
class PolarPairing {
 public:
  /// Score of one point paired at distance 0; a pair at distance d scores kPointScore * (1 - d^2 / t^2).
  static constexpr std::uint32_t kPointScore = 10000;

  explicit PolarPairing(const PolarPairingOptions& options = {});

  /// Sorts `reference` (points in the reference sensor's frame) into angular steps. Non-finite points
  /// and points at the sensor's origin are ignored.
  void build(const ReferencePoints& reference);

  /// Sum over the new scan's points moved by `pose` of kPointScore * (1 - d^2 / threshold^2), d the
  /// distance to the nearest reference point of the same angular step; points with no reference point
  /// of their step within `threshold` score 0. Maximising it minimises the truncated squared error
  /// sum_i min(d_i, threshold)^2: unpaired points cost as much as the worst pair, so a pose cannot win
  /// by pushing points out of view.
  std::uint32_t fitness(const FitnessPoints& points, const Pose2D& pose, double threshold) const;

  /// Number of points of `points` moved by `pose` that find a pair within `threshold`.
  std::size_t pairedCount(const FitnessPoints& points, const Pose2D& pose, double threshold) const;

  bool empty() const { return sorted_.empty(); }
  double angularStep() const { return step_; }
  std::size_t stepCount() const { return step_starts_.empty() ? 0 : step_starts_.size() - 1; }
  const PolarPairingOptions& options() const { return options_; }

 private:
  /// Step of a polar angle; -1 when the angle is not finite.
  long stepOf(double angle) const;
  /// Squared distance from (x, y) to the nearest reference point of `step`; +inf if it has none.
  float nearestSquared(long step, float x, float y) const;

  PolarPairingOptions options_;
  double step_ = 0.0;
  double first_angle_ = 0.0;
  std::vector<std::uint32_t> step_starts_;  // step k holds sorted_[step_starts_[k], step_starts_[k + 1])
  std::vector<Eigen::Vector2f> sorted_;     // reference points sorted by step
};

/// PGA's fitness for the shared GA engine: pairing within the fine threshold, and within the coarse one
/// for the first generations (when it is > 0). `reference` and `points` must outlive the stages.
/// `polish_step`: the compass search's finest step (GLASM's uses its table's cell).
FitnessStages polarPairingStages(const PolarPairing& reference, const FitnessPoints& points,
                                 double polish_step);

/// Median angle between consecutive points of the same scan (radians, wrapped); 0 if there are none.
double medianAngularSpacing(const ReferencePoints& reference);

}  // namespace hglasm
