#include "hglasm_odometry/evaluation/success_ratio.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>
#include <memory>
#include <sstream>

#include "hglasm_odometry/evaluation/statistics.h"

namespace hglasm {
namespace {

constexpr double kDegToRad = M_PI / 180.0;
constexpr double kRadToDeg = 180.0 / M_PI;
// Stream tags: keep the draws of fixed cases, in-box trials and GA seeds independent of each other.
constexpr std::uint64_t kCaseTag = 0x43415345ULL;  // "CASE"
constexpr std::uint64_t kBoxTag = 0x424f58ULL;     // "BOX"
constexpr std::uint64_t kGaTag = 0x4741ULL;        // "GA"

// SplitMix64 (Steele, Lea, Flood 2014): a tiny, well-mixed generator that is identical on every
// platform (std:: distributions are not), used to derive every random number of the protocol.
std::uint64_t splitMix(std::uint64_t value) {
  value += 0x9e3779b97f4a7c15ULL;
  value = (value ^ (value >> 30)) * 0xbf58476d1ce4e5b9ULL;
  value = (value ^ (value >> 27)) * 0x94d049bb133111ebULL;
  return value ^ (value >> 31);
}

std::uint64_t mix(std::uint64_t a, std::uint64_t b) { return splitMix(a ^ splitMix(b)); }

class TrialRandom {
 public:
  explicit TrialRandom(std::uint64_t state) : state_(state) {}
  std::uint64_t next() {
    state_ += 0x9e3779b97f4a7c15ULL;
    return splitMix(state_);
  }
  double uniform01() { return static_cast<double>(next() >> 11) * 0x1.0p-53; }  // [0, 1)
  std::size_t index(std::size_t count) { return static_cast<std::size_t>(next() % count); }

