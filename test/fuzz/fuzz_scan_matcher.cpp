// libFuzzer target: arbitrary bytes -> two RangeScans (+ a guess and options) -> conversion, matching (the
// odometry's matcher and the evaluation's baselines) and tracking. Asserts what the package promises for
// any input: no crash, finite outputs.
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <vector>

#include "hglasm_odometry/core/odometry_tracker.h"
#include "hglasm_odometry/core/scan_matcher.h"
#include "hglasm_odometry/evaluation/baseline_matcher.h"

namespace {

/// Consumes the input front to back; returns zeros once it runs out.
class ByteReader {
 public:
  ByteReader(const std::uint8_t* data, std::size_t size) : data_(data), size_(size) {}
  template <typename T>
  T take() {
    T value{};
    const std::size_t n = std::min(sizeof(T), size_ - offset_);
    std::memcpy(&value, data_ + offset_, n);
    offset_ += n;
    return value;
  }
  std::size_t remaining() const { return size_ - offset_; }

 private:
  const std::uint8_t* data_;
  std::size_t size_;
  std::size_t offset_ = 0;
};

hglasm::RangeScan takeScan(ByteReader& reader) {
  hglasm::RangeScan scan;
  scan.angle_min = reader.take<float>();
  scan.angle_increment = reader.take<float>();
  scan.range_min = reader.take<float>();
  scan.range_max = reader.take<float>();
  const std::size_t beams = reader.take<std::uint16_t>() % 1200;
  for (std::size_t i = 0; i < beams && reader.remaining() >= 2; ++i) {
    // Mostly plausible ranges (0-20 m in mm) with raw floats mixed in (NaN, inf, negative, huge).
    const std::uint16_t raw = reader.take<std::uint16_t>();
    scan.ranges.push_back(raw >= 0xFF00 ? reader.take<float>() : raw * 0.0003f);
  }
  return scan;
}

void check(bool condition) {
  if (!condition) std::abort();
}

void checkFinite(const hglasm::MatchResult& result) {
  check(result.pose.isFinite());
  check(result.prealigned_pose.isFinite());
  check(result.covariance.allFinite());
  check(std::isfinite(result.prealigned_fitness_ratio) && result.prealigned_fitness_ratio >= 0.0 &&
        result.prealigned_fitness_ratio <= 1.0 + 1e-9);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  ByteReader reader(data, size);
  const std::uint8_t selector = reader.take<std::uint8_t>();
  const hglasm::Preset preset = static_cast<hglasm::Preset>(selector % 3);
  const auto algorithm = static_cast<hglasm::Algorithm>((selector / 3) % 7);  // PGA and HPGA included
  hglasm::BaselineOptions baseline = hglasm::baselineOptions(algorithm, preset);
  hglasm::MatcherOptions& options = baseline.matcher;
  // Keep each run short: the fuzzer explores inputs, not GA sizes.
  options.genetic.population = 10;
  options.genetic.generations = 3;
  options.genetic.runs = 1;
  options.mbicp.max_iterations = 10;

  const hglasm::RangeScan reference_ranges = takeScan(reader);
  const hglasm::RangeScan new_ranges = takeScan(reader);
  const hglasm::Pose2D guess(reader.take<float>(), reader.take<float>(), reader.take<float>());

  hglasm::ScanConversionOptions conversion;
  conversion.mirror = selector & 0x80;
  hglasm::ScanError error = hglasm::ScanError::kNone;
  const hglasm::Scan reference = hglasm::scanFromRanges(reference_ranges, conversion, &error);
  const hglasm::Scan scan = hglasm::scanFromRanges(new_ranges, conversion, &error);
  for (const auto& p : reference.points) check(p.allFinite());

  hglasm::ScanMatcher matcher(options);
  matcher.setReference(reference);
  checkFinite(matcher.match(scan, guess));
  checkFinite(matcher.refine(scan, guess));
  hglasm::BaselineMatcher compared(baseline);
  compared.setReference(reference);
  checkFinite(compared.match(scan, guess));

  // The tracker over the two scans, with odometry samples from the same bytes.
  hglasm::TrackerOptions tracker_options;
  tracker_options.matcher = options;
  hglasm::OdometryTracker tracker(tracker_options);
  tracker.addOdometry(reader.take<float>(), guess);
  for (int i = 0; i < 3; ++i) {
    const double stamp = reader.take<float>();
    const hglasm::TrackerUpdate update = tracker.processScan(stamp, i % 2 ? scan : reference);
    check(update.pose.isFinite());
    check(update.pose_covariance.allFinite());
    check(update.velocity.allFinite());
    check(update.velocity_covariance.allFinite());
  }
  return 0;
}
