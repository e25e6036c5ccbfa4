#!/usr/bin/env bash
# Memory check over full replays (issue 5; too slow for CI, run by hand, ~5 min):
#   1. valgrind memcheck (leak-check=full) over `evaluate` on the whole fr079 bag (4934 scans): the same
#      OdometryPipeline as the nodelet, without ROS. Expect: no errors, nothing definitely or
#      indirectly lost.
#   2. peak resident memory of the same run without valgrind (/usr/bin/time -v).
#   3. laser_odometry_node under heaptrack (or valgrind: NODE_TOOL=valgrind) while `rosbag play` replays
#      bags/fr079_slice.bag with simulated time: leaks attributed to hglasm code, peak heap, peak RSS.
# Usage: bash scripts/memory_check.sh            (builds nothing: run scripts/run_tests.sh or build first)
#   HGLASM_BUILD=/path/to/build   build directory (default: <repo>/build)
#   NODE_TOOL=heaptrack|valgrind  tool for step 3 (default heaptrack)
#   OUT=/path                     where logs go (default: a new temporary directory, printed)
#   STEPS="1 2 3"                 which steps to run
# Exits non-zero if valgrind reports errors or leaks, or if hglasm code leaks in the node.
set -uo pipefail
cd "$(dirname "$0")/.."
source scripts/env.sh
bin="$HGLASM_BUILD/devel/lib/hglasm_odometry"
datasets="$HGLASM_ROOT/../shared/datasets"
out="${OUT:-$(mktemp -d /tmp/hglasm_memory.XXXXXX)}"
mkdir -p "$out"
node_tool="${NODE_TOOL:-heaptrack}"
steps="${STEPS:-1 2 3}"
for f in "$bin/evaluate" "$bin/laser_odometry_node"; do
  [ -x "$f" ] || { echo "missing $f: build first (scripts/run_tests.sh or hglasm_build)" >&2; exit 2; }
done
# The devel space: evaluate finds its default config through ROS_PACKAGE_PATH, the node its libraries.
set +u  # catkin's setup scripts read unset variables
source "$HGLASM_BUILD/devel/setup.bash"
set -u
echo "logs in $out"
status=0

if [[ " $steps " == *" 1 "* ]]; then
  echo "== 1. valgrind memcheck: evaluate over fr079.orig.bag (takes ~2-3 min)"
  valgrind --tool=memcheck --leak-check=full --show-leak-kinds=definite,indirect,possible \
    --errors-for-leak-kinds=definite,indirect --error-exitcode=3 --num-callers=30 \
    --log-file="$out/valgrind_evaluate.log" \
    "$bin/evaluate" --quiet --bag "$datasets/fr079/fr079.orig.bag" \
    --relations "$datasets/fr079/fr079.relations" >"$out/evaluate_valgrind_stdout.txt" 2>&1
  rc=$?
  grep -E "ERROR SUMMARY|definitely lost|indirectly lost|possibly lost|still reachable|in use at exit" \
    "$out/valgrind_evaluate.log" | sed 's/^==[0-9]*== /  /'
  grep SUMMARY "$out/evaluate_valgrind_stdout.txt" | sed 's/^/  /'
  if [ $rc -ne 0 ]; then echo "  FAIL: valgrind exit status $rc"; status=1; fi
fi

if [[ " $steps " == *" 2 "* ]]; then
  echo "== 2. peak RSS of evaluate over fr079.orig.bag (no valgrind)"
  /usr/bin/time -v "$bin/evaluate" --quiet --bag "$datasets/fr079/fr079.orig.bag" \
    --relations "$datasets/fr079/fr079.relations" >"$out/evaluate_stdout.txt" 2>"$out/evaluate_time.txt"
  grep -E "Maximum resident|Elapsed" "$out/evaluate_time.txt" | sed 's/^\s*/  /'
fi

[[ " $steps " == *" 3 "* ]] || exit $status

