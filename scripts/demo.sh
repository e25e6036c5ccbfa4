#!/usr/bin/env bash
# THE demo: installs what is missing (apt, by Debian package name), builds the package (Release, ./build),
# replays bags/fr079_slice.bag through the laser-odometry nodelet with simulated time, prints progress and a
# summary (scans processed, time per scan, fallbacks, accuracy against the slice's reference relations) and
# writes a trajectory plot to ./output/trajectory.png and a map picture (the scans at the laser odometry's
# poses beside the same scans at the wheels') to ./output/map.png.
#
#   scripts/demo.sh [--rviz] [--preset small|medium|large] [--bag FILE.bag] [--rate FACTOR]
#
# The bag plays at twice its real speed by default (--rate 1 for real time).
# --rviz shows the run in rviz (needs a display). The bag's reference relations are read from the .relations
# file next to it when there is one. Runs as root on a fresh Debian 12; needs no ../shared.
set -euo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
RVIZ=false
PRESET=""
BAG="$ROOT/bags/fr079_slice.bag"
RATE=2.0
while (($#)); do
  case "$1" in
    --rviz) RVIZ=true ;;
    --preset) PRESET="$2"; shift ;;
    --bag) BAG="$(cd "$(dirname "$2")" && pwd)/$(basename "$2")"; shift ;;
    --rate) RATE="$2"; shift ;;
    -h|--help) sed -n '2,11p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "demo: unknown argument $1 (try --help)" >&2; exit 2 ;;
  esac
  shift
done
RELATIONS="${BAG%.bag}.relations"
[ -f "$RELATIONS" ] || RELATIONS=""

# ROS 1 from Debian: nothing to source for the system part. The system python3 must come first (a pyenv
# shim has no rospy), networking stays on loopback, and logs stay in ./output.
export PATH=/usr/bin:$PATH
export ROS_HOSTNAME=localhost
export ROS_HOME="$ROOT/output/ros_home"
mkdir -p "$ROOT/output" "$ROS_HOME"

echo "[demo] 1/4 dependencies"
"$ROOT/scripts/install_deps.sh"

echo "[demo] 2/4 build (Release, $ROOT/build)"
cmake -S "$ROOT" -B "$ROOT/build" -DCMAKE_BUILD_TYPE=Release -DCATKIN_DEVEL_PREFIX="$ROOT/build/devel" \
  -DPYTHON_EXECUTABLE=/usr/bin/python3 -DPython3_EXECUTABLE=/usr/bin/python3 >"$ROOT/output/configure.log" \
  || { cat "$ROOT/output/configure.log"; exit 1; }
cmake --build "$ROOT/build" -j"$(nproc)" --target hglasm_ros laser_odometry_node demo_report >"$ROOT/output/build.log" 2>&1 \
  || { tail -50 "$ROOT/output/build.log"; exit 1; }
set +u  # setup.bash reads unset variables
# shellcheck disable=SC1091
source "$ROOT/build/devel/setup.bash"
set -u

# A master of our own on a free port, so a running roscore is left alone.
PORT=11411
while (echo >"/dev/tcp/127.0.0.1/$PORT") 2>/dev/null; do PORT=$((PORT + 1)); done
export ROS_MASTER_URI="http://localhost:$PORT"

echo "[demo] 3/4 replaying $(basename "$BAG") through the nodelet (master on port $PORT)"
if $RVIZ && [ -z "${DISPLAY:-}" ]; then
  echo "[demo] --rviz needs a display (DISPLAY is not set); continuing without rviz" >&2
  RVIZ=false
fi
LAUNCH_ARGS=(bag:="$BAG" paused:=true rate:="$RATE" rviz:="$RVIZ" output:=log)
[ -n "$PRESET" ] && LAUNCH_ARGS+=(preset:="$PRESET")
roslaunch -p "$PORT" hglasm_odometry bag.launch "${LAUNCH_ARGS[@]}" >"$ROOT/output/roslaunch.log" 2>&1 &
LAUNCH_PID=$!
stop_launch() {
  if kill -0 "$LAUNCH_PID" 2>/dev/null; then
    kill -INT "$LAUNCH_PID" 2>/dev/null || true
    wait "$LAUNCH_PID" 2>/dev/null || true
  fi
}
trap stop_launch EXIT

until (echo >"/dev/tcp/127.0.0.1/$PORT") 2>/dev/null; do  # the master roslaunch starts
  kill -0 "$LAUNCH_PID" 2>/dev/null || { cat "$ROOT/output/roslaunch.log"; exit 1; }
  sleep 0.2
done
REPORT_ARGS=(--bag "$BAG" --output-dir "$ROOT/output")
[ -n "$RELATIONS" ] && REPORT_ARGS+=(--relations "$RELATIONS")
REPORT_STATUS=0
"$ROOT/build/devel/lib/hglasm_odometry/demo_report" "${REPORT_ARGS[@]}" | tee "$ROOT/output/summary.txt" \
  || REPORT_STATUS=$?
if $RVIZ; then
  echo "[demo] rviz is open: close it (or press Ctrl-C) to finish"
  wait "$LAUNCH_PID" 2>/dev/null || true
fi
stop_launch

echo "[demo] 4/4 plot"
gnuplot "$ROOT/output/trajectory.gp"
echo "[demo] wrote $ROOT/output/trajectory.png and $ROOT/output/map.png (summary: $ROOT/output/summary.txt, logs: $ROOT/output/*.log)"
exit $REPORT_STATUS
