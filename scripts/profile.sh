#!/usr/bin/env bash
# Where the CPU of `evaluate` goes on whole logs: its own per-stage timers ("ms per scan") and `perf`'s
# flat profile (functions above 1.5 % of the samples, self time). Needs perf (Debian: linux-perf) and a
# Release build.
#
# usage: scripts/profile.sh [-e EVALUATE] [-c CONFIG] [-d DATASETS] [-l "fr079 aces fr-clinic"] [-p PRESET]
set -euo pipefail
package_dir="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
evaluate="$package_dir/build/devel/lib/hglasm_odometry/evaluate"
config=""
datasets="$package_dir/../shared/datasets"
logs="fr079 aces fr-clinic"
preset=medium
while getopts "e:c:d:l:p:h" option; do
  case "$option" in
    e) evaluate="$OPTARG" ;;
    c) config="$OPTARG" ;;
    d) datasets="$OPTARG" ;;
    l) logs="$OPTARG" ;;
    p) preset="$OPTARG" ;;
    *) sed -n '2,6p' "$0"; exit 2 ;;
  esac
done
command -v perf >/dev/null || { echo "profile: perf not found (apt-get install linux-perf)" >&2; exit 2; }
export ROS_PACKAGE_PATH="$package_dir${ROS_PACKAGE_PATH:+:$ROS_PACKAGE_PATH}"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
for log in $logs; do
  args=(--bag "$datasets/$log/$log.orig.bag" --preset "$preset" --quiet)
  [[ -n "$config" ]] && args+=(--config "$config")
  perf record -q -o "$work/$log.data" "$evaluate" "${args[@]}" >"$work/$log.log" 2>&1
  echo "== $log ($evaluate)"
  sed -n '/^ms per scan/,/^  total per scan/p' "$work/$log.log"
  perf report -i "$work/$log.data" --no-children --percent-limit 1.5 --stdio 2>/dev/null |
    grep -E '^ +[0-9]+\.[0-9]+%' | sed -E 's/ +\[\.\] / /; s/  +/ /g'
  echo
done
