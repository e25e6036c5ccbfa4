#!/usr/bin/env bash
# CPU per scan of the laser odometry's worker thread (the nodelet replaying a bag through launch/bag.launch)
# beside evaluate's on the same bag, and their ratios. Several devel spaces (-d, e.g. a copy of the build
# before a change and the build after it) run alternately, round by round, so that all see the same load.
#
# usage: scripts/node_cpu.sh [-d DEVEL]... [-b BAG]... [-n ROUNDS] [-r RATE] [-s] [-p] [-o OUT_DIR]
#   -d  a devel space (default build/devel) whose node names its worker thread "laser_odometry"; evaluate
#       is the first one's
#   -b  bags (default bags/fr079_slice.bag bags/aces_slice.bag)
#   -n  rounds (default 3); -r the player's rate (default 3); -s the standalone node instead of the nodelet
#   -p  also record each node run with perf (OUT_DIR/*.perf; perf report -i F --sort sym)
#   -o  run logs (default /tmp/hglasm_node_cpu)
# Worker: the thread's CPU between two consecutive odom -> base transforms on /tf (one whole cycle of the
# worker: waiting, inputs, conversion, matching, publishing; scripts/node_cpu_monitor.py), with /tf and
# /diagnostics the only subscriptions to the node's outputs. Process: every thread of the node's process,
# per scan. Self: the node's own "CPU per scan, mean" (diagnostics; conversion, matching and publishing).
# Wake: the worker's wake-ups (times scheduled in) per scan.
# evaluate: its "total per scan (CPU)" (conversion and OdometryPipeline::processScan, one thread), as fast as
# it goes and paced (--pace RATE: each scan processed when the player would deliver it, the core idle in
# between as the worker's is). All in ms.
# Run it niced on a shared machine: nice -n 10 scripts/node_cpu.sh ...
set -euo pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
devels=() bags=() rounds=3 rate=3 standalone=false perf=false out_dir=/tmp/hglasm_node_cpu
while getopts "d:b:n:r:spo:h" option; do
  case "$option" in
    d) devels+=("$(cd "$OPTARG" && pwd)") ;;
    b) bags+=("$(cd "$(dirname "$OPTARG")" && pwd)/$(basename "$OPTARG")") ;;
    n) rounds="$OPTARG" ;;
    r) rate="$OPTARG" ;;
    s) standalone=true ;;
    p) perf=true ;;
    o) out_dir="$OPTARG" ;;
    h) sed -n '2,21p' "$0"; exit 0 ;;
    *) sed -n '2,21p' "$0" >&2; exit 2 ;;
  esac
