#!/usr/bin/env bash
# CPU per scan of two `evaluate` builds on the same logs, run alternately (A B A B ...) so that both see the
# same machine load, and their ratios (B / A): mean, median and p99 of "total per scan (CPU)", one thread,
# over the whole log. Accuracy is not compared here (scripts/evaluate_all.sh does that).
#
# usage: scripts/cpu_compare.sh -a EVALUATE_A -b EVALUATE_B [-c CONFIG_A] [-C CONFIG_B] [-d DATASETS]
#                               [-l "fr079 aces fr-clinic"] [-n ROUNDS] [-p PRESET] [-o OUT_DIR]
#   -a/-b  the two evaluate binaries (A: e.g. the previous release's build, B: this tree's)
#   -c/-C  their --config (default: each binary's own; a release's config/laser_odometry.yaml for A)
#   -n     rounds per log (default 3); -p preset (default medium); -o run logs (default /tmp/hglasm_cpu_compare)
# Example (the previous release in a worktree):
#   git worktree add --detach /tmp/release 2b92baf && (cd /tmp/release && source scripts/env.sh && hglasm_build --target evaluate)
#   scripts/cpu_compare.sh -a /tmp/release/build/devel/lib/hglasm_odometry/evaluate \
#     -c /tmp/release/config/laser_odometry.yaml -b build/devel/lib/hglasm_odometry/evaluate
set -euo pipefail

package_dir="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
datasets="$package_dir/../shared/datasets"
logs="fr079 aces fr-clinic"
rounds=3
preset=medium
out_dir=/tmp/hglasm_cpu_compare
eval_a="" eval_b="" config_a="" config_b=""
while getopts "a:b:c:C:d:l:n:p:o:h" option; do
  case "$option" in
    a) eval_a="$OPTARG" ;;
    b) eval_b="$OPTARG" ;;
    c) config_a="$OPTARG" ;;
    C) config_b="$OPTARG" ;;
    d) datasets="$OPTARG" ;;
    l) logs="$OPTARG" ;;
    n) rounds="$OPTARG" ;;
    p) preset="$OPTARG" ;;
    o) out_dir="$OPTARG" ;;
    h) sed -n '2,15p' "$0"; exit 0 ;;
    *) sed -n '2,15p' "$0" >&2; exit 2 ;;
  esac
done
for binary in "$eval_a" "$eval_b"; do
  if [[ -z "$binary" || ! -x "$binary" ]]; then
    echo "cpu_compare: pass both evaluate binaries (-a, -b); '$binary' is not executable" >&2
    exit 2
  fi
done
export ROS_PACKAGE_PATH="$package_dir${ROS_PACKAGE_PATH:+:$ROS_PACKAGE_PATH}"
mkdir -p "$out_dir"

# Prints "mean median p99" of the total per scan (CPU) row of an evaluate log.
cpu_of() { awk '/total per scan \(CPU\)/ {print $9, $6, $7}' "$1"; }

run() {  # run LABEL BINARY CONFIG LOG ROUND
  local label="$1" binary="$2" config="$3" log="$4" round="$5"
  local out="$out_dir/${log}_${label}_${round}.log"
  local args=(--bag "$datasets/$log/$log.orig.bag" --preset "$preset" --quiet)
  [[ -n "$config" ]] && args+=(--config "$config")
  "$binary" "${args[@]}" >"$out" 2>&1 || { echo "cpu_compare: $binary failed on $log, see $out" >&2; exit 1; }
  cpu_of "$out"
}

printf "%-10s %5s | %-22s | %-22s | %s\n" log round "A mean/median/p99 ms" "B mean/median/p99 ms" "B/A mean median p99"
for log in $logs; do
  rows="$out_dir/${log}_rows.txt"
  : >"$rows"
  for round in $(seq 1 "$rounds"); do
    echo "$(run A "$eval_a" "$config_a" "$log" "$round") $(run B "$eval_b" "$config_b" "$log" "$round")" >>"$rows"
  done
  # Per round, then the ratio of the sums over the rounds.
  awk -v name="$log" '{
      printf "%-10s %5d | %6.3f %6.3f %7.3f | %6.3f %6.3f %7.3f | %5.2f %5.2f %5.2f\n", name, NR, $1, $2, $3, $4, $5,
        $6, $4 / $1, $5 / $2, $6 / $3
      for (i = 1; i <= 6; ++i) sum[i] += $i
    } END {
      printf "%-10s %5s | %22s | %22s | %5.2f %5.2f %5.2f\n", name, "all", "", "", sum[4] / sum[1], sum[5] / sum[2],
        sum[6] / sum[3]
    }' "$rows"
done