 private:
  std::uint64_t state_;
};

std::uint64_t caseKey(const IpeCase& ipe, std::uint64_t seed) {
  // Rounded so that "20:0.57" parsed from text and 20.0/0.57 in code draw the same trials.
  const auto rot = static_cast<std::uint64_t>(std::llround(ipe.rotation_deg * 1e3));
  const auto trans = static_cast<std::uint64_t>(std::llround(ipe.translation_m * 1e6));
  return mix(mix(mix(seed, kCaseTag), rot), trans);
}

std::uint64_t trialState(std::uint64_t key, int trial) { return mix(key, static_cast<std::uint64_t>(trial)); }

std::string formatNumber(const char* format, double value) {
  char buffer[64];
  std::snprintf(buffer, sizeof(buffer), format, value);
  return buffer;
}

std::string caseLabel(const SuccessRatioRow& row) {
  if (row.in_box) return "box";
  return formatNumber("%g", row.ipe.rotation_deg) + "deg/" + formatNumber("%g", row.ipe.translation_m) + "m";
}

// One prepared trial: the pair and its exact answer.
struct TrialPair {
  Scan reference;  // odd beams, sensor frame
  Scan moved;      // even beams seen from the displaced sensor
  Pose2D truth;    // the displacement = the IPE
  std::uint64_t ga_seed = 0;
};

struct UsableScans {
  std::vector<std::size_t> indices;  // into the caller's scans
};

// `half_offset`: the even half's sensor in the odd half's frame (identity when both halves are one instant).
TrialPair makePair(const RangeScan& ranges, const ScanConversionOptions& conversion, const Pose2D& error,
                   const Pose2D& half_offset, std::uint64_t state) {
  TrialPair pair;
  const Scan scan = scanFromRanges(ranges, conversion);
  pair.reference = selectBeams(scan, 1);
  pair.moved = transformScan(selectBeams(scan, 0), error.inverse());
  pair.truth = half_offset * error;
  pair.ga_seed = mix(state, kGaTag);
  return pair;
}

Pose2D halfOffsetOf(const SuccessRatioOptions& options, std::size_t scan_index) {
  return options.half_offsets.empty() ? Pose2D() : options.half_offsets[scan_index];
}

std::vector<TrialPair> casePairs(const std::vector<RangeScan>& scans, const UsableScans& usable,
                                 const SuccessRatioOptions& options, const IpeCase& ipe, int trials) {
  std::vector<TrialPair> pairs;
  pairs.reserve(static_cast<std::size_t>(trials));
  const std::uint64_t key = caseKey(ipe, options.seed);
  for (int trial = 0; trial < trials; ++trial) {
    std::size_t pick = 0;
    const Pose2D error = caseTrialError(ipe, options.seed, trial, usable.indices.size(), &pick);
    const std::size_t scan_index = usable.indices[pick];
    pairs.push_back(makePair(scans[scan_index], options.conversion, error, halfOffsetOf(options, scan_index),
                             trialState(key, trial)));
  }
  return pairs;
}

std::vector<TrialPair> boxPairs(const std::vector<RangeScan>& scans, const UsableScans& usable,
                                const SuccessRatioOptions& options, const SearchBox& box, int trials) {
  std::vector<TrialPair> pairs;
  pairs.reserve(static_cast<std::size_t>(trials));
  const std::uint64_t key = mix(options.seed, kBoxTag);
  for (int trial = 0; trial < trials; ++trial) {
    std::size_t pick = 0;
    const Pose2D error = boxTrialError(box, options.seed, trial, usable.indices.size(), &pick);
    const std::size_t scan_index = usable.indices[pick];
    pairs.push_back(makePair(scans[scan_index], options.conversion, error, halfOffsetOf(options, scan_index),
                             trialState(key, trial)));
  }
  return pairs;
}

struct TrialOutcome {
  bool success = false;
  bool failed_status = false;
  double dxy = 0.0;
  double dth = 0.0;
  double ms = 0.0;
  double preparation_ms = 0.0;  // lookup tables (coarse included) or PGA's angular sort
  int evaluations = 0;
};

bool usableStatus(MatchStatus status) {
  return status == MatchStatus::kOk || status == MatchStatus::kMbicpNotConverged;
}

// `prealign_only`: judge the GA's pose with the pre-alignment thresholds (curves); otherwise the final
// pose with the thresholds of the algorithm.
TrialOutcome runTrial(BaselineMatcher* matcher, const TrialPair& pair, const SuccessThresholds& thresholds,
                      bool prealign_only) {
  matcher->reseed(pair.ga_seed);
  const auto start = std::chrono::steady_clock::now();
  matcher->setReference(pair.reference);
  const MatchResult result = matcher->match(pair.moved, Pose2D());
  const auto stop = std::chrono::steady_clock::now();

  TrialOutcome outcome;
  outcome.ms = std::chrono::duration<double, std::milli>(stop - start).count();
  outcome.preparation_ms = matcher->lastTableBuildMs() + matcher->lastCoarseTableBuildMs();
  outcome.evaluations = result.evaluations;
  const Algorithm algorithm = matcher->algorithm();
  const bool judge_prealigned = prealign_only || !usesMbicpStage(algorithm);
  const Pose2D estimate = prealign_only ? result.prealigned_pose : result.pose;
  outcome.failed_status = !usableStatus(result.status);
  if (estimate.isFinite()) {
    outcome.dxy = std::hypot(estimate.x - pair.truth.x, estimate.y - pair.truth.y);
    outcome.dth = std::abs(normalizeAngle(estimate.theta - pair.truth.theta));
  } else {
    // Never expected (the matcher promises finite numbers): count it as the error of not moving.
    outcome.failed_status = true;
    outcome.dxy = pair.truth.translationNorm();
    outcome.dth = std::abs(pair.truth.theta);
  }
  const double max_xy = judge_prealigned ? thresholds.prealign_xy : thresholds.refined_xy;
  const double max_th = judge_prealigned ? thresholds.prealign_theta : thresholds.refined_theta;
  outcome.success = !outcome.failed_status && outcome.dxy < max_xy && outcome.dth < max_th;
  return outcome;
}

struct Tally {
  int trials = 0;
  int successes = 0;
  int failed_status = 0;
  double sum_dxy = 0.0;
  double sum_dth = 0.0;
  double sum_ms = 0.0;
  double sum_preparation_ms = 0.0;
  double sum_evaluations = 0.0;
  std::vector<double> dxy;  // per trial, for the medians
  std::vector<double> dth;

