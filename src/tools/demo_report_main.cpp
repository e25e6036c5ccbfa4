// demo_report: the demo's live reporter. Connects to the running laser odometry, resumes the paused bag
// player once everything is connected, prints progress while the bag plays, then a summary (scans
// processed, time per scan from ~match, fallbacks, accuracy against reference relations next to the bag's
// wheel odometry), and writes the trajectories plus a gnuplot script for the plot, and the map picture
// (the bag's scans at the laser odometry's poses beside the wheels').
//
//   demo_report --bag B [--relations R] [--output-dir DIR] [--odom-topic T] [--match-topic T]
//               [--player /player] [--timeout SEC]
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <mutex>
#include <string>
#include <vector>

#include <nav_msgs/Odometry.h>
#include <ros/ros.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/LaserScan.h>
#include <std_srvs/SetBool.h>

#include "hglasm_odometry/Match.h"
#include "hglasm_odometry/core/odometry_buffer.h"
#include "hglasm_odometry/evaluation/gnuplot.h"
#include "hglasm_odometry/evaluation/relations.h"
#include "hglasm_odometry/evaluation/statistics.h"
#include "hglasm_odometry/evaluation/trajectory.h"
#include "hglasm_odometry/ros/conversions.h"
#include "hglasm_odometry/tools/argument_parser.h"
#include "hglasm_odometry/tools/bag_reader.h"
#include "hglasm_odometry/tools/evaluation_run.h"

