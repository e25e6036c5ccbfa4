#include "hglasm_odometry/ros/parameters.h"

#include <cmath>
#include <limits>
#include <set>
#include <sstream>

#include <ros/names.h>

#include "hglasm_odometry/core/scan_matcher.h"
#include "hglasm_odometry/ros/conversions.h"

namespace hglasm_odometry {
namespace {

using XmlRpc::XmlRpcValue;

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kMaxFixedTimeOffset = 10.0;  // seconds: odometry/time_offset set by hand

/// "5", "-0.3", "string \"abc\"", "a list": how a value appears in an error message.
std::string describe(const XmlRpcValue& value) {
  XmlRpcValue copy = value;  // the typed conversions of XmlRpcValue are not const
  std::ostringstream out;
  switch (copy.getType()) {
    case XmlRpcValue::TypeBoolean:
      out << (static_cast<bool>(copy) ? "true" : "false");
      break;
    case XmlRpcValue::TypeInt:
      out << static_cast<int>(copy);
      break;
    case XmlRpcValue::TypeDouble:
      out << static_cast<double>(copy);
      break;
    case XmlRpcValue::TypeString:
      out << "string \"" << static_cast<std::string>(copy) << "\"";
      break;
    case XmlRpcValue::TypeArray:
      out << "a list";
      break;
    case XmlRpcValue::TypeStruct:
      out << "a dictionary";
      break;
    default:
      out << "a value of an unsupported type";
      break;
  }
  return out.str();
}

std::string formatNumber(double value) {
  std::ostringstream out;
  out << value;
  return out.str();
}

/// The ranges every option visitor shares: the reader below validates them, the writer ignores them.
template <typename Derived>
class OptionVisitor {
 public:
  void positiveNumber(const std::string& path, double* value) { self().number(path, value, 0.0, kInf, true); }
  void nonNegativeNumber(const std::string& path, double* value) { self().number(path, value, 0.0, kInf); }
  void fraction(const std::string& path, double* value) { self().number(path, value, 0.0, 1.0); }
  void positiveInteger(const std::string& path, int* value) {
    self().integer(path, value, 1, std::numeric_limits<int>::max());
  }

 private:
  Derived& self() { return static_cast<Derived&>(*this); }
};

/// Typed, validating reads from one parameter subtree. The first error wins; later reads are no-ops.
/// Every path read is remembered, so the keys never read can be reported as unknown.
class ParamTree : public OptionVisitor<ParamTree> {
 public:
  ParamTree(const XmlRpcValue& root, std::string display_prefix, std::string* error)
      : root_(root), prefix_(std::move(display_prefix)), error_(error) {}
  bool failed() const { return failed_; }

  /// Finds `path` ("genetic/population"); false if absent. Marks the path as known either way.
  bool find(const std::string& path, XmlRpcValue* value) {
    known_.insert(path);
    if (failed_) return false;
    const XmlRpcValue* node = &root_;
    std::size_t start = 0;
    while (true) {
      const std::size_t slash = path.find('/', start);
      const std::string key =
          path.substr(start, slash == std::string::npos ? std::string::npos : slash - start);
      if (node->getType() != XmlRpcValue::TypeStruct || !node->hasMember(key)) return false;
      node = &(*node)[key];
      if (slash == std::string::npos) break;
      start = slash + 1;
    }
    *value = *node;
    return true;
  }

  void fail(const std::string& path, const std::string& requirement, const std::string& got) {
    if (failed_) return;
    failed_ = true;
    if (error_) *error_ = "parameter " + prefix_ + path + " must be " + requirement + ", got " + got;
  }