  void add(const TrialOutcome& outcome) {
    sum_preparation_ms += outcome.preparation_ms;
    dxy.push_back(outcome.dxy);
    dth.push_back(outcome.dth);
    ++trials;
    successes += outcome.success ? 1 : 0;
    failed_status += outcome.failed_status ? 1 : 0;
    sum_dxy += outcome.dxy;
    sum_dth += outcome.dth;
    sum_ms += outcome.ms;
    sum_evaluations += outcome.evaluations;
  }
  double mean(double sum) const { return trials > 0 ? sum / trials : 0.0; }
  double ratio() const { return trials > 0 ? static_cast<double>(successes) / trials : 0.0; }
};

Tally runTrials(BaselineMatcher* matcher, const std::vector<TrialPair>& pairs,
                const SuccessThresholds& thresholds, bool prealign_only) {
  Tally tally;
  for (const TrialPair& pair : pairs) tally.add(runTrial(matcher, pair, thresholds, prealign_only));
  return tally;
}

SuccessRatioRow makeRow(Algorithm algorithm, Preset preset, bool in_box, const IpeCase& ipe,
                        const Tally& tally) {
  SuccessRatioRow row;
  row.algorithm = algorithm;
  row.preset = preset;
  row.in_box = in_box;
  row.ipe = in_box ? IpeCase() : ipe;
  row.trials = tally.trials;
  row.successes = tally.successes;
  row.success_ratio = tally.trials > 0 ? static_cast<double>(tally.successes) / tally.trials : 0.0;
  row.mean_dxy_m = tally.mean(tally.sum_dxy);
  row.mean_dth_deg = tally.mean(tally.sum_dth) * kRadToDeg;
  row.mean_ms = tally.mean(tally.sum_ms);
  row.failed_status = tally.failed_status;
  row.mean_evaluations = tally.mean(tally.sum_evaluations);
  return row;
}

std::string rowMessage(const SuccessRatioRow& row) {
  char buffer[256];
  std::snprintf(
      buffer, sizeof(buffer), "%-13s %-6s %-12s %4d/%-4d = %5.1f%%  dxy %.3f m  dth %.2f deg  %.2f ms%s",
      toString(row.algorithm), toString(row.preset), caseLabel(row).c_str(), row.successes, row.trials,
      100.0 * row.success_ratio, row.mean_dxy_m, row.mean_dth_deg, row.mean_ms,
      row.failed_status > 0 ? (" (" + std::to_string(row.failed_status) + " failed status)").c_str() : "");
  return buffer;
}

std::vector<int> curveGenerations(const SuccessRatioOptions& options, int preset_generations) {
  if (!options.curve_generations.empty()) return options.curve_generations;
  std::vector<int> generations;
  for (int g : {1, 2, 3, 4, 6, 8, 10, 12, 16, 20, 24}) {
    if (g <= 2 * preset_generations) generations.push_back(g);
  }
  return generations;
}

bool validate(const SuccessRatioOptions& options, std::string* error) {
  if (options.algorithms.empty()) {
    *error = "no algorithm selected";
  } else if (options.presets.empty()) {
    *error = "no preset selected";
  } else if (options.cases.empty() && !options.in_box && options.curve_trials <= 0) {
    *error = "nothing to run: no cases, no in-box trials, no evaluation curves";
  } else if (options.trials <= 0 && (!options.cases.empty() || options.in_box)) {
    *error = "trials must be positive";
  } else if (options.curve_trials < 0) {
    *error = "curve trials must be >= 0";
  } else if (options.min_points_per_half < 3) {
    *error = "min points per half-scan must be >= 3";
  } else {
    for (const IpeCase& ipe : options.cases) {
      if (!std::isfinite(ipe.rotation_deg) || !std::isfinite(ipe.translation_m) || ipe.rotation_deg < 0.0 ||
          ipe.rotation_deg > 180.0 || ipe.translation_m < 0.0) {
        *error = "invalid case " + formatNumber("%g", ipe.rotation_deg) + ":" +
                 formatNumber("%g", ipe.translation_m) + " (rotation in [0, 180] deg, translation >= 0 m)";
        return false;
      }
    }
    for (int g : options.curve_generations) {
      if (g < 1) {
        *error = "curve generations must be >= 1";
        return false;
      }
    }
    return true;
  }
  return false;
}

template <typename T>
std::size_t positionOf(const std::vector<T>& list, const T& value) {
  return static_cast<std::size_t>(std::find(list.begin(), list.end(), value) - list.begin());
}

}  // namespace

std::vector<IpeCase> paperCases() {
  std::vector<IpeCase> cases;
  for (double rotation : {0, 10, 20, 30, 40, 50, 60, 80, 100, 120, 140, 160, 180}) {
    for (double translation : {0.14, 0.57, 1.13, 2.12}) cases.push_back({rotation, translation});
  }
  return cases;
}

bool parseCases(const std::string& text, std::vector<IpeCase>* cases, std::string* error) {
  cases->clear();
  if (text == "paper") {
    *cases = paperCases();
    return true;
  }
  if (text == "none") return true;
  std::stringstream stream(text);
  std::string item;
  while (std::getline(stream, item, ',')) {
    const std::size_t colon = item.find(':');
    IpeCase ipe;
    bool ok = colon != std::string::npos;
    if (ok) {
      const std::string rotation = item.substr(0, colon);
      const std::string translation = item.substr(colon + 1);
      char* end = nullptr;
      ipe.rotation_deg = std::strtod(rotation.c_str(), &end);
      ok = !rotation.empty() && *end == '\0';
      ipe.translation_m = std::strtod(translation.c_str(), &end);
      ok = ok && !translation.empty() && *end == '\0';
    }
    ok = ok && std::isfinite(ipe.rotation_deg) && std::isfinite(ipe.translation_m) &&
         ipe.rotation_deg >= 0.0 && ipe.rotation_deg <= 180.0 && ipe.translation_m >= 0.0;
    if (!ok) {
      if (error) {
        *error =
            "bad case '" + item + "': expected ROT_DEG:TRANS_M with 0 <= ROT_DEG <= 180 and TRANS_M >= 0";
      }
      cases->clear();
      return false;
    }
    cases->push_back(ipe);
  }
  if (cases->empty()) {
    if (error) *error = "no cases in '" + text + "'";
    return false;
  }
  return true;
}

Pose2D caseTrialError(const IpeCase& ipe, std::uint64_t seed, int trial, std::size_t scan_count,
                      std::size_t* scan_index) {
  TrialRandom random(trialState(caseKey(ipe, seed), trial));
  const std::size_t pick = random.index(std::max<std::size_t>(scan_count, 1));
  if (scan_index) *scan_index = pick;
  const double direction = 2.0 * M_PI * random.uniform01();
  const double sign = (random.next() & 1U) != 0 ? -1.0 : 1.0;
  return Pose2D(ipe.translation_m * std::cos(direction), ipe.translation_m * std::sin(direction),
                sign * ipe.rotation_deg * kDegToRad);
}

Pose2D boxTrialError(const SearchBox& box, std::uint64_t seed, int trial, std::size_t scan_count,
                     std::size_t* scan_index) {
  TrialRandom random(trialState(mix(seed, kBoxTag), trial));
  const std::size_t pick = random.index(std::max<std::size_t>(scan_count, 1));
  if (scan_index) *scan_index = pick;
  const double x = box.half_x * (2.0 * random.uniform01() - 1.0);
  const double y = box.half_y * (2.0 * random.uniform01() - 1.0);
  const double theta = box.half_theta * (2.0 * random.uniform01() - 1.0);
  return Pose2D(x, y, theta);
}

namespace {

// The scans whose odd and even halves both have enough valid points.
UsableScans usableScans(const std::vector<RangeScan>& scans, const SuccessRatioOptions& options) {
  UsableScans usable;
  for (std::size_t i = 0; i < scans.size(); ++i) {
    ScanError scan_error = ScanError::kNone;
    const Scan scan = scanFromRanges(scans[i], options.conversion, &scan_error);
    const std::size_t minimum = static_cast<std::size_t>(options.min_points_per_half);
    if (scan_error == ScanError::kNone && selectBeams(scan, 0).size() >= minimum &&
        selectBeams(scan, 1).size() >= minimum) {
      usable.indices.push_back(i);
    }
  }
  return usable;
}

using MatcherKey = std::pair<Algorithm, Preset>;
using Matchers = std::map<MatcherKey, std::unique_ptr<BaselineMatcher>>;

struct ProgressState {
  SuccessRatioProgress state;
  const SuccessRatioProgressCallback* callback = nullptr;
  void cell(const std::string& message) {
    ++state.cells_done;
    state.message = message;
    if (callback && *callback) (*callback)(state);
  }
};

EvaluationCurvePoint curvePoint(Algorithm algorithm, Preset preset, const GeneticOptions& genetic,
                                int generations, const Tally& tally) {
  EvaluationCurvePoint point;
  point.algorithm = algorithm;
  point.preset = preset;
  point.population = genetic.population;
  point.generations = generations;
  point.runs = genetic.runs;
  point.trials = tally.trials;
  point.successes = tally.successes;
  point.success_ratio = tally.ratio();
  point.mean_evaluations = tally.mean(tally.sum_evaluations);
  point.mean_dxy_m = tally.mean(tally.sum_dxy);
  point.mean_dth_deg = tally.mean(tally.sum_dth) * kRadToDeg;
  point.mean_ms = tally.mean(tally.sum_ms);
  point.median_dxy_m = median(tally.dxy);
  point.median_dth_deg = median(tally.dth) * kRadToDeg;
  point.mean_search_ms = tally.mean(tally.sum_ms - tally.sum_preparation_ms);
  return point;
}

// Figures 5/6: the GA alone at the preset's population and runs, with more and more generations.
void runCurves(const std::vector<RangeScan>& scans, const UsableScans& usable,
               const SuccessRatioOptions& options, SuccessRatioReport* report, ProgressState* progress) {
  for (Preset preset : options.presets) {
    const MatcherOptions base = presetOptions(preset);
    const std::vector<TrialPair> pairs =
        boxPairs(scans, usable, options, base.genetic.box, options.curve_trials);
    for (Algorithm algorithm : options.curve_algorithms) {
      for (int generations : curveGenerations(options, base.genetic.generations)) {
        BaselineOptions matcher_options = baselineOptions(algorithm, preset);
        matcher_options.matcher.genetic.generations = generations;
        BaselineMatcher matcher(matcher_options);
        const Tally tally = runTrials(&matcher, pairs, options.thresholds, true);
        const EvaluationCurvePoint point = curvePoint(algorithm, preset, base.genetic, generations, tally);
        report->curve.push_back(point);
        char buffer[240];
        std::snprintf(buffer, sizeof(buffer),
                      "curve %-12s %-6s gen %2d (%6.0f evals) %4d/%-4d = %5.1f%%  dxy %.3f m  dth %.2f deg  "
                      "%.2f ms",
                      toString(algorithm), toString(preset), generations, point.mean_evaluations,
                      point.successes, point.trials, 100.0 * point.success_ratio, point.mean_dxy_m,
                      point.mean_dth_deg, point.mean_ms);
        progress->cell(buffer);
      }
    }
  }
}

// The fixed cases, then the in-box trials, in algorithm, preset (option order), case order.
void runRows(const std::vector<RangeScan>& scans, const UsableScans& usable,
             const SuccessRatioOptions& options, Matchers& matchers, ProgressState* progress,
             SuccessRatioReport* report) {
  // Rows are computed case by case (each case's pairs are built once and shared by all matchers).
  struct KeyedRow {
    std::size_t algorithm, preset, case_index;
    SuccessRatioRow row;
  };
  std::vector<KeyedRow> keyed;
  for (std::size_t c = 0; c < options.cases.size(); ++c) {
    const std::vector<TrialPair> pairs = casePairs(scans, usable, options, options.cases[c], options.trials);
    for (Preset preset : options.presets) {
      for (Algorithm algorithm : options.algorithms) {
        const Tally tally = runTrials(matchers[{algorithm, preset}].get(), pairs, options.thresholds, false);
        keyed.push_back({positionOf(options.algorithms, algorithm), positionOf(options.presets, preset), c,
                         makeRow(algorithm, preset, false, options.cases[c], tally)});
        progress->cell(rowMessage(keyed.back().row));
      }
    }
  }
  if (options.in_box) {
    for (Preset preset : options.presets) {
      const SearchBox box = presetOptions(preset).genetic.box;
      const std::vector<TrialPair> pairs = boxPairs(scans, usable, options, box, options.trials);
      for (Algorithm algorithm : options.algorithms) {
        const Tally tally = runTrials(matchers[{algorithm, preset}].get(), pairs, options.thresholds, false);
        keyed.push_back({positionOf(options.algorithms, algorithm), positionOf(options.presets, preset),
                         options.cases.size(), makeRow(algorithm, preset, true, IpeCase(), tally)});
        progress->cell(rowMessage(keyed.back().row));
      }
    }
  }
  std::stable_sort(keyed.begin(), keyed.end(), [](const KeyedRow& a, const KeyedRow& b) {
    if (a.algorithm != b.algorithm) return a.algorithm < b.algorithm;
    if (a.preset != b.preset) return a.preset < b.preset;
    return a.case_index < b.case_index;
  });
  for (const KeyedRow& k : keyed) report->rows.push_back(k.row);
}

// The ceiling of every (algorithm, preset): success at zero initial error, the trials of the case 0:0.
std::map<MatcherKey, Tally> runCeilings(const std::vector<RangeScan>& scans, const UsableScans& usable,
                                        const SuccessRatioOptions& options, Matchers& matchers,
                                        ProgressState* progress) {
  std::map<MatcherKey, Tally> ceilings;
  if (!options.ceiling) return ceilings;
  const IpeCase zero;
  const std::vector<TrialPair> pairs = casePairs(scans, usable, options, zero, options.trials);
  for (Preset preset : options.presets) {
    for (Algorithm algorithm : options.algorithms) {
      const Tally tally = runTrials(matchers[{algorithm, preset}].get(), pairs, options.thresholds, false);
      ceilings[{algorithm, preset}] = tally;
      char buffer[160];
      std::snprintf(buffer, sizeof(buffer), "%-13s %-6s ceiling (IPE 0) %4d/%-4d = %5.1f%%",
                    toString(algorithm), toString(preset), tally.successes, tally.trials,
                    100.0 * tally.ratio());
      progress->cell(buffer);
    }
  }
  return ceilings;
}

}  // namespace

bool runSuccessRatio(const std::vector<RangeScan>& scans, const SuccessRatioOptions& options,
                     SuccessRatioReport* report, std::string* error,
                     const SuccessRatioProgressCallback& progress) {
  *report = SuccessRatioReport();
  std::string local_error;
  if (!error) error = &local_error;
  if (!validate(options, error)) return false;
  if (!options.half_offsets.empty() && options.half_offsets.size() != scans.size()) {
    *error = "half-scan offsets: " + std::to_string(options.half_offsets.size()) + " for " +
             std::to_string(scans.size()) + " scans";
    return false;
  }

  const UsableScans usable = usableScans(scans, options);
  report->scans_total = scans.size();
  report->scans_used = usable.indices.size();
  report->scans_skipped = scans.size() - usable.indices.size();
  if (usable.indices.empty()) {
    *error = "none of the " + std::to_string(scans.size()) + " scans has " +
             std::to_string(options.min_points_per_half) + " valid points in both its odd and even beams";
    return false;
  }

  // One matcher per (algorithm, preset): the GA and MbICP buffers are reused across trials.
  Matchers matchers;
  for (Algorithm algorithm : options.algorithms) {
    for (Preset preset : options.presets) {
      matchers[{algorithm, preset}] = std::make_unique<BaselineMatcher>(baselineOptions(algorithm, preset));
    }
  }

  ProgressState tracker;
  tracker.callback = &progress;
  const std::size_t cells_per_case = options.algorithms.size() * options.presets.size();
  tracker.state.cells_total =
      cells_per_case * (options.cases.size() + (options.in_box ? 1 : 0) + (options.ceiling ? 1 : 0));
  if (options.curve_trials > 0) {
    for (Preset preset : options.presets) {
      tracker.state.cells_total +=
          options.curve_algorithms.size() *
          curveGenerations(options, presetOptions(preset).genetic.generations).size();
    }
  }
  const std::map<MatcherKey, Tally> ceilings = runCeilings(scans, usable, options, matchers, &tracker);
  runRows(scans, usable, options, matchers, &tracker, report);
  for (SuccessRatioRow& row : report->rows) {
    const auto found = ceilings.find({row.algorithm, row.preset});
    if (found == ceilings.end()) continue;
    row.ceiling = found->second.ratio();
    row.ceiling_successes = found->second.successes;
    row.ceiling_trials = found->second.trials;
  }
  if (options.curve_trials > 0) runCurves(scans, usable, options, report, &tracker);
  return true;
}

std::vector<double> timeToReachLevels() { return {0.50, 0.70, 0.80, 0.90, 0.95}; }

std::vector<TimeToReach> timeToReach(const std::vector<EvaluationCurvePoint>& curve,
                                     const std::vector<double>& levels) {
  std::vector<std::pair<Preset, Algorithm>> groups;
  for (const EvaluationCurvePoint& point : curve) {
    const std::pair<Preset, Algorithm> group{point.preset, point.algorithm};
    if (std::find(groups.begin(), groups.end(), group) == groups.end()) groups.push_back(group);
  }
  std::vector<TimeToReach> entries;
  for (const auto& [preset, algorithm] : groups) {
    for (double level : levels) {
      TimeToReach entry;
      entry.algorithm = algorithm;
      entry.preset = preset;
      entry.level = level;
      for (const EvaluationCurvePoint& point : curve) {
        if (point.preset != preset || point.algorithm != algorithm || point.success_ratio < level) continue;
        if (entry.reached && point.generations >= entry.generations) continue;
        entry.reached = true;
        entry.generations = point.generations;
        entry.evaluations = point.mean_evaluations;
        entry.success_ratio = point.success_ratio;
        entry.search_ms = point.mean_search_ms;
        entry.total_ms = point.mean_ms;
      }
      entries.push_back(entry);
    }
  }
  return entries;
}

Pose2D halfScanOffset(const Eigen::Vector3d& base_velocity, const Pose2D& base_to_laser, double seconds) {
  const Pose2D base_motion(base_velocity.x() * seconds, base_velocity.y() * seconds,
                           base_velocity.z() * seconds);
  const Pose2D laser_motion = base_to_laser.inverse() * base_motion * base_to_laser;
  return laser_motion.inverse();
}

}  // namespace hglasm
