// Map pictures: every scan's points drawn at the laser poses of one or more odometries (the laser odometry
// beside the wheels'), one point per grid cell so that large logs stay fast and readable, written as a
// gnuplot data file and script and rendered to a PNG by gnuplot. A wall is a single line where the poses
// are right and smeared where they drift.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "hglasm_odometry/core/pose2d.h"

namespace hglasm {

struct MapPlotOptions {
  double cell = 0.05;         ///< metres: at most one point per cell of this size and view (<= 0: all points)
  int scan_step = 1;          ///< draw every n-th scan
  double max_range = 20.0;    ///< metres: farther points (sparse, least precise) are left out; <= 0: none
  double grid = 1.0;          ///< metres between grid lines (widened only if lines would be < 4 px apart)
  double margin = 1.0;        ///< metres of frame around the points
  double frame_trim = 0.002;  ///< fraction of the points that may lie beyond each side of the frame
  int panel_pixels = 900;     ///< pixels of a panel's longer side
  std::string title;          ///< above the panels
  bool keep_files = false;    ///< keep the data file and the script next to the PNG
};

/// One drawing of the scans: where the laser was at each scan by one odometry.
struct MapView {
  std::string title;
  std::string colour = "#1f77b4";   ///< of the points (gnuplot rgb)
  std::vector<Pose2D> laser_poses;  ///< one per scan: the laser in the world; non-finite: scan left out
};

/// Axis ranges shared by every panel (metres), and the grid spacing actually drawn.
struct MapFrame {
  double x_min = 0.0, x_max = 0.0, y_min = 0.0, y_max = 0.0;
  double grid = 1.0;   ///< metres between grid lines
  double label = 1.0;  ///< metres between labelled tics (a multiple of grid)
};

/// The points of `scans` (each in its laser frame) at `laser_poses` (one per scan): every
/// options.scan_step-th scan with a finite pose, its points within options.max_range of the laser, one point
/// per options.cell square (the first one seen), in scan order.
std::vector<Eigen::Vector2d> mapPoints(const std::vector<std::vector<Eigen::Vector2d>>& scans,
                                       const std::vector<Pose2D>& laser_poses, const MapPlotOptions& options);

/// The laser's world pose at each of `stamps`: the base pose of `base_trajectory` (sorted by stamp) with
/// that stamp (within 1 us) composed with `base_to_laser`; a non-finite pose where it has none.
std::vector<Pose2D> laserPosesAtStamps(const std::vector<double>& stamps,
                                       const std::vector<StampedPose>& base_trajectory,
                                       const Pose2D& base_to_laser);

/// `poses` moved rigidly so that, at the first index where both are finite, they coincide with
/// `reference` (e.g. the wheels' started at the laser odometry's first pose).
std::vector<Pose2D> alignedTo(const std::vector<Pose2D>& reference, std::vector<Pose2D> poses);

/// The two views of the scans stamped `stamps` for base trajectories (sorted by stamp): "laser odometry"
/// in blue and, in red, "wheel odometry" started at the laser odometry's pose (alignedTo); the laser at
/// `base_to_laser` on the base.
std::vector<MapView> laserAndWheelViews(const std::vector<double>& stamps,
                                        const std::vector<StampedPose>& laser_odometry,
                                        const std::vector<StampedPose>& wheel_odometry,
                                        const Pose2D& base_to_laser);

/// Bounds of the points (but for the options.frame_trim fraction beyond each end of either axis: stray
/// far points) plus options.margin, rounded out to whole grid lines; the grid spacing and the labelled
/// tics' spacing for panels of options.panel_pixels.
MapFrame mapFrame(const std::vector<std::vector<Eigen::Vector2d>>& view_points,
                  const MapPlotOptions& options);

/// The gnuplot script drawing `png`: one panel per view, side by side for a frame taller than wide, else
/// one above the other, each with equal axis scale, the frame's ranges and a grid. View i's points are
/// data block 2 i of `data`, its laser path block 2 i + 1.
std::string mapPlotScript(const std::string& png, const std::string& data, const std::vector<MapView>& views,
                          const MapFrame& frame, const MapPlotOptions& options);

/// Writes `png`.map.dat (per view: its points, then its laser path; 'x y' lines, blocks separated by two
/// blank lines) and `png`.map.gp; *script receives the script's path. The first view's points decide the
/// frame of every panel (a drifting odometry's smear beyond it is cut off rather than shrinking the
/// picture). False with *error if not written.
bool writeMapFiles(const std::string& png, const std::vector<std::vector<Eigen::Vector2d>>& scans,
                   const std::vector<MapView>& views, const MapPlotOptions& options, std::string* script,
                   std::string* error);

/// writeMapFiles, then gnuplot renders the PNG; the data and script are removed unless options.keep_files.
bool writeMapPlot(const std::string& png, const std::vector<std::vector<Eigen::Vector2d>>& scans,
                  const std::vector<MapView>& views, const MapPlotOptions& options, std::string* error);

}  // namespace hglasm
