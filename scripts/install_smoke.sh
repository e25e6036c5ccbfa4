#!/usr/bin/env bash
# Install smoke test: what `catkin_make install` does (configure with CMAKE_INSTALL_PREFIX, build the install
# target), into a new temporary prefix, then, from that install space alone (a clean environment that sources
# only its setup.bash: neither the source tree nor the devel space is on ROS_PACKAGE_PATH):
#   - the launch files, config, rviz file, nodelet plugin description, message and tools are installed, and no
#     installed library or tool holds the source path;
#   - rospack, pluginlib and rosmsg find the package, the nodelet and Match.msg in the install space;
#   - every installed launch file loads (roslaunch --files), bag.launch's rviz points at the installed file;
#   - evaluate runs on the installed bags/fr079_slice.bag with the installed config;
#   - roslaunch bag.launch runs the nodelet on the installed fr079 slice and demo_report receives odometry and
#     a match message for every one of its 500 scans, and writes the trajectories and the map picture into an
#     output directory it makes (one it cannot make stops it with exit status 2).
# Usage: bash scripts/install_smoke.sh   (builds what is missing in $HGLASM_BUILD; about 40 s once built)
#   KEEP=1   keep the install prefix and logs (printed) instead of removing them
# Exits non-zero on any failure.
set -euo pipefail