namespace {

struct Options {
  std::string bag;
  std::string relations;
  std::string output_dir = "output";
  std::string scan_topic = "/scan";
  std::string wheel_odom_topic = "/odom";
  std::string odom_topic = "/laser_odometry/odom";
  std::string match_topic = "/laser_odometry/match";
  std::string player = "/player";
  double timeout = 600.0;  // wall seconds
};

const char kUsage[] =
    "usage: demo_report --bag B [--relations R] [--output-dir DIR] [--odom-topic T] [--match-topic T]\n"
    "                   [--player /player] [--timeout SEC]\n";

/// kOk with *options filled, or what the tool should exit with. ROS remappings are gone by now.
hglasm_odometry::ArgumentParser::Result parseArguments(int argc, char** argv, Options* options) {
  using Result = hglasm_odometry::ArgumentParser::Result;
  hglasm_odometry::ArgumentParser parser("demo_report", kUsage);
  parser.addOption("--bag", &options->bag);
  parser.addOption("--relations", &options->relations);
  parser.addOption("--output-dir", &options->output_dir);
  parser.addOption("--odom-topic", &options->odom_topic);
  parser.addOption("--match-topic", &options->match_topic);
  parser.addOption("--player", &options->player);
  parser.addOption("--timeout", &options->timeout);
  const Result result = parser.parse(argc, argv);
  if (result != Result::kOk) return result;
  if (options->bag.empty()) {
    parser.fail("--bag is required");
    return Result::kError;
  }
  return Result::kOk;
}

struct Received {
  std::mutex mutex;
  std::vector<nav_msgs::Odometry> odometry;
  std::vector<hglasm_odometry::Match> matches;
};

void printAccuracyRow(const char* label, const hglasm::RelationStats& laser,
                      const hglasm::RelationStats& wheel) {
  std::printf("    %-12s %4d   %7.4f m %7.3f deg     %7.4f m %7.3f deg\n", label, laser.count,
              laser.trans_mean, laser.rot_mean_deg, wheel.trans_mean, wheel.rot_mean_deg);
}

/// The bag's scan stamps (sorted: what must come out) and its wheel odometry (for comparison).
bool readBagInputs(const Options& options, std::vector<double>* scan_stamps, hglasm::OdometryBuffer* wheel) {
  try {
    rosbag::Bag bag(options.bag, rosbag::bagmode::Read);
    for (const rosbag::MessageInstance& m : rosbag::View(bag)) {
      if (m.getTopic() == options.scan_topic) {
        if (auto scan = m.instantiate<sensor_msgs::LaserScan>())
          scan_stamps->push_back(scan->header.stamp.toSec());
      } else if (m.getTopic() == options.wheel_odom_topic) {
        auto odom = m.instantiate<nav_msgs::Odometry>();
        hglasm::Pose2D pose;
        if (odom && hglasm_odometry::pose2DFromOdometryMsg(*odom, &pose))
          wheel->add(odom->header.stamp.toSec(), pose);
      }
    }
  } catch (const rosbag::BagException& ex) {
    std::cerr << "demo_report: " << ex.what() << "\n";
    return false;
  }
  std::sort(scan_stamps->begin(), scan_stamps->end());
  return true;
}

/// Waits for the laser odometry's outputs and the paused player, then resumes the player.
bool startPlayback(const Options& options, const ros::Subscriber& odom_sub, const ros::Subscriber& match_sub,
                   const ros::WallTime& start) {
  std::printf("[demo] waiting for the laser odometry (%s) ...\n", options.odom_topic.c_str());
  std::fflush(stdout);
  while (ros::ok() && (odom_sub.getNumPublishers() == 0 || match_sub.getNumPublishers() == 0)) {
    if ((ros::WallTime::now() - start).toSec() > 60.0) {
      std::cerr << "demo_report: the laser odometry did not come up within 60 s\n";
      return false;
    }
    ros::WallDuration(0.1).sleep();
  }
  const std::string pause_service = options.player + "/pause_playback";
  if (!ros::service::waitForService(pause_service, ros::Duration(60.0))) {
    std::cerr << "demo_report: no " << pause_service << " service (is the player running paused?)\n";
    return false;
  }
  std_srvs::SetBool resume;
  resume.request.data = false;
  ros::service::call(pause_service, resume);
  return true;
}

/// Prints progress until every one of `expected` scans has come out, nothing arrives for 20 s, or the
/// timeout (since `start`) is up.
void reportProgress(const Options& options, std::size_t expected, const ros::WallTime& start,
                    Received* received) {
  std::size_t last_count = 0, last_reported = 0;
  ros::WallTime last_progress = ros::WallTime::now();
  while (ros::ok() && (ros::WallTime::now() - start).toSec() < options.timeout) {
    std::size_t count, fallbacks = 0;
    double ms = 0.0;
    {
      std::lock_guard<std::mutex> lock(received->mutex);
      count = std::min(received->odometry.size(), received->matches.size());
      for (const auto& m : received->matches) {
        fallbacks += m.fallback && m.matched;
        ms += m.total_ms;
      }
      if (!received->matches.empty()) ms /= received->matches.size();
    }
    if (count >= last_reported + std::max<std::size_t>(1, expected / 10) ||
        (count >= expected && count != last_reported)) {
      std::printf("[demo] %4zu / %zu scans (%3.0f %%), %.2f ms per scan, %zu fallbacks\n", count, expected,
                  100.0 * count / std::max<std::size_t>(1, expected), ms, fallbacks);
      std::fflush(stdout);
      last_reported = count;
    }
    if (count >= expected) break;
    if (count != last_count) {
      last_count = count;
      last_progress = ros::WallTime::now();
    } else if ((ros::WallTime::now() - last_progress).toSec() > 20.0) {
      std::printf("[demo] no output for 20 s; stopping at %zu of %zu scans\n", count, expected);
      break;
    }
    ros::WallDuration(0.1).sleep();
  }
}

/// The laser odometry's poses, by stamp.
std::vector<hglasm::StampedPose> laserTrajectory(const std::vector<nav_msgs::Odometry>& odometry) {
  std::vector<hglasm::StampedPose> trajectory;
  for (const auto& odom : odometry) {
    hglasm::StampedPose pose;
    pose.stamp = odom.header.stamp.toSec();
    if (hglasm_odometry::pose2DFromOdometryMsg(odom, &pose.pose)) trajectory.push_back(pose);
  }
  std::sort(trajectory.begin(), trajectory.end(),
            [](const hglasm::StampedPose& a, const hglasm::StampedPose& b) { return a.stamp < b.stamp; });
  return trajectory;
}

/// Scans, time per scan, fallbacks and keyframes from ~match.
void printRunSummary(const Options& options, const Received& received, std::size_t expected, double wall) {
  std::vector<double> total_ms;
  std::size_t fallbacks = 0, matched = 0, keyframes = 0;
  std::uint32_t dropped = 0;
  for (const auto& m : received.matches) {
    total_ms.push_back(m.total_ms);
    matched += m.matched;
    fallbacks += m.matched && m.fallback;
    keyframes += m.new_keyframe;
    dropped = std::max(dropped, m.dropped_scans);
  }

  std::printf("\n================ hglasm_odometry demo summary ================\n");
  std::printf("  bag                 %s\n", options.bag.c_str());
  std::printf("  scans processed     %zu of %zu (%u dropped by the input queue), %.1f s wall\n",
              received.odometry.size(), expected, dropped, wall);
  std::printf(
      "  time per scan       mean %.2f ms, median %.2f ms, p95 %.2f ms, max %.2f ms (~match total_ms)\n",
      hglasm::mean(total_ms), hglasm::median(total_ms), hglasm::percentile(total_ms, 0.95),
      hglasm::percentile(total_ms, 1.0));
  std::printf("  fallbacks           %zu of %zu matches (%.1f %%)\n", fallbacks, matched,
              matched ? 100.0 * fallbacks / matched : 0.0);
  std::printf("  keyframes           %zu\n", keyframes);
}

/// Accuracy of both trajectories against the reference relations (if any were given).
void printAccuracy(const Options& options, const std::vector<hglasm::StampedPose>& trajectory,
                   const std::vector<hglasm::StampedPose>& wheel_trajectory) {
  if (options.relations.empty()) return;
  std::vector<hglasm::Relation> relations;
  std::string error;
  if (!hglasm::readRelations(options.relations, &relations, &error)) {
    std::printf("  accuracy            cannot read %s: %s\n", options.relations.c_str(), error.c_str());
    return;
  }
  std::printf("  accuracy vs %zu reference relations (Kümmerle et al. 2009), mean error:\n",
              relations.size());
  std::printf("    %-12s %4s   %-23s   %s\n", "relations", "n", "laser odometry", "wheel odometry (bag)");
  printAccuracyRow("all", hglasm::evaluateRelations(relations, trajectory, 0.0),
                   hglasm::evaluateRelations(relations, wheel_trajectory, 0.0));
  printAccuracyRow("<= 10 s", hglasm::evaluateRelations(relations, trajectory, 10.0),
                   hglasm::evaluateRelations(relations, wheel_trajectory, 10.0));
}

/// The trajectories (the wheels' started at the laser odometry's first pose) and the gnuplot script of
/// their plot, in options.output_dir.
void writePlot(const Options& options, const std::vector<hglasm::StampedPose>& trajectory,
               const std::vector<hglasm::StampedPose>& wheel_trajectory) {
  const std::string dir = options.output_dir;
  bool written = true;
  {
    std::ofstream out(dir + "/trajectory.txt");
    out << "# laser odometry: stamp x y theta (base_link in odom)\n";
    for (const auto& p : trajectory)
      out << std::fixed << p.stamp << " " << p.pose.x << " " << p.pose.y << " " << p.pose.theta << "\n";
    out.close();
    written = written && !out.fail();
  }
  {
    const hglasm::Pose2D laser_origin = trajectory.empty() ? hglasm::Pose2D() : trajectory.front().pose;
    const hglasm::Pose2D wheel_origin =
        wheel_trajectory.empty() ? hglasm::Pose2D() : wheel_trajectory.front().pose;
    std::ofstream out(dir + "/wheel_odometry.txt");
    out << "# wheel odometry of the bag at the scan stamps, started at the laser odometry's first pose\n";
    for (const auto& p : wheel_trajectory) {
      const hglasm::Pose2D aligned = laser_origin * hglasm::relativePose(wheel_origin, p.pose);
      out << std::fixed << p.stamp << " " << aligned.x << " " << aligned.y << " " << aligned.theta << "\n";
    }
    out.close();
    written = written && !out.fail();
  }
  {
    const std::string laser = hglasm::gnuplotQuote(dir + "/trajectory.txt");
    std::ofstream out(dir + "/trajectory.gp");
    out << "set terminal pngcairo size 1000,900 font 'Sans,11' noenhanced\n"
        << "set output " << hglasm::gnuplotQuote(dir + "/trajectory.png") << "\nset title "
        << hglasm::gnuplotQuote("hglasm_odometry on " +
                                options.bag.substr(options.bag.find_last_of('/') + 1) +
                                ": laser odometry vs wheel odometry (from the bag)")
        << "\nset xlabel 'x (m)'\nset ylabel 'y (m)'\nset size ratio -1\nset grid\nset key below\n"
        << "plot " << hglasm::gnuplotQuote(dir + "/wheel_odometry.txt")
        << " using 2:3 with lines lw 1.5 lc rgb '#999999' title 'wheel odometry', \\\n     " << laser
        << " using 2:3 with lines lw 2 lc rgb '#d62728' title 'laser odometry (HGLASM-g)', \\\n     " << laser
        << " every ::0::0 using 2:3 with points pt 7 ps 1.5 lc rgb 'black' title 'start'\n";
    out.close();
    written = written && !out.fail();
  }
  if (written) {
    std::printf("  trajectory          %s/trajectory.txt (plot script %s/trajectory.gp)\n", dir.c_str(),
                dir.c_str());
  } else {
    std::printf("  trajectory          not written: cannot write into %s\n", dir.c_str());
  }
}

/// options.output_dir/map.png: the bag's scans (in the laser frame, mirrored for an upside-down laser) at
/// the laser poses of the laser odometry and, beside them, of the wheel odometry started at the same pose.
void writeMap(const Options& options, const std::vector<hglasm::StampedPose>& trajectory,
              const std::vector<hglasm::StampedPose>& wheel_trajectory) {
  hglasm_odometry::BagReadOptions read_options;
  read_options.scan_topic = options.scan_topic;
  read_options.odom_topic = options.wheel_odom_topic;  // its child frame is the base frame of the mount
  hglasm_odometry::BagData data;
  std::string error;
  if (!hglasm_odometry::readBag(options.bag, read_options, &data, &error)) {
    std::printf("  map                 cannot read %s: %s\n", options.bag.c_str(), error.c_str());
    return;
  }
  const std::string png = options.output_dir + "/map.png";
  const std::string title = "hglasm_odometry on " + options.bag.substr(options.bag.find_last_of('/') + 1) +
                            ": scans at the laser poses";
  const hglasm::ScanConversionOptions conversion =
      hglasm::conversionForMount(hglasm::ScanConversionOptions(), data.laser_upside_down);
  if (hglasm_odometry::writeScanMap(png, title, data, conversion, trajectory, wheel_trajectory, &error)) {
    std::printf("  map                 %s\n", png.c_str());
  } else {
    std::printf("  map                 not written: %s\n", error.c_str());
  }
}

}  // namespace

