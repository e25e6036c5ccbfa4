// Output of the Success-Ratio protocol (success_ratio.h): the CSV rows and the gnuplot data files and
// scripts of the papers' figures. Only writes files; running gnuplot is the caller's choice.
#pragma once

#include <string>
#include <vector>

#include "hglasm_odometry/evaluation/success_ratio.h"

namespace hglasm {

/// `algorithm,preset,rot_err_deg,trans_err_m,trials,successes,success_ratio,mean_dxy_m,mean_dth_deg,mean_ms,
/// ceiling` (ceiling empty when not run)
std::string successRatioCsvHeader();
std::string successRatioCsvLine(const SuccessRatioRow& row);
std::string evaluationCurveCsvHeader();
std::string evaluationCurveCsvLine(const EvaluationCurvePoint& point);
std::string timeToReachCsvHeader();
std::string timeToReachCsvLine(const TimeToReach& entry);

/// Writes header + rows. False (with *error) if the file cannot be written.
bool writeSuccessRatioCsv(const std::string& path, const std::vector<SuccessRatioRow>& rows,
                          std::string* error);
bool writeEvaluationCurveCsv(const std::string& path, const std::vector<EvaluationCurvePoint>& curve,
                             std::string* error);
bool writeTimeToReachCsv(const std::string& path, const std::vector<TimeToReach>& entries,
                         std::string* error);

/// Writes gnuplot data files and scripts into `directory` (which must exist): one success-vs-rotation
/// plot per (algorithm, preset) with one curve per translation error (the papers' Figures 7/8), when
/// the report has at least two rotation errors; one pre-alignment-vs-evaluations plot per preset
/// (Figure 5: success, mean and median errors of GLASM-g, binary GLASM and PGA), when it has curve points;
/// one time-to-reach bar chart (Figure 6, small and large presets, preparation excluded and included).
/// `scripts` receives the .gp paths; each writes a PNG next to it when run with gnuplot. `title` prefixes
/// every plot title (e.g. the dataset name).
bool writeSuccessRatioPlotScripts(const SuccessRatioReport& report, const std::string& directory,
                                  const std::string& title, std::vector<std::string>* scripts,
                                  std::string* error);

}  // namespace hglasm
