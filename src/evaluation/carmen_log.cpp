#include "hglasm_odometry/evaluation/carmen_log.h"

#include <cctype>
#include <charconv>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <string_view>

namespace hglasm {
namespace {

// A log line has a few hundred fields; a beam count beyond this is a corrupt line, not a laser.
constexpr long kMaxBeams = 100000;
// After the six pose fields CARMEN writes `ipc_timestamp ipc_hostname logger_timestamp`.
constexpr std::size_t kMaxTrailingFields = 3;

void splitFields(const std::string& line, std::vector<std::string_view>* fields) {
  fields->clear();
  const std::string_view text(line);
  std::size_t pos = 0;
  while (pos < text.size()) {
    while (pos < text.size() && (text[pos] == ' ' || text[pos] == '\t' || text[pos] == '\r')) ++pos;
    const std::size_t start = pos;
    while (pos < text.size() && text[pos] != ' ' && text[pos] != '\t' && text[pos] != '\r') ++pos;
    if (pos > start) fields->push_back(text.substr(start, pos - start));
  }
}

// Strict: the whole field must be a number (NaN and inf included). strtod, not std::from_chars: GCC 9's
// libstdc++ (ROS Noetic on Ubuntu 20.04) has no floating-point from_chars. strtod reads the decimal point
// of the C locale, which these programs never change.
bool parseDouble(std::string_view field, double* value) {
  constexpr std::size_t kMaxField = 64;  // far longer than any number in a log
  if (field.empty() || field.size() >= kMaxField || std::isspace(static_cast<unsigned char>(field.front()))) {
    return false;
  }
  char text[kMaxField];
  field.copy(text, field.size());
  text[field.size()] = '\0';
  char* end = nullptr;
  *value = std::strtod(text, &end);
  return end == text + field.size();
}

bool parseLong(std::string_view field, long* value) {
  if (field.empty()) return false;
  const char* end = field.data() + field.size();
  const auto result = std::from_chars(field.data(), end, *value);
  return result.ec == std::errc() && result.ptr == end;
}

bool parsePose(const std::vector<std::string_view>& fields, std::size_t first, Pose2D* pose) {
  double x = 0.0, y = 0.0, theta = 0.0;
  if (!parseDouble(fields[first], &x) || !parseDouble(fields[first + 1], &y) ||
      !parseDouble(fields[first + 2], &theta)) {
    return false;
  }
  if (!std::isfinite(x) || !std::isfinite(y) || !std::isfinite(theta)) return false;
  *pose = Pose2D(x, y, theta);
  return true;
}

bool parseFields(const std::vector<std::string_view>& fields, const CarmenLogOptions& options,
                 CarmenLaserReading* reading) {
  if (fields.size() < 2 || fields[0] != options.message) return false;
  long beams = 0;
  if (!parseLong(fields[1], &beams) || beams < 1 || beams > kMaxBeams) return false;
  const std::size_t beam_count = static_cast<std::size_t>(beams);
  const std::size_t pose_start = 2 + beam_count;
  const std::size_t required = pose_start + 6;
  // Too many trailing fields means the beam count does not match the readings.
  if (fields.size() < required || fields.size() > required + kMaxTrailingFields) return false;

  RangeScan& scan = reading->ranges;
  scan.ranges.resize(beam_count);
  for (std::size_t i = 0; i < beam_count; ++i) {
    double range = 0.0;
    if (!parseDouble(fields[2 + i], &range)) return false;
    scan.ranges[i] = static_cast<float>(range);
  }
  scan.angle_min = options.angle_min;
  if (options.angle_increment != 0.0) {
    scan.angle_increment = options.angle_increment;
  } else {
    scan.angle_increment = beam_count > 1 ? options.field_of_view / static_cast<double>(beam_count - 1) : 0.0;
  }
  scan.range_min = options.range_min;
  scan.range_max = options.range_max;

  if (!parsePose(fields, pose_start, &reading->laser_pose)) return false;
  if (!parsePose(fields, pose_start + 3, &reading->odometry_pose)) return false;

  reading->stamp = 0.0;
  double stamp = 0.0;
  if (fields.size() > required && parseDouble(fields[required], &stamp) && std::isfinite(stamp)) {
    reading->stamp = stamp;
  }
  return true;
}

}  // namespace

bool parseCarmenLaserLine(const std::string& line, const CarmenLogOptions& options,
                          CarmenLaserReading* reading) {
  std::vector<std::string_view> fields;
  splitFields(line, &fields);
  return parseFields(fields, options, reading);
}

bool readCarmenLog(std::istream& input, const CarmenLogOptions& options, CarmenLog* log, std::string* error) {
  *log = CarmenLog();
  if (!input) {
    if (error) *error = "cannot read the CARMEN log stream";
    return false;
  }
  std::string line;
  std::vector<std::string_view> fields;
  std::size_t line_number = 0;
  CarmenLaserReading reading;
  while (std::getline(input, line)) {
    ++line_number;
    splitFields(line, &fields);
    if (fields.empty() || fields[0].front() == '#' || fields[0] != options.message) {
      ++log->ignored_lines;
      continue;
    }
    if (!parseFields(fields, options, &reading)) {
      if (log->malformed_lines == 0) log->first_malformed_line = line_number;
      ++log->malformed_lines;
      continue;
    }
    reading.line_number = line_number;
    log->scans.push_back(reading);
    if (options.max_scans > 0 && log->scans.size() >= options.max_scans) break;
  }
  if (input.bad()) {
    if (error) *error = "read error in the CARMEN log after line " + std::to_string(line_number);
    return false;
  }
  return true;
}

bool readCarmenLog(const std::string& path, const CarmenLogOptions& options, CarmenLog* log,
                   std::string* error) {
  std::ifstream input(path);
  if (!input) {
    *log = CarmenLog();
    if (error) *error = "cannot open CARMEN log '" + path + "'";
    return false;
  }
  return readCarmenLog(input, options, log, error);
}

}  // namespace hglasm
