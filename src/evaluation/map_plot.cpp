// Map pictures: scans drawn at the poses of each odometry, gnuplot data + script, rendered by gnuplot.
#include "hglasm_odometry/evaluation/map_plot.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <sstream>
#include <unordered_set>

#include "hglasm_odometry/evaluation/gnuplot.h"

namespace hglasm {
namespace {

/// Extra pixels of a panel around its plot area: tic labels and axis label, title.
constexpr int kPanelExtraWidth = 110;
constexpr int kPanelExtraHeight = 90;
constexpr int kTitleHeight = 30;
/// Closest grid lines and labelled tics (pixels).
constexpr double kMinGridPixels = 4.0;
constexpr double kMinLabelPixels = 60.0;

/// The smallest number 1, 2 or 5 times a power of ten that is a multiple of `unit` and at least `least`
/// (the least multiple of `unit` if no such number is near).
double niceMultiple(double unit, double least) {
  least = std::max(least, unit);
  double decade = 1e-3;
  for (int i = 0; i < 15; ++i, decade *= 10.0) {
    for (double factor : {1.0, 2.0, 5.0}) {
      const double value = factor * decade;
      const double ratio = value / unit;
      if (value >= least * (1.0 - 1e-9) && std::abs(ratio - std::round(ratio)) < 1e-6) return value;
    }
  }
  return unit * std::ceil(least / unit);
}

Pose2D notAPose() {
  Pose2D pose;
  pose.x = pose.y = pose.theta = std::numeric_limits<double>::quiet_NaN();
  return pose;
}

/// Width and height of a panel's plot area (pixels): the longer side options.panel_pixels.
void panelPixels(const MapFrame& frame, const MapPlotOptions& options, int* width, int* height) {
  const double w = frame.x_max - frame.x_min, h = frame.y_max - frame.y_min;
  const double per_metre = options.panel_pixels / std::max({w, h, 1e-9});
  *width = std::max(200, static_cast<int>(std::lround(w * per_metre)));
  *height = std::max(200, static_cast<int>(std::lround(h * per_metre)));
}

/// What the picture's points and lines mean: "one point per 5 cm cell, points within 20 m, grid lines
/// every 1 m".
std::string mapLegend(const MapFrame& frame, const MapPlotOptions& options) {
  std::ostringstream legend;
  if (options.cell > 0.0) legend << "one point per " << options.cell * 100.0 << " cm cell, ";
  if (options.max_range > 0.0) legend << "points within " << options.max_range << " m, ";
  legend << "grid lines every " << frame.grid << " m";
  return legend.str();
}

/// The smallest and largest of `values` once the fraction `trim` of them is dropped at either end; 0, 0
/// for no values.
void trimmedBounds(std::vector<double>* values, double trim, double* low, double* high) {
  *low = *high = 0.0;
  if (values->empty()) return;
  const std::size_t drop =
      std::min(values->size() / 2, static_cast<std::size_t>(std::max(0.0, trim) * values->size()));
  std::nth_element(values->begin(), values->begin() + drop, values->end());
  *low = (*values)[drop];
  const std::size_t top = values->size() - 1 - drop;
  std::nth_element(values->begin(), values->begin() + top, values->end());
  *high = (*values)[top];
}

void writeBlock(std::ostream& out, const std::vector<Eigen::Vector2d>& points) {
  // An empty block would merge with the next one: a lone undefined point keeps the numbering.
  if (points.empty()) out << "NaN NaN\n";
  for (const auto& p : points) out << p.x() << " " << p.y() << "\n";
  out << "\n\n";
}

}  // namespace

std::vector<Eigen::Vector2d> mapPoints(const std::vector<std::vector<Eigen::Vector2d>>& scans,
                                       const std::vector<Pose2D>& laser_poses,
                                       const MapPlotOptions& options) {
  std::vector<Eigen::Vector2d> points;
  std::unordered_set<std::uint64_t> occupied;
  const std::size_t step = static_cast<std::size_t>(std::max(1, options.scan_step));
  const std::size_t count = std::min(scans.size(), laser_poses.size());
  for (std::size_t i = 0; i < count; i += step) {
    if (!laser_poses[i].isFinite()) continue;
    for (const Eigen::Vector2d& local : scans[i]) {
      if (options.max_range > 0.0 && local.norm() > options.max_range) continue;
      const Eigen::Vector2d world = laser_poses[i] * local;
      if (!world.allFinite()) continue;
      if (options.cell > 0.0) {
        const auto ix = static_cast<std::int64_t>(std::floor(world.x() / options.cell));
        const auto iy = static_cast<std::int64_t>(std::floor(world.y() / options.cell));
        const std::uint64_t key = (static_cast<std::uint64_t>(ix) << 32) ^
                                  static_cast<std::uint32_t>(static_cast<std::int32_t>(iy));
        if (!occupied.insert(key).second) continue;
      }
      points.push_back(world);
    }
  }
  return points;
}

std::vector<Pose2D> laserPosesAtStamps(const std::vector<double>& stamps,
                                       const std::vector<StampedPose>& base_trajectory,
                                       const Pose2D& base_to_laser) {
  constexpr double kTolerance = 1e-6;
  std::vector<Pose2D> poses;
  poses.reserve(stamps.size());
  for (double stamp : stamps) {
    const auto it =
        std::lower_bound(base_trajectory.begin(), base_trajectory.end(), stamp - kTolerance,
                         [](const StampedPose& pose, double value) { return pose.stamp < value; });
    const bool found = it != base_trajectory.end() && std::abs(it->stamp - stamp) <= kTolerance;
    poses.push_back(found ? it->pose * base_to_laser : notAPose());
  }
  return poses;
}

std::vector<Pose2D> alignedTo(const std::vector<Pose2D>& reference, std::vector<Pose2D> poses) {
  const std::size_t count = std::min(reference.size(), poses.size());
  for (std::size_t i = 0; i < count; ++i) {
    if (!reference[i].isFinite() || !poses[i].isFinite()) continue;
    const Pose2D align = reference[i] * poses[i].inverse();
    for (Pose2D& pose : poses) {
      if (pose.isFinite()) pose = align * pose;
    }
    break;
  }
  return poses;
}

std::vector<MapView> laserAndWheelViews(const std::vector<double>& stamps,
                                        const std::vector<StampedPose>& laser_odometry,
                                        const std::vector<StampedPose>& wheel_odometry,
                                        const Pose2D& base_to_laser) {
  std::vector<MapView> views(2);
  views[0].title = "laser odometry";
  views[0].laser_poses = laserPosesAtStamps(stamps, laser_odometry, base_to_laser);
  views[1].title = "wheel odometry (started at the same pose)";
  views[1].colour = "#d62728";
  views[1].laser_poses =
      alignedTo(views[0].laser_poses, laserPosesAtStamps(stamps, wheel_odometry, base_to_laser));
  return views;
}

MapFrame mapFrame(const std::vector<std::vector<Eigen::Vector2d>>& view_points,
                  const MapPlotOptions& options) {
  std::vector<double> xs, ys;
  for (const auto& points : view_points) {
    for (const auto& p : points) {
      xs.push_back(p.x());
      ys.push_back(p.y());
    }
  }
  double x_min = 0.0, x_max = 0.0, y_min = 0.0, y_max = 0.0;
  trimmedBounds(&xs, options.frame_trim, &x_min, &x_max);
  trimmedBounds(&ys, options.frame_trim, &y_min, &y_max);
  const double margin = std::max(0.0, options.margin);
  const double extent = std::max({x_max - x_min + 2.0 * margin, y_max - y_min + 2.0 * margin, 1e-3});
  const double per_metre = std::max(1, options.panel_pixels) / extent;
  MapFrame frame;
  const double grid = options.grid > 0.0 ? options.grid : 1.0;
  frame.grid = grid * per_metre >= kMinGridPixels ? grid : niceMultiple(grid, kMinGridPixels / per_metre);
  frame.label = niceMultiple(frame.grid, kMinLabelPixels / per_metre);
  frame.x_min = std::floor((x_min - margin) / frame.grid) * frame.grid;
  frame.x_max = std::ceil((x_max + margin) / frame.grid) * frame.grid;
  frame.y_min = std::floor((y_min - margin) / frame.grid) * frame.grid;
  frame.y_max = std::ceil((y_max + margin) / frame.grid) * frame.grid;
  return frame;
}

std::string mapPlotScript(const std::string& png, const std::string& data, const std::vector<MapView>& views,
                          const MapFrame& frame, const MapPlotOptions& options) {
  int width = 0, height = 0;
  panelPixels(frame, options, &width, &height);
  const int n = static_cast<int>(std::max<std::size_t>(1, views.size()));
  const bool side_by_side = frame.y_max - frame.y_min > frame.x_max - frame.x_min;
  const int canvas_width = (width + kPanelExtraWidth) * (side_by_side ? n : 1);
  const int canvas_height = (height + kPanelExtraHeight) * (side_by_side ? 1 : n) + kTitleHeight;
  const long minor = std::lround(frame.label / frame.grid);
  std::ostringstream out;
  out << "set terminal pngcairo size " << canvas_width << "," << canvas_height
      << " font 'Sans,10' noenhanced\n"
      << "set output " << gnuplotQuote(png) << "\n"
      << "set multiplot layout " << (side_by_side ? 1 : n) << "," << (side_by_side ? n : 1) << " title "
      << gnuplotQuote(options.title + " (" + mapLegend(frame, options) + ")") << "\n"
      << "set size ratio -1\nunset key\n"
      << "set xrange [" << frame.x_min << ":" << frame.x_max << "]\n"
      << "set yrange [" << frame.y_min << ":" << frame.y_max << "]\n"
      << "set xtics " << frame.label << "\nset ytics " << frame.label << "\n"
      << "set mxtics " << minor << "\nset mytics " << minor << "\n"
      << "set grid back xtics ytics mxtics mytics lt 1 lc rgb '#b0b0b0' lw 0.8, lt 1 lc rgb '#e0e0e0' lw "
         "0.6\n"
      << "set xlabel 'x (m)'\nset ylabel 'y (m)'\n";
  for (std::size_t i = 0; i < views.size(); ++i) {
    out << "set title " << gnuplotQuote(views[i].title) << "\n"
        << "plot " << gnuplotQuote(data) << " index " << 2 * i << " using 1:2 with dots lc rgb "
        << gnuplotQuote(views[i].colour) << ", \\\n     " << gnuplotQuote(data) << " index " << 2 * i + 1
        << " using 1:2 with lines lw 1 lc rgb '#303030'\n";
  }
  out << "unset multiplot\n";
  return out.str();
}

bool writeMapFiles(const std::string& png, const std::vector<std::vector<Eigen::Vector2d>>& scans,
                   const std::vector<MapView>& views, const MapPlotOptions& options, std::string* script,
                   std::string* error) {
  std::vector<std::vector<Eigen::Vector2d>> view_points;
  const std::string data = png + ".map.dat";
  std::ofstream data_out(data);
  data_out.precision(9);
  for (const MapView& view : views) {
    view_points.push_back(mapPoints(scans, view.laser_poses, options));
    std::vector<Eigen::Vector2d> path;
    for (const Pose2D& pose : view.laser_poses) {
      if (pose.isFinite()) path.push_back(pose.translation());
    }
    data_out << "# " << view.title << ": points, then the laser's path\n";
    writeBlock(data_out, view_points.back());
    writeBlock(data_out, path);
  }
  data_out.close();
  *script = png + ".map.gp";
  std::ofstream script_out(*script);
  script_out << mapPlotScript(
      png, data, views,
      mapFrame({view_points.empty() ? std::vector<Eigen::Vector2d>() : view_points.front()}, options),
      options);
  script_out.close();
  if (!data_out || !script_out) {
    if (error) *error = "cannot write " + data + " or " + *script;
    return false;
  }
  return true;
}

bool writeMapPlot(const std::string& png, const std::vector<std::vector<Eigen::Vector2d>>& scans,
                  const std::vector<MapView>& views, const MapPlotOptions& options, std::string* error) {
  std::string script;
  if (!writeMapFiles(png, scans, views, options, &script, error)) return false;
  const bool plotted = runGnuplot(script);
  if (!options.keep_files) {
    std::remove(script.c_str());
    std::remove((png + ".map.dat").c_str());
  }
  if (!plotted) {
    if (error) *error = "gnuplot failed on " + script;
    return false;
  }
  return true;
}

}  // namespace hglasm
