#!/usr/bin/env bash
# Reproduces the papers' Success-Ratio experiments on real scans (intel and fr079 by default) with the
# `success_ratio` command, all algorithms and presets, and prints one summary table.
#
# Per log, two runs (same seed, so a case draws the same trials in both):
#   1. headline: 20 deg + 0.57 m and errors uniform in each preset's whole box (--in-box), HEADLINE
#      trials per cell, plus the GA-alone curves of pre-alignment success vs fitness evaluations
#      (GLASM-g vs binary GLASM, the papers' Figures 5/6), CURVE trials per point;
#   2. sweep: the papers' grid, rotation 0..180 deg x translation 0.14/0.57/1.13/2.12 m (52 cases),
#      SWEEP trials per cell (fewer, to keep the runtime sane), with the Figures 7/8 plots.
# Outputs in OUT_DIR/<log>/: headline.csv, headline_evaluations.csv, sweep.csv, *.log and plots/*.png;
# the summary in OUT_DIR/summary.txt.
# Runtime on the 2-core development machine with the defaults: about 8 min (about 4 min of CPU per
# bag; -s 500: about 15 min).
#
# usage: scripts/success_ratio_experiments.sh [-e BIN] [-b BUILD_DIR] [-d DATASETS] [-o OUT_DIR]
#            [-l "intel fr079"] [-n HEADLINE] [-s SWEEP] [-c CURVE] [-S SEED]
#   -e  the success_ratio binary (default: $SUCCESS_RATIO; otherwise it is built, see -b)
#   -b  catkin build directory to build success_ratio in (default: $HGLASM_BUILD, else <package>/build,
#       as scripts/env.sh; configured with plain cmake if it has no CMakeCache.txt)
#   -d  datasets folder (default: <package>/../shared/datasets)
#   -o  output folder (default: <package>/output/success_ratio)
#   -l  logs: any of intel fr079 laserazos (default: "intel fr079")
#   -n  trials per headline and in-box cell (default 500)
#   -s  trials per sweep cell (default 200; 0 skips the sweep; -s 500 gives every cell 500 trials)
#   -c  trials per point of the fitness-evaluation curves (default 500)
#   -S  seed (default 1)
set -euo pipefail

package_dir="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
# PATH with Debian's python3 first (catkin), ROS_HOME, HGLASM_BUILD.
# shellcheck source=env.sh
source "$package_dir/scripts/env.sh"
binary="${SUCCESS_RATIO:-}"
build_dir="${HGLASM_BUILD:-$package_dir/build}"
datasets="$package_dir/../shared/datasets"
out_dir="$package_dir/output/success_ratio"
logs="intel fr079"
headline_trials=500
sweep_trials=200
curve_trials=500
seed=1

usage() { sed -n '2,27p' "$0" | sed 's/^# \{0,1\}//'; }
while getopts "e:b:d:o:l:n:s:c:S:h" option; do
  case "$option" in
    e) binary="$OPTARG" ;;
    b) build_dir="$OPTARG" ;;
    d) datasets="$OPTARG" ;;
    o) out_dir="$OPTARG" ;;
    l) logs="$OPTARG" ;;
    n) headline_trials="$OPTARG" ;;
    s) sweep_trials="$OPTARG" ;;
    c) curve_trials="$OPTARG" ;;
    S) seed="$OPTARG" ;;
    h) usage; exit 0 ;;
    *) usage >&2; exit 2 ;;
  esac
done
for number in "$headline_trials" "$sweep_trials" "$curve_trials" "$seed"; do
  [[ "$number" =~ ^[0-9]+$ ]] || { echo "success_ratio_experiments: not a number: '$number'" >&2; exit 2; }
done
((headline_trials > 0)) || { echo "success_ratio_experiments: -n must be positive" >&2; exit 2; }

