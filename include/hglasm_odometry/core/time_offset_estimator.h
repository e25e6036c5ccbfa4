// The time offset between the wheel odometry and the scans, learned from the matches. Some robots publish
// their wheels' pose late (a motor controller's own cycle, a driver that stamps on arrival): the pose
// stamped t + offset is the robot's at the scans' t, and a prediction read at t is wrong by the motion of
// `offset` seconds, which the noise model would learn as noise.
//
// Every window of about kWindow seconds between two matched scans (where the scans alone put the base) is
// compared with the wheels' motion over the same window shifted by each candidate offset: its heading
// change, with the wheels' scale fitted away (wheels that over-count turns by a few percent do so at every
// offset). Heading only: scans know it precisely anywhere, while the distance travelled is what a corridor
// leaves them unsure of. The candidate with the smallest squared residual wins once its evidence against
// the offset in use is strong: a likelihood ratio of kEvidenceSigmas^2 / 2 in log. Only where the wheels
// are sampled finely (kMaxSampleGap) can their timing be measured at all. An offset under
// kMinOffset is taken as none: the wheels' sampling alone shifts the estimate by as much (samples only at the
// scans' stamps, bursts of samples a millisecond apart that hold other instants), reading the wheels off
// their samples then costs more than it gains, and waiting for late wheels costs latency.
#pragma once

#include <deque>
#include <vector>

#include "hglasm_odometry/core/odometry_buffer.h"
#include "hglasm_odometry/core/pose2d.h"

namespace hglasm {

struct TimeOffsetOptions {
  bool estimate = true;     ///< learn the offset from the matches; false: `offset` is fixed
  double offset = 0.0;      ///< seconds the wheels' stamps run late: the start, or the fixed value
  double max_offset = 1.0;  ///< seconds: the candidates span [-max_offset, max_offset]
};

/// Seconds: the largest offset that may be set by hand (a larger one is a misconfigured clock).
constexpr double kMaxFixedTimeOffset = 10.0;

/// Its parameters and their valid ranges, for OptionReader and OptionWriter (parameter_source.h).
template <typename Visitor>
void visitOptions(Visitor& visitor, TimeOffsetOptions* options) {
  bool automatic = options->estimate;
  visitor.autoOrNumber("odometry/time_offset", &automatic, &options->offset, kMaxFixedTimeOffset, "seconds");
  options->estimate = automatic;
  visitor.number("odometry/max_time_offset", &options->max_offset, 0.0, kMaxFixedTimeOffset);
}

/// Not thread-safe per instance.
class TimeOffsetEstimator {
 public:
  explicit TimeOffsetEstimator(const TimeOffsetOptions& options = {});

  /// Where a matched scan alone put the base (odometry frame) at `stamp`. Scans arrive in stamp order; a
  /// gap longer than kMaxWindow starts the next window afresh.
  void addScanPose(double stamp, const Pose2D& pose);

  /// Scores the windows `wheels` now cover at every candidate (their end plus max_offset); true when the
  /// offset in use changed.
  bool update(const OdometryBuffer& wheels);

  /// Seconds to add to a scan's stamp to read the wheels' pose of the same instant.
  double offset() const { return offset_; }
  /// The best candidate so far (refined between grid points); the offset in use until a window is scored.
  double estimate() const { return estimate_; }
  /// Windows scored (with the forgetting of kHalfLife windows, their weight).
  double windows() const { return weight_; }
  bool estimating() const { return options_.estimate; }
  const TimeOffsetOptions& options() const { return options_; }

  static constexpr double kStep = 0.01;       // seconds between candidates
  static constexpr double kWindow = 1.0;      // seconds a window spans at least
  static constexpr double kMaxWindow = 3.0;   // seconds: longer spans (a pause, failed matches) are skipped
  static constexpr double kHalfLife = 600.0;  // windows after which an old one counts half
  static constexpr double kMinWindows = 5.0;  // before any change of the offset in use
  static constexpr double kEvidenceSigmas = 4.0;
  static constexpr double kMinOffset = 0.05;  // seconds
  /// Seconds: windows where the wheels' samples lie farther apart than this (at any candidate) are not
  /// scored; reading them between their samples would measure the interpolation, not their timing.
  static constexpr double kMaxSampleGap = 0.25;
  /// rad/s: wheels turning faster between two samples jumped (a base does not spin a turn per second).
  static constexpr double kMaxWheelTurnRate = 2.0 * 3.14159265358979323846;

 private:
  struct Window {
    double from = 0.0, to = 0.0;
    double turn = 0.0;  // of the base, where the scans put it
  };
  /// Least-squares sums of one residual component at one candidate: the scans' value s, the wheels' w.
  struct Sums {
    double ss = 0.0, sw = 0.0, ww = 0.0;
    /// Squared residual with the wheels' scale fitted: min over u of sum (s - u w)^2.
    double cost() const { return ww > 0.0 ? ss - sw * sw / ww : ss; }
  };
  void score(const Window& window, const OdometryBuffer& wheels);
  double cost(std::size_t candidate) const;
  std::size_t nearest(double offset) const;  ///< the candidate closest to `offset`
  double candidateOffset(std::size_t candidate) const;
  /// The best candidate (refined by a parabola through its neighbours) and its cost; false if none.
  bool best(double* offset, double* cost) const;
  bool decide();

  TimeOffsetOptions options_;
  double offset_;
  double estimate_;
  std::vector<Sums> heading_;  // per candidate
  double weight_ = 0.0;
  bool have_start_ = false;
  StampedPose start_;  // where the next window begins
  std::deque<Window> pending_;
};

}  // namespace hglasm
