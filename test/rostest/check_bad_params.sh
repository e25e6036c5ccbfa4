#!/usr/bin/env bash
# laser_odometry_node refuses bad parameters (issue 5): for each case below it must exit non-zero within a
# few seconds, having printed exactly one error line (ERROR or FATAL) that names the parameter. A valid
# configuration must keep running (the control case). Starts its own ROS master on a free port.
# Usage: check_bad_params.sh PATH/TO/laser_odometry_node
set -u
export PATH=/usr/bin:$PATH  # ROS python tools need the system python3 (not a pyenv shim)
node="${1:?usage: check_bad_params.sh PATH/TO/laser_odometry_node}"
here="$(cd "$(dirname "$0")" && pwd)"
config="$here/../../config"
export ROS_HOSTNAME=localhost
work="$(mktemp -d)"
export ROS_HOME="$work"
port=$(python3 -c 'import socket; s = socket.socket(); s.bind(("localhost", 0)); print(s.getsockname()[1])')
export ROS_MASTER_URI="http://localhost:$port"
rosmaster --core -p "$port" >"$work/master.log" 2>&1 &
master=$!
trap 'kill "$master" 2>/dev/null; wait "$master" 2>/dev/null; rm -rf "$work"' EXIT
for _ in $(seq 100); do rosparam list >/dev/null 2>&1 && break; sleep 0.1; done

failed=0
# name | YAML loaded into the node's private namespace (after presets.yaml and laser_odometry.yaml) | the
# parameter the one error line must name
cases=(
  "unknown_preset|preset: huge|~preset"
  "text_for_a_number|keyframe: {distance: far}|~keyframe/distance"
  "bool_for_an_integer|queue_size: true|~queue_size"
  "list_for_a_number|table: {cell_size: [1, 2]}|~table/cell_size"
  "negative_population|genetic: {population: -5}|~genetic/population"
  "negative_path_length|path_length: -1|~path_length"
  "negative_size_in_a_preset|presets: {medium: {genetic: {box_x: -1.0}}}|~presets/medium/genetic/box_x"
  "no_elites|genetic: {elite_count: 0}|~genetic/elite_count"
  "removed_algorithm|algorithm: pga|~algorithm"
)
run_case() {  # name yaml -> sets rc, out
  local name="$1" yaml="$2"
  rosparam load "$config/presets.yaml" "/$name/presets"
  rosparam load "$config/laser_odometry.yaml" "/$name"
  if [ -n "$yaml" ]; then echo "$yaml" >"$work/$name.yaml" && rosparam load "$work/$name.yaml" "/$name"; fi
  timeout "${3:-20}" "$node" "__name:=$name" >"$work/$name.out" 2>&1
  rc=$?
  out=$(sed 's/\x1b\[[0-9;]*m//g' "$work/$name.out")  # without colour codes
}
for c in "${cases[@]}"; do
  IFS='|' read -r name yaml param <<<"$c"
  run_case "$name" "$yaml"
  errors=$(echo "$out" | grep -E '^\[ *(ERROR|FATAL) *\]' || true)
  count=$(echo -n "$errors" | grep -c '' || true)
  if [ "$rc" -eq 0 ] || [ "$rc" -eq 124 ]; then
    echo "FAIL  $name: exit status $rc (expected non-zero, and not a timeout)"; failed=1
  elif [ "$count" -ne 1 ]; then
    echo "FAIL  $name: $count error lines (expected 1):"; echo "$out" | sed 's/^/      /'; failed=1
  elif ! grep -qF -- "$param" <<<"$errors"; then
    echo "FAIL  $name: the error does not name $param: $errors"; failed=1
  else
    echo "OK    $name: exit $rc: $errors"
  fi
done
# Control: the shipped configuration starts and keeps running (killed by the timeout, status 124).
run_case valid_configuration "" 3
if [ "$rc" -ne 124 ] || echo "$out" | grep -qE '^\[ *(ERROR|FATAL) *\]'; then
  echo "FAIL  valid_configuration: exit status $rc (expected to keep running):"; echo "$out" | sed 's/^/      /'
  failed=1
else
  echo "OK    valid_configuration: still running after 3 s"
fi
exit $failed
