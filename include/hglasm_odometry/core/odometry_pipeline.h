// One laser-odometry pipeline for the live node and the offline tools: scan conversion (mirrored for an
// upside-down laser), the scanner-geometry check, the wheel-odometry feeding policy, the tracker, and the
// guess as the matcher saw it. Callers only add transport (ROS messages, bags), timing and output.
#pragma once

#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "hglasm_odometry/core/awaited_stamps.h"
#include "hglasm_odometry/core/odometry_tracker.h"
#include "hglasm_odometry/core/pose2d.h"
#include "hglasm_odometry/core/scan.h"
#include "hglasm_odometry/core/stamp_order.h"

namespace hglasm {

/// The scan conversion for a laser mount: an upside-down laser's scans are mirrored. The mount decides,
/// whatever `conversion.mirror` said before.
ScanConversionOptions conversionForMount(ScanConversionOptions conversion, bool upside_down);

/// What the pipeline did with one scan.
struct PipelineUpdate {
  TrackerUpdate tracker;
  /// The converted scan in the laser frame, before de-skewing (size() valid points, invalid_count).
  Scan scan;
  ScanError scan_error = ScanError::kNone;
  /// scan_error differs from the previous scan's (the first scan counts as following a valid one): log
  /// once per change of state, not per scan.
  bool scan_error_changed = false;
  /// The scan's stamp lay more than reset_on_jump_back behind the last one's: a new timeline, the odometry
  /// restarted from the origin (tracker.reset, tracker.warning says so).
  bool jumped_back = false;
  /// Set when a match was attempted: the predicted pose of the new laser in the keyframe's laser frame,
  /// the guess the search was centred on.
  std::optional<Pose2D> laser_guess;
  /// use_imu, and no IMU samples covered the step to this scan (stale or missing): the wheels (or the
  /// velocity) predicted the rotation. Scans that start the odometry keep the previous scan's state.
  bool imu_stale = false;
  /// imu_stale differs from the previous scan's (at first: not stale): log once per change of state.
  bool imu_stale_changed = false;
  double conversion_cpu_ms = 0.0;  ///< CPU time of the scan conversion (calling thread)
};

/// What became of one wheel-odometry or IMU sample (the time policy below).
enum class SampleVerdict { kTaken, kInvalid, kStale, kNewTimeline };
const char* toString(SampleVerdict verdict);

/// Samples and scans the time policy dropped, and the clock jumps it restarted on, since construction.
struct InputCounts {
  std::uint64_t stale_scans = 0;
  std::uint64_t stale_odometry = 0;
  std::uint64_t stale_imu = 0;
  std::uint64_t jumps_back = 0;  ///< of the scans' clock: the odometry restarted
};

/// Not thread-safe per instance (callers with several threads guard it with one mutex); instances share
/// nothing.
///
/// Time policy (one per input stream: scans, wheel odometry, IMU; StampOrder): a message stamped before the
/// newest one of its stream is dropped (a driver's jitter, a reordered bag; counted, and a stale scan is
/// reported in its update), never a reset. One stamped more than reset_on_jump_back behind is a clock that
/// went back (a looped bag, a restarted clock): for scans the odometry restarts from the origin with a
/// warning, and samples of the other streams still on the old timeline are forgotten; a wheel or IMU
/// sample starts its stream's new timeline. A forward gap of any length continues from the current pose,
/// predicted by the wheels when their samples cover it.
///
/// Wheel-odometry feeding policy (both the live node and offline replays obey it, so the tracker sees
/// the same samples around every scan): a scan stamped t is processed once inputsReadyFor(t), i.e.
/// once a sample stamped at or after t + the wheels' time offset has been added, so the prediction at t
/// is interpolated between the two samples around it, never extrapolated, even across a gap in the data.
/// It is not waited for when odometry is off, when none has been added yet, or while odometry is stalled:
/// a live node bounds each wait in wall time (odometry/wait) and reports a wait that timed out
/// (inputsWaitTimedOut()); scans then go on without waiting until a sample arrives that the last scan
/// processed would have waited for. Samples added beyond the first one at or after t change nothing:
/// interpolation only uses the two around t. With use_imu the IMU's samples are waited for the same way,
/// and stall on their own.
class OdometryPipeline {
 public:
  /// `wait_for_odometry` false: scans never wait for odometry (a live node with odometry/wait 0).
  explicit OdometryPipeline(const TrackerOptions& options = {}, bool wait_for_odometry = true);

  /// base -> laser (after mirroring) and whether the laser is upside down (its scans are then mirrored).
  /// A non-finite mount is ignored (false).
  bool setLaserMount(const Pose2D& base_to_laser, bool upside_down);

  /// Wheel odometry: pose of the base in the wheel-odometry frame at `stamp` (time policy above).
  /// Non-finite samples are kInvalid.
  SampleVerdict addOdometry(double stamp, const Pose2D& pose);

  /// IMU: the base's yaw rate (rad/s), or its yaw (rad) with imu.use_orientation, at `stamp` (time policy
  /// above); kInvalid without use_imu or for non-finite values.
  SampleVerdict addImu(double stamp, double value);

  /// Stamp of the newest odometry sample added; -infinity before the first.
  double newestOdometryStamp() const { return wheels_.order.newest(); }
  /// Seconds the wheels' stamps run late against the scans' (learned, or odometry/time_offset).
  double odometryTimeOffset() const { return tracker_.odometryTimeOffset(); }
  InputCounts inputCounts() const;

