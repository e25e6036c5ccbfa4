#!/usr/bin/env bash
# Installs, by Debian package name, everything hglasm_odometry needs to build, test and run its demo.
# Debian 12 (bookworm) ships ROS 1 in its own archive; no rosdep database is needed or reachable.
# Idempotent: packages already installed are skipped; apt runs only when something is missing.
set -euo pipefail

PACKAGES=(
  # build tools
  build-essential cmake catkin ros-message-generation ros-message-runtime
  # ROS 1 C++ libraries
  libroscpp-dev libnodeletlib-dev libnodeletlib-tools pluginlib-dev
  libtf2-ros-dev libtf2-geometry-msgs-dev libdiagnostic-updater-dev
  libstd-msgs-dev libsensor-msgs-dev libnav-msgs-dev libgeometry-msgs-dev
  libstd-srvs-dev libvisualization-msgs-dev libdiagnostic-msgs-dev
  librosbag-dev librostest-dev libgtest-dev libbenchmark-dev libeigen3-dev
  # the offline tools: parameter YAML, package paths
  libyaml-cpp-dev libroslib-dev
  # .msg definitions (needed by genmsg) and Python message modules (rostopic, rostest)
  ros-std-msgs ros-sensor-msgs ros-nav-msgs ros-geometry-msgs ros-std-srvs ros-visualization-msgs
  ros-diagnostic-msgs python3-std-msgs python3-sensor-msgs python3-nav-msgs python3-geometry-msgs
  python3-tf2-msgs python3-std-srvs python3-visualization-msgs python3-diagnostic-msgs
  python3-rostest ros-core rosbash
  # plots, headless rviz and screenshots
  gnuplot-nox rviz xvfb x11-apps imagemagick libgl1-mesa-dri
  # sanitizers and fuzzing
  clang libclang-rt-14-dev clang-format
)

missing=()
for p in "${PACKAGES[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done

if ((${#missing[@]})); then
  echo "[install_deps] installing ${#missing[@]} Debian packages: ${missing[*]}"
  SUDO=""
  [ "$(id -u)" -eq 0 ] || SUDO="sudo"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
else
  echo "[install_deps] all ${#PACKAGES[@]} Debian packages present"
fi