if [[ -z "$binary" ]]; then
  if [[ ! -f "$build_dir/CMakeCache.txt" ]]; then
    echo "== configuring $build_dir" >&2
    cmake -S "$package_dir" -B "$build_dir" -DCMAKE_BUILD_TYPE=Release \
      -DPYTHON_EXECUTABLE=/usr/bin/python3 -DPython3_EXECUTABLE=/usr/bin/python3 \
      -DCATKIN_DEVEL_PREFIX="$build_dir/devel" >&2
  fi
  echo "== building success_ratio in $build_dir" >&2
  cmake --build "$build_dir" --target success_ratio -j2 >&2
  devel="$(sed -n 's/^CATKIN_DEVEL_PREFIX:[A-Z]*=//p' "$build_dir/CMakeCache.txt")"
  binary="${devel:-$build_dir/devel}/lib/hglasm_odometry/success_ratio"
fi
[[ -x "$binary" ]] || { echo "success_ratio_experiments: no success_ratio binary at '$binary'" >&2; exit 2; }

input=()
set_input() {  # sets `input` to the input flags of one log
  case "$1" in
    intel) input=(--bag "$datasets/intel/intel.orig.bag") ;;
    fr079) input=(--bag "$datasets/fr079/fr079.orig.bag") ;;
    laserazos) input=(--carmen "$datasets/laserazos/laserazosSM3.log") ;;
    *) echo "success_ratio_experiments: unknown log '$1' (intel, fr079, laserazos)" >&2; exit 2 ;;
  esac
  [[ -f "${input[1]}" ]] || { echo "success_ratio_experiments: missing ${input[1]}" >&2; exit 2; }
}
for log in $logs; do set_input "$log"; done

mkdir -p "$out_dir"
start_all=$SECONDS
timings=""
for log in $logs; do
  set_input "$log"
  dir="$out_dir/$log"
  mkdir -p "$dir/plots"
  echo "== $log: headline 20 deg + 0.57 m and in-box, $headline_trials trials; curves $curve_trials trials" >&2
  start=$SECONDS
  "$binary" "${input[@]}" --trials "$headline_trials" --seed "$seed" --cases 20:0.57 --in-box \
    --curve-trials "$curve_trials" --csv "$dir/headline.csv" --plots "$dir/plots" --title "$log" \
    2> >(tee "$dir/headline.log" >&2)
  timings+="$log headline+in-box+curves: $((SECONDS - start)) s"$'\n'
  if ((sweep_trials > 0)); then
    echo "== $log: sweep of the papers' 52 cases, $sweep_trials trials" >&2
    start=$SECONDS
    "$binary" "${input[@]}" --trials "$sweep_trials" --seed "$seed" --cases paper --curve-trials 0 \
      --csv "$dir/sweep.csv" --plots "$dir/plots" --title "$log" 2> >(tee "$dir/sweep.log" >&2)
    timings+="$log sweep: $((SECONDS - start)) s"$'\n'
  fi
done
wait  # the tee processes