echo "== 3. laser_odometry_node under $node_tool, rosbag play bags/fr079_slice.bag"
export ROS_HOME="$out/ros_home"
port=$(python3 -c 'import socket; s = socket.socket(); s.bind(("localhost", 0)); print(s.getsockname()[1])')
export ROS_MASTER_URI="http://localhost:$port"
rosmaster --core -p "$port" >"$out/master.log" 2>&1 &
master=$!
node=""
echo_pid=""
cleanup() {
  [ -n "$echo_pid" ] && kill "$echo_pid" 2>/dev/null
  [ -n "$node" ] && rosnode kill /laser_odometry >/dev/null 2>&1
  kill "$master" 2>/dev/null
  wait 2>/dev/null
}
trap cleanup EXIT
for _ in $(seq 100); do rosparam list >/dev/null 2>&1 && break; sleep 0.1; done
rosparam set /use_sim_time true
rosparam load config/presets.yaml /laser_odometry/presets
rosparam load config/laser_odometry.yaml /laser_odometry
rosparam set /laser_odometry/queue_size 1000  # process every scan, however slow the tool makes the node
if [ "$node_tool" = valgrind ]; then
  valgrind --tool=memcheck --leak-check=full --num-callers=30 --log-file="$out/valgrind_node.log" \
    "$bin/laser_odometry_node" __name:=laser_odometry >"$out/node.log" 2>&1 &
  rate=0.5
else
  heaptrack -o "$out/heaptrack_node" "$bin/laser_odometry_node" __name:=laser_odometry >"$out/node.log" 2>&1 &
  rate=2
fi
node=$!
rostopic echo -p /laser_odometry/match/header/stamp >"$out/match_stamps.csv" 2>/dev/null &
echo_pid=$!
for _ in $(seq 300); do  # until the node subscribes to /scan (valgrind starts slowly)
  rostopic info /scan 2>/dev/null | grep -q laser_odometry && break
  sleep 0.2
done
rosbag play --clock --quiet --rate="$rate" bags/fr079_slice.bag --topics /scan /odom /tf_static \
  >"$out/play.log" 2>&1
sleep 5
# A clean shutdown (ros::spin returns, destructors run) so that the tool sees every free. Signals do not
# reach the node through the tool's wrapper, and background jobs of a script ignore SIGINT anyway.
rosnode kill /laser_odometry >/dev/null 2>&1
wait "$node"
node_rc=$?
node=""
kill "$echo_pid" 2>/dev/null
echo_pid=""
processed=$(($(wc -l <"$out/match_stamps.csv") - 1))
echo "  scans processed (~match received): $processed of 500; node exit status $node_rc"
if [ "$processed" -lt 450 ]; then echo "  FAIL: the node processed too few scans"; status=1; fi
if [ "$node_tool" = valgrind ]; then
  grep -E "ERROR SUMMARY|definitely lost|indirectly lost|possibly lost" "$out/valgrind_node.log" |
    sed 's/^==[0-9]*== /  /'
  if grep -A30 "definitely lost in" "$out/valgrind_node.log" | grep -q "hglasm"; then
    echo "  FAIL: hglasm code in a definite leak (see $out/valgrind_node.log)"
    status=1
  fi
else
  data=$(ls "$out"/heaptrack_node.* | head -1)
  heaptrack_print --print-leaks=1 --print-peaks=0 --print-allocators=0 --print-temporary=0 \
    "$data" >"$out/heaptrack_node.txt" 2>&1
  grep -E "^(peak heap memory consumption|peak RSS|total memory leaked|calls to allocation)" \
    "$out/heaptrack_node.txt" | sed 's/^/  /'
  # A leak is ours if the allocation was made by hglasm code: the first frame outside the standard
  # library / Eigen is an hglasm function. (ROS, log4cxx and glibc keep some allocations until exit: thread
  # stacks' TLS, stdio buffers, class registries. They are reported but do not grow with the data.)
  ours=$(python3 - "$out/heaptrack_node.txt" <<'PY'
import re, sys
text = open(sys.argv[1]).read()
section = text.split("MEMORY LEAKS", 1)[1] if "MEMORY LEAKS" in text else ""
records = re.split(r"\n(?=\S[^\n]* leaked over )", section)
system = ("std::", "__gnu_cxx::", "Eigen::", "operator new", "malloc", "calloc", "realloc", "void std::")
count = 0
for record in records:
    frames = [l.strip() for l in record.splitlines()[1:]
              if l.strip() and not l.strip().startswith(("at ", "in ", "and "))]
    first = next((f for f in frames if not f.startswith(system)), "")
    if "hglasm" in first:
        count += 1
        print(record, file=sys.stderr)
print(count)
PY
)
  echo "  leaks allocated by hglasm code: $ours"
  if [ "$ours" -ne 0 ]; then echo "  FAIL: see $out/heaptrack_node.txt"; status=1; fi
fi
exit $status