done
((${#devels[@]})) || devels=("$ROOT/build/devel")
((${#bags[@]})) || bags=("$ROOT/bags/fr079_slice.bag" "$ROOT/bags/aces_slice.bag")
mkdir -p "$out_dir"
export PATH=/usr/bin:$PATH ROS_HOSTNAME=localhost ROS_HOME="$out_dir/ros_home"
node=/laser_odometry_manager
$standalone && node=/laser_odometry

# Prints "mean median p99" of evaluate's total per scan (CPU); further arguments go to evaluate.
evaluate_cpu() {  # BAG LOG [ARGS...]
  local bag="$1" log="$2"
  shift 2
  (
    set +u
    source "${devels[0]}/setup.bash"
    "${devels[0]}/lib/hglasm_odometry/evaluate" --bag "$bag" --quiet "$@" >"$log" 2>&1
  ) || { echo "node_cpu: evaluate failed on $bag, see $log" >&2; exit 1; }
  awk '/total per scan \(CPU\)/ {print $9, $6, $7}' "$log"
}

# Plays BAG through the node of DEVEL; prints the monitor's line.
node_cpu() {  # DEVEL BAG LOG
  local devel="$1" bag="$2" log="$3" port=11511 launch_file="$out_dir/node_cpu.launch"
  while (echo >"/dev/tcp/127.0.0.1/$port") 2>/dev/null; do port=$((port + 1)); done
  # As the rostests replay: the queue holds the whole bag, the odometry wait never times out; and the
  # diagnostics' CPU per scan covers the whole bag.
  cat >"$launch_file" <<EOF
<launch>
  <include file="\$(find hglasm_odometry)/launch/bag.launch">
    <arg name="bag" value="$bag"/> <arg name="rate" value="$rate"/> <arg name="paused" value="true"/>
    <arg name="queue_size" value="1000"/> <arg name="standalone" value="$standalone"/> <arg name="output" value="log"/>
  </include>
  <param name="laser_odometry/odometry/wait" value="1.0"/>
  <param name="laser_odometry/diagnostics/window" value="100000.0"/>
</launch>
EOF
  local scans
  scans=$(rosbag info --yaml --key=topics "$bag" | awk '/topic: \/scan$/ {found = 1} found && /messages:/ {print $2; exit}')
  (
    set +u
    source "$devel/setup.bash"
    export ROS_MASTER_URI="http://localhost:$port"
    roslaunch -p "$port" "$launch_file" >"$log.launch" 2>&1 &
    launch_pid=$!
    trap 'kill -INT $launch_pid 2>/dev/null; wait $launch_pid 2>/dev/null' EXIT
    until (echo >"/dev/tcp/127.0.0.1/$port") 2>/dev/null; do sleep 0.2; done
    monitor=(--node "$node" --scans "$scans" --library "$devel")
    $perf && monitor+=(--perf "${log%.log}.perf")
    python3 "$ROOT/scripts/node_cpu_monitor.py" "${monitor[@]}" >"$log" 2>&1
  ) || { echo "node_cpu: the node run failed on $bag, see $log and $log.launch" >&2; exit 1; }
  tail -1 "$log"
}

printf "%-12s %5s %-2s | %-20s | %-20s | %-20s | %-19s | %s\n" bag round d "evaluate mean/med/p99" \
  "paced mean/med/p99" "worker mean/med/p99" "process, self, wake" "worker/evaluate mean med p99, /paced mean"
for bag in "${bags[@]}"; do
  name=$(basename "$bag" .bag)
  rows="$out_dir/${name}_rows.txt"
  : >"$rows"
  for round in $(seq 1 "$rounds"); do
    evaluate=$(evaluate_cpu "$bag" "$out_dir/${name}_evaluate_$round.log")
    paced=$(evaluate_cpu "$bag" "$out_dir/${name}_paced_$round.log" --pace "$rate")
    for d in "${!devels[@]}"; do
      line=$(node_cpu "${devels[$d]}" "$bag" "$out_dir/${name}_node${d}_$round.log")
      worker=$(awk '{print $6, $8, $10, $12, $14, $16}' <<<"$line")
      echo "$d $evaluate $paced $worker" >>"$rows"
      # columns: d, evaluate mean median p99, paced mean median p99, worker mean median p99, process mean,
      # the node's own mean, the worker's wake-ups
    done
  done
  awk -v name="${name%_slice}" -v n="${#devels[@]}" '
    function row(label, d, v) {
      printf "%-12s %5s %-2s | %6.3f %6.3f %6.3f | %6.3f %6.3f %6.3f | %6.3f %6.3f %6.3f | %6.3f %6.3f %5.2f | %5.2f %5.2f %5.2f %5.2f\n",
        name, label, d, v[2], v[3], v[4], v[5], v[6], v[7], v[8], v[9], v[10], v[11], v[12], v[13],
        v[8] / v[2], v[9] / v[3], v[10] / v[4], v[8] / v[5]
    }
    {
      for (i = 2; i <= 13; ++i) { v[i] = $i; sum[$1, i] += $i }
      row(int((NR - 1) / n) + 1, $1, v)
    } END {
      for (d = 0; d < n; ++d) {
        for (i = 2; i <= 13; ++i) v[i] = sum[d, i] * n / NR
        row("all", d, v)
      }
    }' "$rows"
done
echo "devels:"
for d in "${!devels[@]}"; do echo "  $d ${devels[$d]}"; done
