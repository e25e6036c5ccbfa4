// Output of the Success-Ratio protocol: CSV rows and gnuplot data + scripts of the papers' figures.
#include "hglasm_odometry/evaluation/success_ratio_report.h"

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <map>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "hglasm_odometry/evaluation/gnuplot.h"

namespace hglasm {
namespace {

std::string formatNumber(const char* format, double value) {
  char buffer[64];
  std::snprintf(buffer, sizeof(buffer), format, value);
  return buffer;
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

bool writeTimeToReachCsv(const std::string& path, const std::vector<TimeToReach>& entries,
                         std::string* error) {
  std::string content = timeToReachCsvHeader() + "\n";
  for (const TimeToReach& entry : entries) content += timeToReachCsvLine(entry) + "\n";
  return writeFile(path, content, error);
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
