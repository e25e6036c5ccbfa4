#!/usr/bin/env bash
# Runs `evaluate` on the Freiburg relations benchmark logs (intel, fr079, aces, fr-clinic) for every preset
# and prints one table: relations metric (all and <= 10 s, and the <= 10 s median translation) of the laser
# odometry next to the raw wheel odometry, the wheels' time offset found (odometry/time_offset), fallbacks,
# CPU per scan, the covariance calibration (mean squared Mahalanobis distance of the <= 10 s relations; 3 is
# honest), the along-track scale of the <= 10 s relations that move >= 0.1 m (laser/wheels: the distance
# travelled along the reference's direction over the reference's; 1 is unbiased), the leap ratio (largest
# <= 10 s error / (3 x the wheels' + 0.10 m); above 1 is a leap) and the timing of laser and wheels against
# the reference (ms) and their turn scale against it (%), fitted jointly: heading error = timing x change of
# turn rate + turn scale x the reference's turn (0 / 0: the reference's clock and turns). Logs,
# trajectories, traces and plots of each run go to the output directory.
#
# usage: scripts/evaluate_all.sh [-e EVALUATE] [-d DATASETS] [-o OUT_DIR] [-p "small medium large"]
#                                [-l "intel fr079"] [-- extra evaluate arguments]
#   -e  the evaluate binary (default: $EVALUATE, then `catkin_find hglasm_odometry evaluate`, then the
#       newest build*/devel/lib/hglasm_odometry/evaluate in the package (scripts/env.sh's hglasm_build) or
#       beside it (a catkin workspace))
#   -d  the datasets folder (default: <package>/../shared/datasets)
#   -o  where run logs, trajectories and plots go (default: /tmp/hglasm_evaluate_all)
#   -p  presets (default: the top-level keys of config/presets.yaml, else "small medium large")
#   -l  logs (default: "intel fr079 aces fr-clinic")
# Example: scripts/evaluate_all.sh -e /work/build/devel/lib/hglasm_odometry/evaluate -- --config /tmp/my.yaml
set -euo pipefail

package_dir="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
evaluate="${EVALUATE:-}"
datasets="$package_dir/../shared/datasets"
out_dir="/tmp/hglasm_evaluate_all"
presets=""
logs="intel fr079 aces fr-clinic"

while getopts "e:d:o:p:l:h" option; do
  case "$option" in
    e) evaluate="$OPTARG" ;;
    d) datasets="$OPTARG" ;;
    o) out_dir="$OPTARG" ;;
    p) presets="$OPTARG" ;;
    l) logs="$OPTARG" ;;
    h) sed -n '2,21p' "$0"; exit 0 ;;
    *) sed -n '2,21p' "$0" >&2; exit 2 ;;
  esac
done
shift $((OPTIND - 1))
[[ "${1:-}" == "--" ]] && shift
extra_args=("$@")

if [[ -z "$evaluate" ]] && command -v catkin_find >/dev/null 2>&1; then
  evaluate="$(catkin_find --first-only hglasm_odometry evaluate 2>/dev/null | head -n1 || true)"
  [[ -x "$evaluate" ]] || evaluate=""  # catkin_find also names install paths that do not exist
fi
if [[ -z "$evaluate" ]]; then
  evaluate="$(ls -t "$package_dir"/build*/devel/lib/hglasm_odometry/evaluate \
                    "$package_dir"/../build*/devel/lib/hglasm_odometry/evaluate 2>/dev/null | head -n1 || true)"
fi
if [[ -z "$evaluate" || ! -x "$evaluate" ]]; then
  echo "evaluate_all: evaluate binary not found; build it and pass -e PATH (or set EVALUATE)" >&2
  exit 2
fi

if [[ -z "$presets" ]]; then
  presets_yaml="$package_dir/config/presets.yaml"
  if [[ -f "$presets_yaml" ]]; then
    presets="$(/usr/bin/python3 -c 'import sys, yaml
d = yaml.safe_load(open(sys.argv[1])) or {}
d = d.get("presets", d) if isinstance(d, dict) else {}
print(" ".join(k for k, v in d.items() if isinstance(v, dict)))' "$presets_yaml")"
  fi
  [[ -n "$presets" ]] || presets="small medium large"
fi

# evaluate's default config (and presets.yaml beside it) is this package's, found through ROS_PACKAGE_PATH.
export ROS_PACKAGE_PATH="$package_dir${ROS_PACKAGE_PATH:+:$ROS_PACKAGE_PATH}"

mkdir -p "$out_dir"
echo "evaluate: $evaluate"
echo "runs:     $out_dir/<log>_<preset>.{log,txt,png}"
[[ ${#extra_args[@]} -gt 0 ]] && echo "extra:    ${extra_args[*]}"
echo

header=$(printf "%-9s %-6s %5s %8s %19s | %-17s %-17s %-13s %-13s | %-17s %-17s | %5s %5s %6s %11s %11s" \
  log preset scans fallback "CPU ms med/p99/max" "<=10s laser m/deg" "<=10s wheel" "median l/w m" \
  "scale l/w" "all laser m/deg" "all wheel" calib leap offset "timing l/w" "turns l/w %")
echo "$header"
printf '%*s\n' "${#header}" '' | tr ' ' '-'

status=0
for log in $logs; do
  bag="$datasets/$log/$log.orig.bag"
  relations="$datasets/$log/$log.relations"
  if [[ ! -f "$bag" || ! -f "$relations" ]]; then
    echo "$log: $bag or $relations missing, skipped" >&2
    status=1
    continue
  fi
  for preset in $presets; do
    run="$out_dir/${log}_${preset}"
    if ! "$evaluate" --bag "$bag" --relations "$relations" --preset "$preset" --quiet \
         --out "$run.txt" --trace "$run.trace" --plot "$run.png" "${extra_args[@]}" >"$run.log" 2>&1; then
      printf "%-9s %-6s evaluate failed, see %s\n" "$log" "$preset" "$run.log"
      status=1
      continue
    fi
    summary="$(grep '^SUMMARY' "$run.log" | tail -n1)"
    field() { sed -n "s/.* $1=\([^ ]*\).*/\1/p" <<<"$summary"; }
    printf "%-9s %-6s %5s %7s%% %19s | %-17s %-17s %-13s %-13s | %-17s %-17s | %5s %5s %6s %11s %11s\n" "$log" "$preset" \
      "$(field scans)" "$(field fallback_pct)" "$(field cpu_median_ms)/$(field cpu_p99_ms)/$(field cpu_max_ms)" \
      "$(field short_t) / $(field short_r)" "$(field wheel_short_t) / $(field wheel_short_r)" \
      "$(field short_t_median)/$(field wheel_short_t_median)" "$(field short_scale)/$(field wheel_short_scale)" \
      "$(field all_t) / $(field all_r)" "$(field wheel_all_t) / $(field wheel_all_r)" \
      "$(printf %.2f "$(field calibration)")" "$(printf %.2f "$(field worst_leap)")" "$(field time_offset)" \
      "$(field timing_ms)/$(field wheel_timing_ms)" "$(field turn_scale_pct)/$(field wheel_turn_scale_pct)"
  done
done
exit $status