# ---------------------------------------------------------------- stage 2: inside the install space
if [[ "${1:-}" == "--from-install" ]]; then
  prefix="$2"
  logs="$3"
  set +u  # catkin's setup scripts read unset variables
  # shellcheck disable=SC1091
  source "$prefix/setup.bash"
  set -u
  share="$prefix/share/hglasm_odometry"
  fail() {
    echo "install_smoke: $*" >&2
    exit 1
  }
  echo "ROS_PACKAGE_PATH=$ROS_PACKAGE_PATH"
  IFS=: read -ra entries <<<"$ROS_PACKAGE_PATH"
  for entry in "${entries[@]}"; do
    for tree in "$HGLASM_SOURCE_TREE" "$HGLASM_BUILD_TREE"; do
      [[ "$entry" != "$tree"* ]] || fail "the source tree or the build/devel space is on ROS_PACKAGE_PATH: $entry"
    done
  done
  [[ "$(rospack find hglasm_odometry)" == "$share" ]] || fail "rospack finds $(rospack find hglasm_odometry)"
  rospack plugins --attrib=plugin nodelet | grep -qx "hglasm_odometry $share/nodelet_plugins.xml" ||
    fail "pluginlib does not see the installed nodelet_plugins.xml"
  rosmsg show hglasm_odometry/Match >/dev/null || fail "rosmsg cannot show hglasm_odometry/Match"
  python3 -c 'from hglasm_odometry.msg import Match' || fail "the Python message module is not importable"

  for launch in "$share"/launch/*.launch; do
    roslaunch --files "$launch" bag:=/dev/null >/dev/null || fail "roslaunch --files $launch"
  done
  rviz_args="$(roslaunch --args rviz "$share/launch/bag.launch" bag:=/dev/null rviz:=true)"
  [[ "$rviz_args" == *"-d $share/rviz/hglasm_odometry.rviz"* ]] || fail "bag.launch's rviz: $rviz_args"

  # The offline pipeline with the installed config (found through ROS_PACKAGE_PATH, no --config).
  evaluate="$(catkin_find --first-only hglasm_odometry evaluate)"
  [[ "$evaluate" == "$prefix/lib/hglasm_odometry/evaluate" ]] || fail "catkin_find finds evaluate at $evaluate"
  "$evaluate" --bag "$share/bags/fr079_slice.bag" --relations "$share/bags/fr079_slice.relations" \
    --quiet >"$logs/evaluate.log" 2>&1 || fail "evaluate failed, see $logs/evaluate.log"
  grep -q "^options  *$share/config/laser_odometry.yaml," "$logs/evaluate.log" ||
    fail "evaluate did not read the installed config: $(grep '^options' "$logs/evaluate.log")"
  grep "^SUMMARY" "$logs/evaluate.log" | cut -c1-100

  # The nodelet in its own manager on the installed slice, master on a free port; the player starts paused
  # and demo_report resumes it once the nodelet is connected. Every scan is kept (queue_size 1000).
  export ROS_HOME="$logs/ros_home"
  port=11511
  while (echo >"/dev/tcp/127.0.0.1/$port") 2>/dev/null; do port=$((port + 1)); done
  export ROS_MASTER_URI="http://localhost:$port"
  roslaunch -p "$port" hglasm_odometry bag.launch bag:="$share/bags/fr079_slice.bag" paused:=true rate:=5 \
    queue_size:=1000 output:=log >"$logs/roslaunch.log" 2>&1 &
  launch_pid=$!
  stop_launch() {
    kill -INT "$launch_pid" 2>/dev/null || true
    wait "$launch_pid" 2>/dev/null || true
  }
  trap stop_launch EXIT
  until (echo >"/dev/tcp/127.0.0.1/$port") 2>/dev/null; do  # the master roslaunch starts
    kill -0 "$launch_pid" 2>/dev/null || fail "roslaunch exited, see $logs/roslaunch.log"
    sleep 0.2
  done
  status=0
  rosrun hglasm_odometry demo_report --bag "$share/bags/fr079_slice.bag" \
    --relations "$share/bags/fr079_slice.relations" --output-dir "$logs/demo" --timeout 120 \
    >"$logs/demo_report.log" 2>&1 || status=$?
  sed -n '/demo summary/,$p' "$logs/demo_report.log"
  ((status == 0)) || fail "demo_report exit status $status (not every scan came out), see $logs"
  for file in trajectory.txt wheel_odometry.txt trajectory.gp map.png; do  # into a directory it makes
    [[ -s "$logs/demo/$file" ]] || fail "demo_report did not write $logs/demo/$file"
  done
  # An output directory that cannot be made stops it before the bag plays, naming the option.
  status=0
  rosrun hglasm_odometry demo_report --bag "$share/bags/fr079_slice.bag" --output-dir "$logs/evaluate.log/demo" \
    >"$logs/demo_report_bad_dir.log" 2>&1 || status=$?
  ((status == 2)) && grep -q "cannot create --output-dir" "$logs/demo_report_bad_dir.log" ||
    fail "demo_report with an output directory under a file: exit status $status, see $logs/demo_report_bad_dir.log"
  exit 0
fi

# ---------------------------------------------------------------- stage 1: install
cd "$(dirname "$0")/.."
source scripts/env.sh
prefix="$(mktemp -d /tmp/hglasm_install.XXXXXX)"
logs="$prefix.logs"
mkdir -p "$logs"
cleanup() {
  if [[ "${KEEP:-0}" == 1 ]]; then
    echo "install_smoke: kept $prefix and $logs"
  else
    rm -rf "$prefix" "$logs"
  fi
}
trap cleanup EXIT
fail() {
  echo "install_smoke: $*" >&2
  exit 1
}

# The build keeps this prefix in its cache afterwards; changing it rebuilds nothing (only catkin's
# install-space setup files are regenerated).
echo "== install into $prefix (configure with CMAKE_INSTALL_PREFIX, build the install target)"
cmake -S "$HGLASM_ROOT" -B "$HGLASM_BUILD" "${HGLASM_CMAKE_ARGS[@]}" -DCMAKE_INSTALL_PREFIX="$prefix" \
  >"$logs/configure.log" || fail "configure failed, see $logs/configure.log"
cmake --build "$HGLASM_BUILD" -j"$(nproc)" --target install >"$logs/install.log" ||
  fail "install failed, see $logs/install.log"

share="$prefix/share/hglasm_odometry"
for file in launch/*.launch config/*.yaml rviz/*.rviz nodelet_plugins.xml package.xml msg/Match.msg; do
  cmp -s "$file" "$share/$file" || fail "$file is not installed as $share/$file"
done
for file in lib/libhglasm_core.so lib/libhglasm_ros.so include/hglasm_odometry/Match.h \
  include/hglasm_odometry/core/scan_matcher.h include/hglasm_odometry/ros/laser_odometry.h \
  lib/hglasm_odometry/{laser_odometry_node,evaluate,success_ratio,cut_bag,demo_report} \
  share/hglasm_odometry/bags/fr079_slice.bag setup.bash; do
  [[ -e "$prefix/$file" ]] || fail "$prefix/$file is not installed"
done
for private in tools evaluation; do  # static libraries of this package's tools: nothing to build against
  [[ ! -e "$prefix/include/hglasm_odometry/$private" ]] || fail "include/hglasm_odometry/$private is installed"
done
binaries=("$prefix"/lib/*.so "$prefix"/lib/hglasm_odometry/*)
for binary in "${binaries[@]}"; do
  if strings "$binary" | grep -qF -e "$HGLASM_ROOT" -e "$HGLASM_BUILD"; then
    fail "$binary holds the source or build path"
  fi
done
echo "installed: $(find "$prefix" -type f | wc -l) files; no source or build path in ${#binaries[@]} libraries and tools"

echo "== from the install space only (clean environment, $prefix/setup.bash)"
env -i HOME="$HOME" PATH=/usr/bin:/bin ROS_HOSTNAME=localhost HGLASM_SOURCE_TREE="$HGLASM_ROOT" \
  HGLASM_BUILD_TREE="$HGLASM_BUILD" \
  bash --noprofile --norc "$HGLASM_ROOT/scripts/install_smoke.sh" --from-install "$prefix" "$logs" ||
  { KEEP=1; fail "the install space failed (logs kept)"; }
echo "== install smoke test passed"