summary() {
  echo "Success-Ratio experiments (seed $seed; success = |dxy| < 0.10 m and |dtheta| < 0.01 rad after MbICP,"
  echo "0.30 m and 0.1 rad for the GA alone: glasm_g, glasm_binary). ms = mean wall time per match,"
  echo "lookup-table build included, one thread."
  for log in $logs; do
    dir="$out_dir/$log"
    echo
    echo "== $log: 20 deg + 0.57 m and in-box (errors uniform in the preset's box), $headline_trials trials per cell"
    awk -F, 'NR > 1 {
        key = $1 " " $2; if (!(key in seen)) { seen[key] = 1; order[++n] = key }
        cell = ($3 == "box") ? "box" : "head"
        text[key, cell] = sprintf("%5.1f%% %6.3f %6.2f %7.2f", 100 * $7, $8, $9, $10)
      }
      END {
        printf "%-14s %-6s | %-31s | %-31s\n", "algorithm", "preset", "20deg+0.57m: succ dxy(m) dth(deg) ms", "in-box: succ dxy(m) dth(deg) ms"
        for (i = 1; i <= n; ++i) {
          split(order[i], part, " ")
          printf "%-14s %-6s | %-36s | %s\n", part[1], part[2], text[order[i], "head"], text[order[i], "box"]
        }
      }' "$dir/headline.csv"
    if [[ -f "$dir/headline_evaluations.csv" ]]; then
      echo
      echo "-- $log: GA alone, pre-alignment success vs fitness evaluations (errors uniform in the box, $curve_trials trials)"
      # The two tables' GAs spend slightly different evaluations per generation count (elitism, the final
      # polish), so binary GLASM's success is read off its curve at GLASM-g's evaluation count (linear
      # interpolation between its neighbouring points; points outside its range are not compared).
      awk -F, 'NR > 1 {
          preset = $2
          if (!(preset in seen)) { seen[preset] = 1; presets[++np] = preset }
          k = ++count[preset, $1]
          gen[preset, $1, k] = $4; ev[preset, $1, k] = $7; su[preset, $1, k] = 100 * $9
        }
        END {
          printf "%-6s %4s %8s | %8s %16s %7s\n", "preset", "gen", "evals", "GLASM-g", "binary@same evals", "diff"
          for (p = 1; p <= np; ++p) {
            preset = presets[p]; nb = count[preset, "glasm_binary"]
            for (i = 1; i <= count[preset, "glasm_g"]; ++i) {
              e = ev[preset, "glasm_g", i]; b = "none"
              for (j = 1; j < nb; ++j) {
                e0 = ev[preset, "glasm_binary", j]; e1 = ev[preset, "glasm_binary", j + 1]
                if (e >= e0 && e <= e1 && e1 > e0) {
                  b = su[preset, "glasm_binary", j] + (e - e0) / (e1 - e0) * (su[preset, "glasm_binary", j + 1] - su[preset, "glasm_binary", j])
                  break
                }
              }
              if (b == "none") {
                printf "%-6s %4s %8.0f | %7.1f%% %16s\n", preset, gen[preset, "glasm_g", i], e, su[preset, "glasm_g", i], "(out of range)"
                continue
              }
              d = su[preset, "glasm_g", i] - b; n++; wins += (d > 0.05); ties += (d >= -0.05 && d <= 0.05); total += d
              printf "%-6s %4s %8.0f | %7.1f%% %15.1f%% %+6.1f\n", preset, gen[preset, "glasm_g", i], e, su[preset, "glasm_g", i], b, d
            }
          }
          if (n > 0) printf "GLASM-g ahead at %d of %d equal-evaluation points (%d ties), mean difference %+.1f points\n", wins, n, ties, total / n
        }' "$dir/headline_evaluations.csv"
    fi
    if [[ -f "$dir/sweep.csv" ]] && ((sweep_trials > 0)); then
      for translation in 0.57 2.12; do
        echo
        echo "-- $log: sweep, success % vs rotation error at $translation m, $sweep_trials trials per cell"
        awk -F, -v t="$translation" 'NR > 1 && $3 != "box" && $4 + 0 == t + 0 {
            key = $1 " " $2; if (!(key in seen)) { seen[key] = 1; order[++n] = key }
            if (!($3 in rot_seen)) { rot_seen[$3] = 1; rots[++m] = $3 }
            succ[key, $3] = 100 * $7
          }
          END {
            printf "%-21s", "algorithm preset \\ deg"; for (j = 1; j <= m; ++j) printf " %4s", rots[j]; printf "\n"
            for (i = 1; i <= n; ++i) {
              printf "%-21s", order[i]; for (j = 1; j <= m; ++j) printf " %4.0f", succ[order[i], rots[j]]; printf "\n"
            }
          }' "$dir/sweep.csv"
      done
    fi
    echo
    echo "plots: $dir/plots/success_<algorithm>_<preset>.png (Figures 7/8), $dir/plots/evaluations_<preset>.png (Figures 5/6)"
  done
  echo
  echo "runtime:"
  printf "%s" "$timings"
  echo "total: $((SECONDS - start_all)) s"
}
summary | tee "$out_dir/summary.txt"
