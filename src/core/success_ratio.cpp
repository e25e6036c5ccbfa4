#include "hglasm_odometry/core/success_ratio.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <memory>
#include <set>
#include <sstream>

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
TrialOutcome runTrial(ScanMatcher* matcher, const TrialPair& pair, const SuccessThresholds& thresholds,
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
  const Algorithm algorithm = matcher->options().algorithm;
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

// Median (the mean of the middle two for an even count); 0 when empty.
double median(std::vector<double> values) {
  if (values.empty()) return 0.0;
  const std::size_t middle = values.size() / 2;
  std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(middle), values.end());
  const double upper = values[middle];
  if (values.size() % 2 == 1) return upper;
  const double lower =
      *std::max_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(middle));
  return 0.5 * (lower + upper);
}

Tally runTrials(ScanMatcher* matcher, const std::vector<TrialPair>& pairs,
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

std::string gnuplotQuote(const std::string& text) {
  std::string quoted = "'";
  for (char c : text) {
    quoted += c;
    if (c == '\'') quoted += '\'';
  }
  return quoted + "'";
}

bool writeFile(const std::string& path, const std::string& content, std::string* error) {
  std::ofstream out(path);
  out << content;
  out.close();
  if (!out) {
    if (error) *error = "cannot write '" + path + "'";
    return false;
  }
  return true;
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
using Matchers = std::map<MatcherKey, std::unique_ptr<ScanMatcher>>;

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
        MatcherOptions matcher_options = base;
        matcher_options.algorithm = algorithm;
        matcher_options.genetic.generations = generations;
        ScanMatcher matcher(matcher_options);
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
      MatcherOptions matcher_options = presetOptions(preset);
      matcher_options.algorithm = algorithm;
      matchers[{algorithm, preset}] = std::make_unique<ScanMatcher>(matcher_options);
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

std::string successRatioCsvHeader() {
  return "algorithm,preset,rot_err_deg,trans_err_m,trials,successes,success_ratio,mean_dxy_m,mean_dth_deg,"
         "mean_ms,ceiling";
}

std::string successRatioCsvLine(const SuccessRatioRow& row) {
  std::string line = std::string(toString(row.algorithm)) + "," + toString(row.preset) + ",";
  if (row.in_box) {
    line += "box,box,";
  } else {
    line += formatNumber("%.10g", row.ipe.rotation_deg) + "," + formatNumber("%.10g", row.ipe.translation_m) +
            ",";
  }
  line += std::to_string(row.trials) + "," + std::to_string(row.successes) + "," +
          formatNumber("%.4f", row.success_ratio) + "," + formatNumber("%.5f", row.mean_dxy_m) + "," +
          formatNumber("%.4f", row.mean_dth_deg) + "," + formatNumber("%.4f", row.mean_ms) + ",";
  if (row.ceiling >= 0.0) line += formatNumber("%.4f", row.ceiling);
  return line;
}

std::string evaluationCurveCsvHeader() {
  return "algorithm,preset,population,generations,runs,trials,mean_evaluations,successes,success_ratio,"
         "mean_dxy_m,mean_dth_deg,mean_ms,median_dxy_m,median_dth_deg,mean_search_ms";
}

std::string evaluationCurveCsvLine(const EvaluationCurvePoint& point) {
  return std::string(toString(point.algorithm)) + "," + toString(point.preset) + "," +
         std::to_string(point.population) + "," + std::to_string(point.generations) + "," +
         std::to_string(point.runs) + "," + std::to_string(point.trials) + "," +
         formatNumber("%.1f", point.mean_evaluations) + "," + std::to_string(point.successes) + "," +
         formatNumber("%.4f", point.success_ratio) + "," + formatNumber("%.5f", point.mean_dxy_m) + "," +
         formatNumber("%.4f", point.mean_dth_deg) + "," + formatNumber("%.4f", point.mean_ms) + "," +
         formatNumber("%.5f", point.median_dxy_m) + "," + formatNumber("%.4f", point.median_dth_deg) + "," +
         formatNumber("%.4f", point.mean_search_ms);
}

std::string timeToReachCsvHeader() {
  return "algorithm,preset,level,reached,generations,mean_evaluations,success_ratio,search_ms,total_ms";
}

std::string timeToReachCsvLine(const TimeToReach& entry) {
  std::string line = std::string(toString(entry.algorithm)) + "," + toString(entry.preset) + "," +
                     formatNumber("%.2f", entry.level) + "," + (entry.reached ? "1" : "0") + ",";
  if (!entry.reached) return line + ",,,,";
  return line + std::to_string(entry.generations) + "," + formatNumber("%.1f", entry.evaluations) + "," +
         formatNumber("%.4f", entry.success_ratio) + "," + formatNumber("%.4f", entry.search_ms) + "," +
         formatNumber("%.4f", entry.total_ms);
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

bool writeTimeToReachCsv(const std::string& path, const std::vector<TimeToReach>& entries,
                         std::string* error) {
  std::string content = timeToReachCsvHeader() + "\n";
  for (const TimeToReach& entry : entries) content += timeToReachCsvLine(entry) + "\n";
  return writeFile(path, content, error);
}

Pose2D halfScanOffset(const Eigen::Vector3d& base_velocity, const Pose2D& base_to_laser, double seconds) {
  const Pose2D base_motion(base_velocity.x() * seconds, base_velocity.y() * seconds,
                           base_velocity.z() * seconds);
  const Pose2D laser_motion = base_to_laser.inverse() * base_motion * base_to_laser;
  return laser_motion.inverse();
}

bool writeSuccessRatioCsv(const std::string& path, const std::vector<SuccessRatioRow>& rows,
                          std::string* error) {
  std::string content = successRatioCsvHeader() + "\n";
  for (const SuccessRatioRow& row : rows) content += successRatioCsvLine(row) + "\n";
  return writeFile(path, content, error);
}

bool writeEvaluationCurveCsv(const std::string& path, const std::vector<EvaluationCurvePoint>& curve,
                             std::string* error) {
  std::string content = evaluationCurveCsvHeader() + "\n";
  for (const EvaluationCurvePoint& point : curve) content += evaluationCurveCsvLine(point) + "\n";
  return writeFile(path, content, error);
}

namespace {

// Figures 7/8: success ratio vs rotation error, one plot per (algorithm, preset).
bool writeRotationPlots(const SuccessRatioReport& report, const std::string& directory,
                        const std::string& prefix, std::vector<std::string>* scripts, std::string* error) {
  // Figures 7/8: success ratio vs rotation error, one curve per translation error.
  std::vector<std::pair<Algorithm, Preset>> groups;
  for (const SuccessRatioRow& row : report.rows) {
    if (row.in_box) continue;
    const std::pair<Algorithm, Preset> group{row.algorithm, row.preset};
    if (std::find(groups.begin(), groups.end(), group) == groups.end()) groups.push_back(group);
  }
  for (const auto& group : groups) {
    std::map<double, std::vector<const SuccessRatioRow*>> by_translation;
    std::set<double> rotations;
    int min_trials = 0;
    for (const SuccessRatioRow& row : report.rows) {
      if (row.in_box || row.algorithm != group.first || row.preset != group.second) continue;
      by_translation[row.ipe.translation_m].push_back(&row);
      rotations.insert(row.ipe.rotation_deg);
      min_trials = min_trials == 0 ? row.trials : std::min(min_trials, row.trials);
    }
    if (rotations.size() < 2) continue;
    const std::string stem = directory + "/success_" + toString(group.first) + "_" + toString(group.second);
    std::string data;
    std::string plot;
    int index = 0;
    for (auto& [translation, rows] : by_translation) {
      std::sort(rows.begin(), rows.end(), [](const SuccessRatioRow* a, const SuccessRatioRow* b) {
        return a->ipe.rotation_deg < b->ipe.rotation_deg;
      });
      data += "# translation error " + formatNumber("%g", translation) + " m: rot_err_deg success_percent\n";
      for (const SuccessRatioRow* row : rows) {
        data += formatNumber("%g", row->ipe.rotation_deg) + " " +
                formatNumber("%.3f", 100.0 * row->success_ratio) + "\n";
      }
      data += "\n\n";
      plot += std::string(index == 0 ? "plot " : ", \\\n     ") + gnuplotQuote(stem + ".dat") + " index " +
              std::to_string(index) + " using 1:2 with linespoints lw 2 pt 7 ps 0.8 title " +
              gnuplotQuote(formatNumber("%g", translation) + " m");
      ++index;
    }
    const std::string script =
        "set terminal pngcairo size 900,600 noenhanced font 'Sans,11'\n"
        "set output " +
        gnuplotQuote(stem + ".png") +
        "\n"
        "set title " +
        gnuplotQuote(prefix + toString(group.first) + ", " + toString(group.second) +
                     " preset: success ratio vs initial rotation error (" + std::to_string(min_trials) +
                     " trials per point)") +
        "\n"
        "set xlabel 'initial rotation error (deg)'\n"
        "set ylabel 'success ratio (%)'\n"
        "set xrange [0:180]\nset xtics 20\nset yrange [0:105]\nset ytics 10\nset grid\n"
        "set key outside below horizontal title 'initial translation error'\n" +
        plot + "\n";
    if (!writeFile(stem + ".dat", data, error) || !writeFile(stem + ".gp", script, error)) return false;
    scripts->push_back(stem + ".gp");
  }

  return true;
}

const char* curveTitle(Algorithm algorithm) {
  switch (algorithm) {
    case Algorithm::kGlasmG:
      return "GLASM-g (graded table)";
    case Algorithm::kGlasmBinary:
      return "GLASM (binary table)";
    case Algorithm::kPga:
      return "PGA (polar pairing)";
    default:
      return toString(algorithm);
  }
}

const char* curveStyle(Algorithm algorithm) {
  switch (algorithm) {
    case Algorithm::kGlasmG:
      return "lc rgb '#1f5fbf' pt 7";
    case Algorithm::kGlasmBinary:
      return "lc rgb '#c0392b' pt 5";
    default:
      return "lc rgb '#2e8b3a' pt 9";
  }
}

std::vector<Algorithm> curveAlgorithms(const std::vector<EvaluationCurvePoint>& curve) {
  std::vector<Algorithm> algorithms;
  for (const EvaluationCurvePoint& point : curve) {
    if (std::find(algorithms.begin(), algorithms.end(), point.algorithm) == algorithms.end())
      algorithms.push_back(point.algorithm);
  }
  return algorithms;
}

// One gnuplot data block per algorithm of `preset`'s curve; `blocks` receives the algorithms in order.
std::string curveData(const std::vector<EvaluationCurvePoint>& curve, Preset preset,
                      std::vector<Algorithm>* blocks) {
  std::string data;
  for (Algorithm algorithm : curveAlgorithms(curve)) {
    std::string block;
    for (const EvaluationCurvePoint& point : curve) {
      if (point.preset != preset || point.algorithm != algorithm) continue;
      block += formatNumber("%.1f", point.mean_evaluations) + " " +
               formatNumber("%.3f", 100.0 * point.success_ratio) + " " +
               formatNumber("%.5f", point.mean_dxy_m) + " " + formatNumber("%.4f", point.mean_dth_deg) + " " +
               formatNumber("%.4f", point.mean_ms) + " " + std::to_string(point.generations) + " " +
               formatNumber("%.5f", point.median_dxy_m) + " " + formatNumber("%.4f", point.median_dth_deg) +
               " " + formatNumber("%.4f", point.mean_search_ms) + "\n";
    }
    if (block.empty()) continue;
    data += std::string("# ") + toString(algorithm) +
            ": evaluations success_percent mean_dxy_m mean_dth_deg mean_ms generations median_dxy_m "
            "median_dth_deg mean_search_ms\n" +
            block + "\n\n";
    blocks->push_back(algorithm);
  }
  return data;
}

// Figure 5: per preset, success and mean / median translation and rotation errors vs fitness evaluations.
bool writeEvaluationPlot(const SuccessRatioReport& report, Preset preset, const std::string& directory,
                         const std::string& prefix, std::vector<std::string>* scripts, std::string* error) {
  const std::string stem = directory + "/evaluations_" + toString(preset);
  std::vector<Algorithm> blocks;
  const std::string data = curveData(report.curve, preset, &blocks);
  int population = 0, runs = 0, trials = 0, min_generations = 0, max_generations = 0;
  double max_evaluations = 0.0, preset_evaluations = 0.0;
  const int preset_generations = presetOptions(preset).genetic.generations;
  for (const EvaluationCurvePoint& point : report.curve) {
    if (point.preset != preset) continue;
    population = point.population;
    runs = point.runs;
    trials = point.trials;
    min_generations = min_generations == 0 ? point.generations : std::min(min_generations, point.generations);
    max_generations = std::max(max_generations, point.generations);
    max_evaluations = std::max(max_evaluations, point.mean_evaluations);
    if (point.generations == preset_generations) preset_evaluations = point.mean_evaluations;
  }
  // Thousands keep the tick labels of the large preset (up to ~10^4 evaluations) apart.
  const bool thousands = max_evaluations >= 2000.0;
  const double scale = thousands ? 1000.0 : 1.0;
  const std::string x_column = thousands ? "($1/1000)" : "1";
  std::string marker;  // dashed line at the preset's own GA size (Table 1)
  if (preset_evaluations > 0.0) {
    const std::string x = formatNumber("%g", preset_evaluations / scale);
    marker = "set arrow 1 from " + x + ", graph 0 to " + x + ", graph 1 nohead dt 2 lc rgb 'gray40'\n";
  }
  // Mean: solid; median: dashed, same colour.
  auto plot_columns = [&](int mean_column, int median_column) {
    std::string plot = "plot ";
    for (std::size_t i = 0; i < blocks.size(); ++i) {
      const std::string source =
          gnuplotQuote(stem + ".dat") + " index " + std::to_string(i) + " using " + x_column + ":";
      plot += (i == 0 ? "" : ", ") + source + std::to_string(mean_column) + " with linespoints lw 2 " +
              curveStyle(blocks[i]) + " title " +
              gnuplotQuote(std::string(curveTitle(blocks[i])) + (median_column > 0 ? " mean" : ""));
      if (median_column > 0) {
        plot += ", " + source + std::to_string(median_column) + " with linespoints lw 2 dt 2 " +
                curveStyle(blocks[i]) + " title " +
                gnuplotQuote(std::string(curveTitle(blocks[i])) + " median");
      }
    }
    return plot + "\n";
  };
  const std::string script =
      "set terminal pngcairo size 1650,560 noenhanced font 'Sans,11'\nset output " +
      gnuplotQuote(stem + ".png") + "\nset multiplot layout 1,3 title " +
      gnuplotQuote(prefix + toString(preset) + " preset box, GA alone (population " +
                   std::to_string(population) + ", " + std::to_string(runs) + " run(s), " +
                   std::to_string(min_generations) + ".." + std::to_string(max_generations) +
                   " generations; dashed vertical: Table 1 size), errors uniform " + "in the box, " +
                   std::to_string(trials) + " trials per point; success = 0.30 m and 0.1 rad") +
      "\nset grid\nset xlabel " +
      gnuplotQuote(thousands ? "fitness evaluations per match (thousands)"
                             : "fitness evaluations per match") +
      "\nset key bottom right\n" + marker +
      "set title 'pre-alignment success ratio'\nset ylabel 'success ratio (%)'\nset yrange [0:105]\n" +
      plot_columns(2, 0) +
      "set title 'translation error (solid: mean, dashed: median)'\nset ylabel '|dxy| (m)'\nset logscale y\n"
      "set yrange [*:*]\nset key top right font ',9'\n" +
      plot_columns(3, 7) +
      "set title 'rotation error (solid: mean, dashed: median)'\nset ylabel '|dtheta| (deg)'\n" +
      plot_columns(4, 8) + "unset multiplot\n";
  if (!writeFile(stem + ".dat", data, error) || !writeFile(stem + ".gp", script, error)) return false;
  scripts->push_back(stem + ".gp");
  return true;
}

// Figure 6: time per match to reach each success level, one bar per algorithm, preparation excluded (left)
// and included (right), one row per preset of the curves.
bool writeTimeToReachPlot(const SuccessRatioReport& report, const std::string& directory,
                          const std::string& prefix, std::vector<std::string>* scripts, std::string* error) {
  const std::vector<TimeToReach> entries = timeToReach(report.curve, timeToReachLevels());
  const std::vector<Algorithm> algorithms = curveAlgorithms(report.curve);
  std::vector<Preset> presets;
  for (const EvaluationCurvePoint& point : report.curve) {
    if (std::find(presets.begin(), presets.end(), point.preset) == presets.end())
      presets.push_back(point.preset);
  }
  const std::string stem = directory + "/time_to_reach";
  std::string data;
  for (Preset preset : presets) {
    data += std::string("# ") + toString(preset) +
            ": level, then per algorithm search_ms total_ms ('?': not reached)\n";
    for (double level : timeToReachLevels()) {
      data += formatNumber("%.0f%%", 100.0 * level);
      for (Algorithm algorithm : algorithms) {
        for (const TimeToReach& entry : entries) {
          if (entry.preset != preset || entry.algorithm != algorithm || entry.level != level) continue;
          data += entry.reached ? " " + formatNumber("%.4f", entry.search_ms) + " " +
                                      formatNumber("%.4f", entry.total_ms)
                                : std::string(" ? ?");
        }
      }
      data += "\n";
    }
    data += "\n\n";
  }
  std::string script =
      "set terminal pngcairo size 1400," + std::to_string(120 + 380 * presets.size()) +
      " noenhanced font 'Sans,11'\nset output " + gnuplotQuote(stem + ".png") + "\nset multiplot layout " +
      std::to_string(presets.size()) + ",2 title " +
      gnuplotQuote(prefix +
                   "GA alone: ms per match to reach a pre-alignment success ratio (fewest "
                   "generations reaching it; no bar: not reached)") +
      "\nset style data histogram\nset style histogram clustered gap 1\nset style fill solid 0.85 "
      "border -1\nset datafile missing '?'\nset logscale y\nset grid ytics\nset yrange [0.01:*]\n"
      "set key above horizontal\nset xlabel 'success ratio reached'\nset ylabel 'ms per match (log)'\n";
  for (std::size_t p = 0; p < presets.size(); ++p) {
    for (int included = 0; included < 2; ++included) {
      script += "set title " +
                gnuplotQuote(std::string(toString(presets[p])) + " preset, " +
                             (included ? "reference preparation included"
                                       : "reference preparation excluded (as the papers)")) +
                "\nplot ";
      for (std::size_t a = 0; a < algorithms.size(); ++a) {
        const int column = 2 + 2 * static_cast<int>(a) + included;
        std::string colour = curveStyle(algorithms[a]);
        colour = colour.substr(0, colour.find(" pt"));
        script += (a == 0 ? "" : ", ") + gnuplotQuote(stem + ".dat") + " index " + std::to_string(p) +
                  " using " + std::to_string(column) + ":xtic(1) " + colour + " title " +
                  gnuplotQuote(curveTitle(algorithms[a]));
      }
      script += "\n";
    }
  }
  script += "unset multiplot\n";
  if (!writeFile(stem + ".dat", data, error) || !writeFile(stem + ".gp", script, error)) return false;
  scripts->push_back(stem + ".gp");
  return true;
}

}  // namespace

bool writeSuccessRatioPlotScripts(const SuccessRatioReport& report, const std::string& directory,
                                  const std::string& title, std::vector<std::string>* scripts,
                                  std::string* error) {
  scripts->clear();
  const std::string prefix = title.empty() ? "" : title + ": ";
  if (!writeRotationPlots(report, directory, prefix, scripts, error)) return false;
  std::vector<Preset> presets;
  for (const EvaluationCurvePoint& point : report.curve) {
    if (std::find(presets.begin(), presets.end(), point.preset) == presets.end())
      presets.push_back(point.preset);
  }
  for (Preset preset : presets) {
    if (!writeEvaluationPlot(report, preset, directory, prefix, scripts, error)) return false;
  }
  if (!report.curve.empty() && !writeTimeToReachPlot(report, directory, prefix, scripts, error)) return false;
  return true;
}

}  // namespace hglasm
