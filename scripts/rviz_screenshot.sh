#!/bin/bash
# Screenshot of rviz (scan, local map, path, GA population) after replaying bags/fr079_slice.bag, under Xvfb.
#
#   scripts/rviz_screenshot.sh [OUT.png]     (default doc/rviz_fr079.png; needs a built tree, xvfb, imagemagick)
#
# The shipped rviz/hglasm_odometry.rviz follows base_link; here the view is fixed on odom, centred on the
# fr079 slice's trajectory (x -3.5..3.1 m, y 0..7.9 m). Software OpenGL (Mesa llvmpipe) is forced.
set -eo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
OUT="${1:-$ROOT/doc/rviz_fr079.png}"
BAG="$ROOT/bags/fr079_slice.bag"
RATE="${RATE:-2}"
source "$ROOT/scripts/env.sh"
source "$ROOT/build/devel/setup.bash"
export LIBGL_ALWAYS_SOFTWARE=1

WORK="$(mktemp -d)"
# Two views of the shipped config: the slice (fixed on odom, without the Odometry arrows and the TF axes,
# which hide the rest) and, as an inset, the GA population around the robot (its spread is centimetres).
python3 - "$ROOT/rviz/hglasm_odometry.rviz" "$WORK" <<'PY'
import sys, yaml
config = yaml.safe_load(open(sys.argv[1]))
manager = config["Visualization Manager"]
for display in manager["Displays"]:
    if display["Name"] in ("Odometry", "TF"):
        display["Enabled"] = False
        display["Value"] = False
    if display["Name"] == "Scan":  # over the local map it matches: larger and red, to stand out
        display["Color"] = "255; 40; 40"
        display["Size (Pixels)"] = 5
view = manager["Views"]["Current"]
view.update({"Target Frame": "<Fixed Frame>", "Scale": 48, "X": 0.5, "Y": 3.8})
config["Window Geometry"].update({"X": 0, "Y": 0, "Width": 1200, "Height": 846})
yaml.safe_dump(config, open(sys.argv[2] + "/slice.rviz", "w"), sort_keys=False)
view.update({"Target Frame": "base_link", "Scale": 400, "X": 0.0, "Y": 0.0})
config["Window Geometry"].update({"X": 0, "Y": 860, "Width": 420, "Height": 420, "Hide Left Dock": True})
for panel in config["Window Geometry"].values():
    if isinstance(panel, dict):
        panel["collapsed"] = True
yaml.safe_dump(config, open(sys.argv[2] + "/population.rviz", "w"), sort_keys=False)
PY

DISPLAY_NUM=99
while [ -e "/tmp/.X11-unix/X$DISPLAY_NUM" ]; do DISPLAY_NUM=$((DISPLAY_NUM + 1)); done
Xvfb ":$DISPLAY_NUM" -screen 0 1280x1300x24 >"$WORK/xvfb.log" 2>&1 &
XVFB_PID=$!
export DISPLAY=":$DISPLAY_NUM"

PORT=11611
while (echo >"/dev/tcp/127.0.0.1/$PORT") 2>/dev/null; do PORT=$((PORT + 1)); done
export ROS_MASTER_URI="http://localhost:$PORT"
roslaunch -p "$PORT" hglasm_odometry bag.launch bag:="$BAG" paused:=true rate:="$RATE" \
  publish_population:=true output:=log >"$WORK/roslaunch.log" 2>&1 &
LAUNCH_PID=$!
RVIZ_PIDS=()
cleanup() {
  for pid in "${RVIZ_PIDS[@]}"; do kill "$pid" 2>/dev/null || true; done
  kill -INT "$LAUNCH_PID" 2>/dev/null || true
  wait "$LAUNCH_PID" 2>/dev/null || true
  kill "$XVFB_PID" 2>/dev/null || true
}
trap cleanup EXIT

until rosservice list 2>/dev/null | grep -q /player/pause_playback; do sleep 0.5; done
for view in slice population; do
  rosrun rviz rviz -d "$WORK/$view.rviz" __name:="rviz_$view" >"$WORK/rviz_$view.log" 2>&1 &
  RVIZ_PIDS+=($!)
done
# Until both rviz subscribe to the local map and the population (their displays are up).
for topic in /laser_odometry/local_map /laser_odometry/ga_population; do
  until [ "$(rostopic info "$topic" 2>/dev/null | grep -c '/rviz_')" -ge 2 ]; do
    for pid in "${RVIZ_PIDS[@]}"; do kill -0 "$pid" 2>/dev/null || { cat "$WORK"/rviz_*.log; exit 1; }; done
    sleep 0.5
  done
done
sleep 3
rosservice call /player/pause_playback false >/dev/null
# Until the bag is played: the player's node is gone (three checks in a row, rosnode can fail under load).
gone=0
while [ "$gone" -lt 3 ]; do
  sleep 1
  if rosnode list 2>/dev/null | grep -qx /player; then gone=0; else gone=$((gone + 1)); fi
done
sleep 3
# The windows where they are (no window manager): the slice window whole, the population view's canvas
# as an inset over the slice's Views panel.
xwininfo -root -tree >"$WORK/windows.txt"
import -window root "$WORK/screen.png"
convert "$WORK/screen.png" -crop 1200x846+0+0 +repage "$WORK/slice.png"
convert "$WORK/screen.png" -crop 300x300+350+922 +repage -resize 262x262 -bordercolor white -border 2 "$WORK/inset.png"
convert "$WORK/slice.png" "$WORK/inset.png" -geometry +932+92 -composite -font DejaVu-Sans -pointsize 13 \
  -fill black -annotate +934+376 "Scan red, local map blue, path green.\n\nInset: GA population (orange),\nestimate (green), prediction (blue)\naround the robot, 0.75 m across" \
  "$OUT"
echo "wrote $OUT (screen and logs in $WORK)"