int main(int argc, char** argv) {
  ros::init(argc, argv, "demo_report", ros::init_options::AnonymousName);
  Options options;
  const auto parsed = parseArguments(argc, argv, &options);
  if (parsed != hglasm_odometry::ArgumentParser::Result::kOk) return hglasm_odometry::exitStatus(parsed);
  // Made now, so that a directory that cannot be made stops the demo before the bag plays.
  std::error_code made;
  std::filesystem::create_directories(options.output_dir, made);
  if (made) {
    std::cerr << "demo_report: cannot create --output-dir '" << options.output_dir << "': " << made.message()
              << "\n";
    return 2;
  }

  // The bag: its scan stamps (what must come out) and wheel odometry (for comparison).
  std::vector<double> scan_stamps;
  hglasm::OdometryBuffer wheel(1e9);
  if (!readBagInputs(options, &scan_stamps, &wheel)) return 1;
  const std::size_t expected = scan_stamps.size();

  ros::NodeHandle nh;
  Received received;
  ros::Subscriber odom_sub = nh.subscribe<nav_msgs::Odometry>(
      options.odom_topic, 10000, [&received](const nav_msgs::OdometryConstPtr& msg) {
        std::lock_guard<std::mutex> lock(received.mutex);
        received.odometry.push_back(*msg);
      });
  ros::Subscriber match_sub = nh.subscribe<hglasm_odometry::Match>(
      options.match_topic, 10000, [&received](const hglasm_odometry::MatchConstPtr& msg) {
        std::lock_guard<std::mutex> lock(received.mutex);
        received.matches.push_back(*msg);
      });
  ros::AsyncSpinner spinner(1);
  spinner.start();

  const ros::WallTime start = ros::WallTime::now();
  if (!startPlayback(options, odom_sub, match_sub, start)) return 1;
  std::printf("[demo] playing %zu scans of %s\n", expected, options.bag.c_str());
  std::fflush(stdout);
  reportProgress(options, expected, start, &received);
  ros::WallDuration(0.3).sleep();
  spinner.stop();
  const double wall = (ros::WallTime::now() - start).toSec();

  std::lock_guard<std::mutex> lock(received.mutex);
  const std::vector<hglasm::StampedPose> trajectory = laserTrajectory(received.odometry);
  const std::vector<hglasm::StampedPose> wheel_trajectory = hglasm::trajectoryAt(wheel, scan_stamps, 1.0);
  printRunSummary(options, received, expected, wall);
  printAccuracy(options, trajectory, wheel_trajectory);
  writePlot(options, trajectory, wheel_trajectory);
  writeMap(options, trajectory, wheel_trajectory);
  std::printf("===============================================================\n");
  return received.odometry.size() == expected ? 0 : 1;
}
