// Reads laser scans from CARMEN text logs (FLASER lines), e.g. laserazosSM3.log of the MbICP paper.
#pragma once

#include <cmath>
#include <cstddef>
#include <istream>
#include <string>
#include <vector>

#include "hglasm_odometry/core/pose2d.h"
#include "hglasm_odometry/core/scan.h"

namespace hglasm {

/// One `FLASER n r1 .. rn x y theta odom_x odom_y odom_theta [ipc_ts host logger_ts]` line.
struct CarmenLaserReading {
  RangeScan ranges;             ///< `NaN` readings stay NaN (invalid per REP-117)
  Pose2D laser_pose;            ///< x y theta: the laser's pose as logged (corrected)
  Pose2D odometry_pose;         ///< odom_x odom_y odom_theta: the robot's raw odometry
  double stamp = 0.0;           ///< ipc timestamp, seconds (0 when absent; laserazos stores 0 everywhere)
  std::size_t line_number = 0;  ///< 1-based line in the log
};

struct CarmenLogOptions {
  std::string message = "FLASER";  ///< which laser message to read (e.g. "RLASER" for the rear laser)
  double angle_min = -M_PI / 2.0;  ///< angle of the first beam, radians
  /// Beam spacing, radians; 0 = field_of_view / (n - 1), i.e. the first and last beams span the field.
  double angle_increment = 0.0;
  double field_of_view = M_PI;  ///< radians; only used when angle_increment is 0
  double range_min = 0.0;       ///< metres
  double range_max = 80.0;      ///< metres; SICK "no return" readings (81.83 m, 81.91 m) exceed it
  std::size_t max_scans = 0;    ///< stop after this many readings; 0 = all
};

struct CarmenLog {
  std::vector<CarmenLaserReading> scans;  ///< in file order (CARMEN logs are written in time order)
  std::size_t malformed_lines = 0;        ///< `message` lines that could not be parsed (skipped)
  std::size_t first_malformed_line = 0;   ///< 1-based line number of the first one, 0 if none
  std::size_t ignored_lines = 0;          ///< other messages, comments (#) and blank lines
};

/// Parses one line. False if it is not a `options.message` line or is malformed (too few fields, a
/// beam count that does not match, a field that is not a number, non-finite poses); *reading is then
/// unspecified. Readings may be numbers, `NaN`/`nan`/`inf` (kept; invalid when converted).
bool parseCarmenLaserLine(const std::string& line, const CarmenLogOptions& options,
                          CarmenLaserReading* reading);

/// Reads every `options.message` line of a log, skipping and counting malformed ones.
/// False (with *error) only if the stream cannot be read at all.
bool readCarmenLog(std::istream& input, const CarmenLogOptions& options, CarmenLog* log, std::string* error);

/// As above, from a file. False (with *error) if the file cannot be opened.
bool readCarmenLog(const std::string& path, const CarmenLogOptions& options, CarmenLog* log,
                   std::string* error);

}  // namespace hglasm