  /// A number (int or double) within [lo, hi]; `positive` additionally excludes 0. Infinity only if
  /// `allow_inf`.
  void number(const std::string& path, double* out, double lo, double hi, bool positive = false,
              bool allow_inf = false) {
    XmlRpcValue value;
    if (!find(path, &value)) return;
    std::string requirement;
    if (positive && hi == kInf) {
      requirement = "a positive number";
    } else if (lo == 0.0 && hi == kInf) {
      requirement = "a non-negative number";
    } else if (lo == -kInf && hi == kInf) {
      requirement = "a finite number";
    } else {
      requirement = "a number in [" + formatNumber(lo) + ", " + formatNumber(hi) + "]";
      if (positive) requirement += " and > 0";
    }
    if (allow_inf) requirement += " (or .inf)";
    double number = 0.0;
    if (value.getType() == XmlRpcValue::TypeInt) {
      number = static_cast<int>(value);
    } else if (value.getType() == XmlRpcValue::TypeDouble) {
      number = static_cast<double>(value);
    } else {
      fail(path, requirement, describe(value));
      return;
    }
    const bool inf_ok = allow_inf && std::isinf(number) && number > 0.0;
    if (std::isnan(number) || (!std::isfinite(number) && !inf_ok) || number < lo || number > hi ||
        (positive && number <= 0.0)) {
      fail(path, requirement, describe(value));
      return;
    }
    *out = number;
  }

  /// An integer within [lo, hi].
  void integer(const std::string& path, int* out, int lo, int hi) {
    XmlRpcValue value;
    if (!find(path, &value)) return;
    std::string requirement;
    if (lo == 1 && hi == std::numeric_limits<int>::max()) {
      requirement = "a positive integer";
    } else if (lo == 0 && hi == std::numeric_limits<int>::max()) {
      requirement = "a non-negative integer";
    } else {
      requirement = "an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]";
    }
    if (value.getType() != XmlRpcValue::TypeInt) {
      fail(path, requirement, describe(value));
      return;
    }
    const int number = static_cast<int>(value);
    if (number < lo || number > hi) {
      fail(path, requirement, describe(value));
      return;
    }
    *out = number;
  }

  void boolean(const std::string& path, bool* out) {
    XmlRpcValue value;
    if (!find(path, &value)) return;
    if (value.getType() != XmlRpcValue::TypeBoolean) {
      fail(path, "true or false", describe(value));
      return;
    }
    *out = static_cast<bool>(value);
  }

  /// A non-empty string.
  bool string(const std::string& path, std::string* out) {
    XmlRpcValue value;
    if (!find(path, &value)) return false;
    if (value.getType() != XmlRpcValue::TypeString || static_cast<std::string>(value).empty()) {
      fail(path, "a non-empty string", describe(value));
      return false;
    }
    *out = static_cast<std::string>(value);
    return true;
  }

  /// A frame id (a non-empty string; a leading slash is dropped, tf2 rejects it).
  void frame(const std::string& path, std::string* out) {
    std::string frame;
    if (string(path, &frame)) *out = stripLeadingSlash(frame);
  }

  /// A valid relative or absolute graph resource name (not a private "~" one).
  void topic(const std::string& path, std::string* out) {
    std::string name;
    if (!string(path, &name)) return;
    std::string why;
    if (name[0] == '~' || !ros::names::validate(name, why)) {
      fail(path, "a relative or absolute topic name", describe(name));
      return;
    }
    *out = name;
  }

  /// A parameter that was removed: set at all, it is an error saying so (`why`: what to do instead).
  void removed(const std::string& path, const std::string& why) {
    XmlRpcValue value;
    if (!find(path, &value) || failed_) return;
    failed_ = true;
    if (error_) *error_ = "parameter " + prefix_ + path + " (" + describe(value) + ") was removed: " + why;
  }

  /// "auto" (learned from the matches) or a fixed number of seconds within +-kMaxFixedTimeOffset.
  void timeOffset(const std::string& path, hglasm::TimeOffsetOptions* out) {
    XmlRpcValue value;
    if (!find(path, &value)) return;
    const std::string requirement = "auto or a number of seconds in [-" + formatNumber(kMaxFixedTimeOffset) +
                                    ", " + formatNumber(kMaxFixedTimeOffset) + "]";
    if (value.getType() == XmlRpcValue::TypeString && static_cast<std::string>(value) == "auto") {
      out->estimate = true;
      out->offset = 0.0;
      return;
    }
    double seconds = 0.0;
    if (value.getType() == XmlRpcValue::TypeInt) {
      seconds = static_cast<int>(value);
    } else if (value.getType() == XmlRpcValue::TypeDouble) {
      seconds = static_cast<double>(value);
    } else {
      fail(path, requirement, describe(value));
      return;
    }
    if (!(std::abs(seconds) <= kMaxFixedTimeOffset)) {
      fail(path, requirement, describe(value));
      return;
    }
    out->estimate = false;
    out->offset = seconds;
  }