  /// The feeding policy (see the class comment): true once a scan stamped `stamp` may be processed (the
  /// wheels are waited for to `stamp` plus their time offset). The IMU is waited for to the end of the
  /// scan's sweep (`sweep` seconds after the stamp; scanSweepTime): de-skewing takes its turn during the
  /// sweep. A scan the time policy will drop waits for nothing.
  bool inputsReadyFor(double stamp, double sweep = 0.0) const { return awaitedFor(stamp, sweep).nothing(); }

  /// The stamps the wheels and the IMU must reach (a sample stamped at or after them) before a scan at
  /// `stamp` may be processed; +infinity where that input is not waited for (nothing, once it is ready).
  /// What a live wait wakes for.
  AwaitedStamps awaitedFor(double stamp, double sweep = 0.0) const;

  /// A live wait for a scan at `stamp` timed out: the wheel odometry, the IMU or both (whichever had no
  /// sample at or after it) count as stalled until a sample of theirs arrives that the newest scan
  /// processed waited for: one that lags by more than the wait is not waited for at every scan.
  void inputsWaitTimedOut(double stamp, double sweep = 0.0);
  bool odometryStalled() const { return wheels_.stalled; }
  bool imuStalled() const { return imu_.stalled; }

  /// Offline replay of recorded odometry, under the feeding policy: adds the samples [next, end) (sorted
  /// by stamp; each with .stamp and .pose) that a live node holds when it processes a scan at `stamp`:
  /// every sample stamped at or before it, then later ones until inputsReadyFor(stamp). Returns the
  /// first sample not added. Adds nothing when odometry is off. Assumes no live wait timed out; and a
  /// sample stamped exactly at `stamp` may round an ulp differently from a live buffer that already holds a
  /// later one (OdometryBuffer extrapolates by 0 s there instead of interpolating).
  template <typename Iterator>
  Iterator addRecordedOdometry(Iterator next, Iterator end, double stamp) {
    if (!tracker_.options().prediction.use_odometry) return end;
    const double wheel_stamp = stamp + odometryTimeOffset();
    for (; next != end && next->stamp <= wheel_stamp; ++next) addOdometry(next->stamp, next->pose);
    for (; next != end && !inputsReadyFor(stamp); ++next) addOdometry(next->stamp, next->pose);
    return next;
  }

  /// Converts and processes one scan taken at `stamp` (seconds), under the time policy (a stale scan is
  /// not processed: tracker.stale). If `population` is given, it receives the GA's final population as
  /// base poses in the odometry frame.
  PipelineUpdate processScan(double stamp, const RangeScan& ranges,
                             std::vector<Pose2D>* population = nullptr);

  /// Restarts the estimate from the identity pose at the next scan. Kept: the odometry history, the
  /// laser mount and what the previous scans looked like (geometry, error state).
  void reset();

  /// Restarts like reset(), but from `pose` (the base in the odometry frame at `stamp`) with `covariance`:
  /// OdometryTracker::setPose. False (nothing changed) for invalid input.
  bool setPose(double stamp, const Pose2D& pose, const Eigen::Matrix3d& covariance);

  const TrackerOptions& options() const { return tracker_.options(); }
  const ScanConversionOptions& conversion() const { return conversion_; }
  Pose2D pose() const { return tracker_.pose(); }
  /// The reference scans are matched against: its points in its frame() (the newest keyframe's laser
  /// pose in the odometry frame). revision() tells when it changed.
  const LocalMap& localMap() const { return tracker_.localMap(); }

 private:
  /// The update of a scan stamped before the newest one processed (`newest`): dropped, nothing published.
  PipelineUpdate staleScan(double stamp, double newest) const;
  /// The scans' clock went back from `newest` to `stamp`: restart, and forget the inputs still on the old
  /// timeline. Returns the warning.
  std::string restartTimeline(double stamp, double newest);

  OdometryTracker tracker_;
  bool wait_for_inputs_;
  ScanConversionOptions conversion_;
  /// One input the scans wait for (wheel odometry, the IMU) under the time and feeding policies.
  struct InputFeed {
    explicit InputFeed(double reset_on_jump_back) : order(reset_on_jump_back) {}
    StampOrder order;  ///< newest(): the stamp of the newest sample added
    bool stalled = false;
    /// Judges a sample's stamp (time policy). A new timeline, or a sample at or after
    /// `needed_by_last_scan` (what the last scan processed waited for), revives a stalled input.
    StampOrder::Verdict take(double stamp, double needed_by_last_scan);
    /// A scan needing samples up to `stamp` may go on: one has come, or none ever did (nothing to wait
    /// for), or the input stalled.
    bool readyFor(double stamp) const {
      return !std::isfinite(order.newest()) || stalled || order.newest() >= stamp;
    }
  };
  InputFeed wheels_, imu_;
  StampOrder scan_order_;  // newest(): the stamp of the last scan processed
  bool wheelsReadyFor(double stamp) const;
  bool imuReadyFor(double stamp) const;  // the stamp the IMU must reach

  ScanError scan_error_ = ScanError::kNone;
  bool imu_stale_ = false;
};

}  // namespace hglasm
