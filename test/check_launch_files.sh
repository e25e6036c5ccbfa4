#!/usr/bin/env bash
# Checks that every launch file parses and that everything it includes resolves: `roslaunch --files`
# loads the full launch tree (includes, args, rosparam files, $(find ...)) without starting anything.
# Usage: check_launch_files.sh [LAUNCH_DIR]   (default: ../launch next to this script)
# Exits non-zero if any file fails.
set -u
export PATH=/usr/bin:$PATH  # ROS python tools need the system python3 (not a pyenv shim)
dir="${1:-$(cd "$(dirname "$0")/../launch" && pwd)}"
# Let $(find hglasm_odometry) resolve to this source tree even when nothing is sourced.
export ROS_PACKAGE_PATH="$(cd "$dir/.." && pwd)${ROS_PACKAGE_PATH:+:$ROS_PACKAGE_PATH}"
export ROS_HOME="${ROS_HOME:-$(mktemp -d)}"
shopt -s nullglob
files=("$dir"/*.launch)
if ((${#files[@]} == 0)); then
  echo "check_launch_files: no launch files in $dir" >&2
  exit 1
fi
failed=0
for f in "${files[@]}"; do
  # bag.launch requires a bag argument; give every launch file the args it declares without a default.
  args=()
  for a in $(grep -o '<arg[[:space:]][^>]*>' "$f" | grep -v 'default=\|value=' | sed -n 's/.*name="\([^"]*\)".*/\1/p'); do
    args+=("$a:=/dev/null")
  done
  if out=$(roslaunch --files "$f" "${args[@]}" 2>&1); then
    echo "OK    $(basename "$f") ($(echo "$out" | wc -l) files)"
  else
    echo "FAIL  $(basename "$f"):"
    echo "$out" | sed 's/^/      /'
    failed=1
  fi
done
exit $failed