  /// Leaf paths present in the tree but never read (typos), skipping the given top-level keys.
  std::vector<std::string> unknownPaths(const std::set<std::string>& skipped_top_level) const {
    std::vector<std::string> unknown;
    collect(root_, "", skipped_top_level, &unknown);
    return unknown;
  }

 private:
  void collect(const XmlRpcValue& node, const std::string& path, const std::set<std::string>& skipped,
               std::vector<std::string>* unknown) const {
    if (node.getType() != XmlRpcValue::TypeStruct) {
      if (!path.empty() && known_.count(path) == 0) unknown->push_back(prefix_ + path);
      return;
    }
    if (!path.empty() && known_.count(path) != 0) return;  // a known key holding a dictionary
    for (auto it = node.begin(); it != node.end(); ++it) {
      if (path.empty() && skipped.count(it->first) != 0) continue;
      collect(it->second, path.empty() ? it->first : path + "/" + it->first, skipped, unknown);
    }
  }

  XmlRpcValue root_;
  std::string prefix_;
  std::string* error_;
  bool failed_ = false;
  std::set<std::string> known_;
};

/// Writes every option at its parameter path: what loadOptions would read back unchanged.
class ParamWriter : public OptionVisitor<ParamWriter> {
 public:
  explicit ParamWriter(XmlRpcValue* root) : root_(root) {}

  void number(const std::string& path, double* value, double, double, bool = false, bool = false) {
    set(path, XmlRpcValue(*value));
  }
  void integer(const std::string& path, int* value, int, int) { set(path, XmlRpcValue(*value)); }
  void boolean(const std::string& path, bool* value) { set(path, XmlRpcValue(*value)); }
  void frame(const std::string& path, std::string* value) { set(path, XmlRpcValue(*value)); }
  void topic(const std::string& path, std::string* value) { set(path, XmlRpcValue(*value)); }
  void timeOffset(const std::string& path, hglasm::TimeOffsetOptions* value) {
    set(path, value->estimate ? XmlRpcValue(std::string("auto")) : XmlRpcValue(value->offset));
  }

 private:
  void set(const std::string& path, const XmlRpcValue& value) {
    XmlRpcValue* node = root_;
    std::size_t start = 0;
    for (std::size_t slash; (slash = path.find('/', start)) != std::string::npos; start = slash + 1) {
      node = &(*node)[path.substr(start, slash - start)];
    }
    (*node)[path.substr(start)] = value;
  }

  XmlRpcValue* root_;
};

// The one list of the parameters, by layer (visitOptions below): each option at its parameter path with
// its valid range.

/// Frames, topics' behaviour, queue.
template <typename Params>
void visitNodeOptions(Params& tree, LaserOdometryOptions* options) {
  tree.frame("odom_frame", &options->odom_frame);
  tree.frame("base_frame", &options->base_frame);
  tree.boolean("publish_tf", &options->publish_tf);
  tree.boolean("use_odom", &options->tracker.prediction.use_odometry);
  tree.boolean("use_imu", &options->tracker.prediction.use_imu);
  tree.integer("path_length", &options->path_length, 0, 1000000);
  tree.integer("queue_size", &options->queue_size, 1, 10000);
  tree.boolean("publish_population", &options->publish_population);
  tree.positiveNumber("tf_warn_period", &options->tf_warn_period);
  tree.boolean("set_pose/topic_enabled", &options->set_pose.topic_enabled);
  tree.topic("set_pose/topic", &options->set_pose.topic);
}

/// Keyframes, failure policy, the search around the prediction and leaps away from it, the local map.
template <typename Params>
void visitTrackerOptions(Params& tree, hglasm::TrackerOptions* options) {
  hglasm::TrackerOptions& tracker = *options;
  tree.positiveNumber("keyframe/distance", &tracker.keyframe.distance);
  tree.number("keyframe/angle", &tracker.keyframe.angle, 0.0, M_PI, true);
  tree.fraction("keyframe/min_fitness", &tracker.keyframe.min_fitness);
  tree.fraction("min_fitness", &tracker.min_fitness);
  tree.positiveInteger("min_points", &tracker.min_points);
  tree.number("fallback_covariance_scale", &tracker.uncertainty.fallback_scale, 1.0, 1e12);
  tree.positiveNumber("time/reset_on_jump_back", &tracker.reset_on_jump_back);

  // The search around the prediction, and leaps away from it.
  tree.boolean("fusion", &tracker.fusion);
  tree.nonNegativeNumber("covariance/unexplained_xy", &tracker.uncertainty.unexplained_xy);
  tree.nonNegativeNumber("covariance/unexplained_theta", &tracker.uncertainty.unexplained_theta);
  tree.positiveNumber("search/sigmas", &tracker.search.sigmas);
  tree.nonNegativeNumber("search/min_xy", &tracker.search.min_xy);
  tree.number("search/min_theta", &tracker.search.min_theta, 0.0, M_PI);
  tree.positiveNumber("leap/max_mahalanobis", &tracker.leap.max_mahalanobis);
  tree.number("leap/probability", &tracker.leap.probability, 0.0, 0.5, true);
  tree.number("leap/persistence", &tracker.leap.persistence, 0.0, 1.0, true);
  tree.number("leap/likelihood_outlier", &tracker.leap.likelihood_outlier, 0.0, 1.0, true);
  tree.boolean("leap/confirm", &tracker.leap.confirm);
  tree.number("leap/confirm_below", &tracker.leap.confirm_below, 0.0, 1.0, true);

  // The local map the scans are matched against.
  tree.positiveInteger("local_map/keyframes", &tracker.local_map.keyframes);
  tree.positiveNumber("local_map/max_distance", &tracker.local_map.max_distance);
  tree.nonNegativeNumber("local_map/resolution", &tracker.local_map.resolution);
  tree.nonNegativeNumber("local_map/reframe_distance", &tracker.local_map.reframe_distance);
}

/// Wheel odometry as the prediction, and its noise.
template <typename Params>
void visitPredictionOptions(Params& tree, LaserOdometryOptions* options) {
  hglasm::TrackerOptions& tracker = options->tracker;
  tree.nonNegativeNumber("odometry/max_extrapolation", &tracker.prediction.max_odometry_extrapolation);
  tree.timeOffset("odometry/time_offset", &tracker.learning.odometry_time_offset);
  tree.number("odometry/max_time_offset", &tracker.learning.odometry_time_offset.max_offset, 0.0,
              kMaxFixedTimeOffset);
  hglasm::MotionNoiseOptions& motion = tracker.motion;
  tree.nonNegativeNumber("odometry/noise/xy_per_metre", &motion.xy_per_metre);
  tree.nonNegativeNumber("odometry/noise/xy_per_radian", &motion.xy_per_radian);
  tree.nonNegativeNumber("odometry/noise/xy_per_second", &motion.xy_per_second);
  tree.nonNegativeNumber("odometry/noise/theta_per_metre", &motion.theta_per_metre);
  tree.nonNegativeNumber("odometry/noise/theta_per_radian", &motion.theta_per_radian);
  tree.nonNegativeNumber("odometry/noise/theta_per_second", &motion.theta_per_second);
  tree.nonNegativeNumber("odometry/noise/systematic", &motion.systematic);
  hglasm::NoiseLearnerOptions& learning = tracker.learning.noise;
  tree.boolean("odometry/noise/learn", &learning.learn_wheels);
  tree.positiveNumber("odometry/noise/learn_half_life", &learning.half_life);
  tree.positiveInteger("odometry/noise/learn_lags", &learning.lags);
  tree.positiveNumber("odometry/noise/min_scale", &learning.min_wheel_scale);
  tree.positiveNumber("odometry/noise/max_scale", &learning.max_wheel_scale);
  hglasm::WheelCalibrationOptions& calibration = tracker.learning.wheel_calibration;
  tree.boolean("odometry/calibration/learn", &calibration.learn);
  tree.positiveNumber("odometry/calibration/half_life", &calibration.half_life);
  tree.positiveNumber("odometry/calibration/heading_per_metre", &calibration.heading_per_metre);
  tree.positiveNumber("odometry/calibration/turn_scale", &calibration.turn_scale);
  tree.positiveNumber("odometry/calibration/distance_scale", &calibration.distance_scale);
  tree.boolean("scan_noise/learn", &learning.learn_scan);
  tree.boolean("scan_noise/directional", &learning.directional);
  tree.positiveNumber("scan_noise/min_scale", &learning.min_scan_scale);
  tree.positiveNumber("scan_noise/max_scale", &learning.max_scan_scale);
  tree.positiveNumber("constant_velocity/xy", &motion.constant_velocity_xy);
  tree.positiveNumber("constant_velocity/theta", &motion.constant_velocity_theta);
  tree.nonNegativeNumber("constant_velocity/velocity_xy", &motion.constant_velocity_velocity_xy);
  tree.nonNegativeNumber("constant_velocity/velocity_theta", &motion.constant_velocity_velocity_theta);
  tree.positiveNumber("odometry/max_speed", &tracker.prediction.max_speed);
  tree.positiveNumber("odometry/max_turn_rate", &tracker.prediction.max_turn_rate);
  tree.number("odometry/wait", &options->odometry_wait, 0.0, 10.0);
  hglasm::GyroOptions& imu = tracker.prediction.imu;
  tree.boolean("imu/use_orientation", &imu.use_orientation);
  tree.number("imu/max_gap", &imu.max_gap, 0.0, 10.0, true);
  tree.nonNegativeNumber("imu/noise/angle_random_walk", &imu.angle_random_walk);
  tree.nonNegativeNumber("imu/noise/bias_sigma", &imu.bias_sigma);
  tree.nonNegativeNumber("imu/noise/scale_error", &imu.scale_error);
  tree.boolean("imu/noise/estimate_bias", &imu.estimate_bias);
  tree.nonNegativeNumber("imu/noise/bias_random_walk", &imu.bias_random_walk);
}

/// Scan conversion.
template <typename Params>
void visitScanOptions(Params& tree, hglasm::TrackerOptions* tracker) {
  tree.nonNegativeNumber("scan/min_range", &tracker->conversion.min_range);
  tree.number("scan/max_range", &tracker->conversion.max_range, 0.0, kInf, true, true);
  tree.integer("scan/beam_step", &tracker->conversion.beam_step, 1, 100);
  tree.boolean("scan/deskew", &tracker->deskew);
  tree.number("scan/sweep_time", &tracker->conversion.sweep_time, 0.0, hglasm::kMaxSweepTime);
}

/// Lookup tables (the fine one, and the coarse one of the first GA generations) and the genetic
/// pre-alignment.
template <typename Params>
void visitGeneticOptions(Params& tree, hglasm::MatcherOptions* options) {
  hglasm::MatcherOptions& matcher = *options;
  for (const char* name : {"table", "coarse_table"}) {
    hglasm::LookupTableOptions& table = std::string(name) == "table" ? matcher.table : matcher.coarse_table;
    const std::string prefix = std::string(name) + "/";
    tree.positiveNumber(prefix + "cell_size", &table.cell_size);
    tree.positiveNumber(prefix + "sigma", &table.sigma);
    tree.positiveNumber(prefix + "cutoff", &table.cutoff);
    tree.number(prefix + "segment_max_gap", &table.segment_max_gap, 0.0, kInf);
    tree.number(prefix + "segment_max_incidence", &table.segment_max_incidence, 0.0, 0.5 * M_PI);
    tree.nonNegativeNumber(prefix + "isolated_footprint", &table.isolated_footprint);
  }

  // Genetic pre-alignment.
  hglasm::GeneticOptions& genetic = matcher.genetic;
  tree.positiveNumber("genetic/box_x", &genetic.box.half_x);
  tree.positiveNumber("genetic/box_y", &genetic.box.half_y);
  tree.number("genetic/box_theta", &genetic.box.half_theta, 0.0, M_PI, true);
  tree.integer("genetic/population", &genetic.population, 2, 100000);
  tree.positiveInteger("genetic/generations", &genetic.generations);
  tree.positiveInteger("genetic/runs", &genetic.runs);
  tree.integer("genetic/bits_per_gene", &genetic.bits_per_gene, 2, 20);
  tree.fraction("genetic/crossover_rate", &genetic.crossover_rate);
  tree.fraction("genetic/mutation_rate", &genetic.mutation_rate);
  tree.positiveInteger("genetic/tournament_size", &genetic.tournament_size);
  tree.integer("genetic/elite_count", &genetic.elite_count, 1, 100000);
  tree.integer("genetic/max_points", &genetic.max_points, 0, 1000000);
  tree.integer("genetic/polish_evaluations", &genetic.polish_evaluations, 0, 1000000);
  tree.integer("genetic/coarse_generations", &genetic.coarse_generations, 0, 100000);
  int seed = static_cast<int>(genetic.seed);
  tree.integer("genetic/seed", &seed, 0, std::numeric_limits<int>::max());
  genetic.seed = static_cast<std::uint64_t>(seed);
}

/// MbICP refinement.
template <typename Params>
void visitMbicpOptions(Params& tree, hglasm::MbicpOptions* options) {
  hglasm::MbicpOptions& mbicp = *options;
  tree.positiveNumber("mbicp/metric_l", &mbicp.metric_l);
  tree.number("mbicp/bearing_window", &mbicp.bearing_window, 0.0, M_PI, true);
  tree.positiveNumber("mbicp/max_distance", &mbicp.max_distance);
  tree.nonNegativeNumber("mbicp/fine_max_distance", &mbicp.fine_max_distance);
  tree.nonNegativeNumber("mbicp/settle_step_xy", &mbicp.settle_step_xy);
  tree.nonNegativeNumber("mbicp/settle_step_theta", &mbicp.settle_step_theta);
  tree.nonNegativeNumber("mbicp/segment_max_gap", &mbicp.segment_max_gap);
  tree.number("mbicp/segment_max_incidence", &mbicp.segment_max_incidence, 0.0, 0.5 * M_PI);
  tree.boolean("mbicp/point_to_line", &mbicp.point_to_line);
  tree.nonNegativeNumber("mbicp/robust_scale", &mbicp.robust_scale);
  tree.number("mbicp/trim_fraction", &mbicp.trim_fraction, 0.0, 1.0, true);
  tree.nonNegativeNumber("mbicp/point_noise", &mbicp.point_noise);
  tree.positiveInteger("mbicp/max_iterations", &mbicp.max_iterations);
  tree.nonNegativeNumber("mbicp/error_ratio", &mbicp.error_ratio);
  tree.nonNegativeNumber("mbicp/min_step_xy", &mbicp.min_step_xy);
  tree.nonNegativeNumber("mbicp/min_step_theta", &mbicp.min_step_theta);
  tree.positiveInteger("mbicp/converged_iterations", &mbicp.converged_iterations);
  tree.fraction("mbicp/min_association_ratio", &mbicp.min_association_ratio);
  tree.fraction("mbicp/degenerate_eigenvalue", &mbicp.degenerate_eigenvalue);
  tree.nonNegativeNumber("mbicp/independent_points", &mbicp.independent_points);
}

/// Every option except ~preset itself (which selects the starting point), each at its parameter path with
/// its valid range: read (ParamTree) from the ~presets/<name> subtree and from the top level alike, or
/// written (ParamWriter). The one list of the parameters.
template <typename Params>
void visitOptions(Params& tree, LaserOdometryOptions* options) {
  visitNodeOptions(tree, options);
  visitTrackerOptions(tree, &options->tracker);
  visitPredictionOptions(tree, options);
  visitScanOptions(tree, &options->tracker);
  visitGeneticOptions(tree, &options->tracker.matcher);
  visitMbicpOptions(tree, &options->tracker.matcher.mbicp);
  // Diagnostics.
  tree.nonNegativeNumber("diagnostics/min_rate", &options->diagnostics.min_rate);
  tree.fraction("diagnostics/warn_failure_ratio", &options->diagnostics.warn_failure_ratio);
  tree.fraction("diagnostics/error_failure_ratio", &options->diagnostics.error_failure_ratio);
  tree.positiveNumber("diagnostics/window", &options->diagnostics.window);
  tree.positiveNumber("diagnostics/period", &options->diagnostics.period);
}

/// Constraints between parameters, checked once all layers are applied.
bool checkConsistency(const LaserOdometryOptions& options, std::string* error) {
  auto fail = [error](const std::string& message) {
    if (error) *error = message;
    return false;
  };
  const hglasm::GeneticOptions& genetic = options.tracker.matcher.genetic;
  if (genetic.elite_count >= genetic.population) {
    return fail("parameter ~genetic/elite_count must be less than ~genetic/population (" +
                std::to_string(genetic.population) + "), got " + std::to_string(genetic.elite_count));
  }
  if (genetic.coarse_generations > genetic.generations) {
    return fail("parameter ~genetic/coarse_generations must not exceed ~genetic/generations (" +
                std::to_string(genetic.generations) + "), got " + std::to_string(genetic.coarse_generations));
  }
  if (genetic.tournament_size > genetic.population) {
    return fail("parameter ~genetic/tournament_size must not exceed ~genetic/population (" +
                std::to_string(genetic.population) + "), got " + std::to_string(genetic.tournament_size));
  }
  const hglasm::NoiseLearnerOptions& learning = options.tracker.learning.noise;
  if (learning.max_wheel_scale < learning.min_wheel_scale) {
    return fail("parameter ~odometry/noise/max_scale must be at least ~odometry/noise/min_scale (" +
                formatNumber(learning.min_wheel_scale) + "), got " + formatNumber(learning.max_wheel_scale));
  }
  if (learning.max_scan_scale < learning.min_scan_scale) {
    return fail("parameter ~scan_noise/max_scale must be at least ~scan_noise/min_scale (" +
                formatNumber(learning.min_scan_scale) + "), got " + formatNumber(learning.max_scan_scale));
  }
  const hglasm::ScanConversionOptions& conversion = options.tracker.conversion;
  if (conversion.max_range <= conversion.min_range) {
    return fail("parameter ~scan/max_range must be greater than ~scan/min_range (" +
                formatNumber(conversion.min_range) + "), got " + formatNumber(conversion.max_range));
  }
  if (options.diagnostics.error_failure_ratio < options.diagnostics.warn_failure_ratio) {
    return fail(
        "parameter ~diagnostics/error_failure_ratio must be at least ~diagnostics/warn_failure_ratio (" +
        formatNumber(options.diagnostics.warn_failure_ratio) + "), got " +
        formatNumber(options.diagnostics.error_failure_ratio));
  }
  if (options.odom_frame.empty() || options.base_frame.empty() || options.odom_frame == options.base_frame) {
    return fail("parameter ~base_frame must differ from ~odom_frame and neither may be \"/\", got \"" +
                options.base_frame + "\" and \"" + options.odom_frame + "\"");
  }
  return true;
}

/// ~algorithm chose among the papers' matchers; a baseline is no longer what the odometry can run.
constexpr const char* kAlgorithmRemoved =
    "the odometry always runs hglasm_g; the papers' other algorithms are compared by the success_ratio tool "
    "(--algorithms); delete the parameter";

/// What a user is told of a parameter nobody reads: a retired one says what replaced it.
std::string unknownParameterWarning(const std::string& path) {
  if (path == "~max_time_jump") {
    return "parameter ~max_time_jump is no longer used (ignored): a forward gap in the scans' stamps of any "
           "length continues from the current pose; only a clock that jumps back by more than "
           "~time/reset_on_jump_back resets";
  }
  return "unknown parameter " + path + " (ignored)";
}

/// Layer 1: the built-in values of the preset ~preset names. *in_yaml: ~presets/<name> exists (layer 2),
/// then copied into *preset_tree.
bool startFromPreset(ParamTree& top, LaserOdometryOptions* options, bool* in_yaml, XmlRpcValue* preset_tree,
                     std::string* error) {
  std::string preset_name = options->preset;
  if (!top.string("preset", &preset_name) && top.failed()) return false;
  XmlRpcValue presets;
  const bool has_presets = top.find("presets", &presets);
  if (has_presets && presets.getType() != XmlRpcValue::TypeStruct) {
    if (error) *error = "parameter ~presets must be a dictionary of presets, got " + describe(presets);
    return false;
  }
  const bool preset_in_yaml = has_presets && presets.hasMember(preset_name);
  hglasm::Preset builtin = hglasm::Preset::kMedium;  // what a preset defined in YAML alone builds on
  if (!hglasm::parsePreset(preset_name, &builtin) && !preset_in_yaml) {
    if (error) {
      *error =
          "parameter ~preset must be one of small, medium, large (or a preset defined under ~presets), "
          "got string \"" +
          preset_name + "\"";
    }
    return false;
  }
  options->preset = preset_name;
  options->tracker.matcher = hglasm::presetOptions(builtin);
  *in_yaml = preset_in_yaml;
  if (preset_in_yaml) *preset_tree = presets[preset_name];
  return true;
}

/// Layer 2: ~presets/<name> (config/presets.yaml).
bool applyPresetTree(const XmlRpcValue& preset_tree, LaserOdometryOptions* options, std::string* error,
                     std::vector<std::string>* warnings) {
  const std::string prefix = "~presets/" + options->preset;
  if (preset_tree.getType() != XmlRpcValue::TypeStruct) {
    if (error) *error = "parameter " + prefix + " must be a dictionary, got " + describe(preset_tree);
    return false;
  }
  std::string preset_error;
  ParamTree preset_params(preset_tree, prefix + "/", &preset_error);
  visitOptions(preset_params, options);
  preset_params.removed("algorithm", kAlgorithmRemoved);
  if (preset_params.failed()) {
    if (error) *error = preset_error;
    return false;
  }
  if (warnings) {
    for (const std::string& path : preset_params.unknownPaths({})) {
      warnings->push_back("unknown parameter " + path + " (ignored)");
    }
  }
  return true;
}

}  // namespace

bool loadOptions(const XmlRpcValue& private_params, LaserOdometryOptions* options, std::string* error,
                 std::vector<std::string>* warnings) {
  // An invalid (empty) value means no parameters at all: every default applies.
  const XmlRpcValue& root = private_params;
  if (root.getType() != XmlRpcValue::TypeStruct && root.getType() != XmlRpcValue::TypeInvalid) {
    if (error) *error = "the private namespace must hold a dictionary of parameters, got " + describe(root);
    return false;
  }
  std::string top_error;
  ParamTree top(root, "~", &top_error);
  *options = LaserOdometryOptions();
  bool preset_in_yaml = false;
  XmlRpcValue preset_tree;
  if (!startFromPreset(top, options, &preset_in_yaml, &preset_tree, error)) {
    if (error && top.failed()) *error = top_error;
    return false;
  }
  if (preset_in_yaml && !applyPresetTree(preset_tree, options, error, warnings)) return false;

  // Layer 3: the top level (config/laser_odometry.yaml, single overrides).
  visitOptions(top, options);
  top.removed("algorithm", kAlgorithmRemoved);
  if (top.failed()) {
    if (error) *error = top_error;
    return false;
  }
  if (!checkConsistency(*options, error)) return false;
  if (warnings) {
    // diagnostic_period belongs to diagnostic_updater, which reads it from the same namespace.
    for (const std::string& path : top.unknownPaths({"presets", "diagnostic_period"})) {
      warnings->push_back(unknownParameterWarning(path));
    }
  }
  return true;
}

XmlRpcValue toParams(const LaserOdometryOptions& options) {
  XmlRpcValue params;
  ParamWriter writer(&params);
  LaserOdometryOptions copy = options;  // the visitor reads through non-const pointers
  visitOptions(writer, &copy);
  return params;
}

bool loadOptions(const ros::NodeHandle& private_nh, LaserOdometryOptions* options, std::string* error,
                 std::vector<std::string>* warnings) {
  XmlRpcValue params;
  if (!private_nh.getParam(private_nh.getNamespace(), params)) params = XmlRpcValue();
  return loadOptions(params, options, error, warnings);
}

std::string summarize(const LaserOdometryOptions& options) {
  const hglasm::MatcherOptions& matcher = options.tracker.matcher;
  const hglasm::GeneticOptions& genetic = matcher.genetic;
  std::ostringstream out;
  out << "preset " << options.preset << ", box +-" << genetic.box.half_x << " m x +-" << genetic.box.half_y
      << " m x +-" << genetic.box.half_theta << " rad, GA " << genetic.population << "x"
      << genetic.generations << "x" << genetic.runs << ", cell " << matcher.table.cell_size << " m, keyframe "
      << options.tracker.keyframe.distance << " m / " << options.tracker.keyframe.angle << " rad, "
      << options.odom_frame << " -> " << options.base_frame << (options.publish_tf ? " (tf)" : " (no tf)")
      << (options.tracker.prediction.use_odometry ? ", wheel odometry in" : ", no wheel odometry")
      << (options.tracker.prediction.use_imu
              ? (options.tracker.prediction.imu.use_orientation ? ", IMU orientation in" : ", IMU rate in")
              : "")
      << ", queue " << options.queue_size;
  return out.str();
}

}  // namespace hglasm_odometry
