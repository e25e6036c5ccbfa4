#!/usr/bin/env bash
# Reproduces the papers' Success-Ratio experiments on real scans (intel, fr079 and aces by default) with
# the `success_ratio` command, all algorithms (PGA and HPGA included) and presets, and prints one summary
# table with each log's ceiling (success at zero initial error).
#
# Per log, two runs (same seed, so a case draws the same trials in both):
#   1. headline: 20 deg + 0.57 m and errors uniform in each preset's whole box (--in-box), HEADLINE
#      trials per cell, every algorithm, with the ceiling beside every cell; plus the GA-alone curves of
#      pre-alignment success and mean / median errors vs fitness evaluations (GLASM-g, binary GLASM and
#      PGA: the papers' Figure 5) and the time each needs to reach 50..95 % (Figure 6), CURVE trials per
#      point;
#   2. sweep: the papers' grid, rotation 0..180 deg x translation 0.14/0.57/1.13/2.12 m (52 cases),
#      SWEEP trials per cell (fewer, to keep the runtime sane), with the Figures 7/8 plots; the lookup-
#      table algorithms and MbICP only (SWEEP_ALGORITHMS: PGA's search costs 10x theirs).
# fr079 (interlaced sweeps, odd beams 14 ms after the even ones) also gets its ceiling with the interlace
# accounted for: --interlace-seconds 0.014, the turn rate from the bag's wheel odometry.
# Outputs in OUT_DIR/<log>/: headline.csv, headline_evaluations.csv, headline_time_to_reach.csv,
# sweep.csv, ceiling_interlace.csv (fr079), *.log and plots/*.png; the summary in OUT_DIR/summary.txt.
# Runtime on the 2-core development machine with the defaults: see the README ("Success ratio").
#
# usage: scripts/success_ratio_experiments.sh [-e BIN] [-b BUILD_DIR] [-d DATASETS] [-o OUT_DIR]
#            [-l "intel fr079 aces"] [-n HEADLINE] [-s SWEEP] [-c CURVE] [-S SEED]
#   -e  the success_ratio binary (default: $SUCCESS_RATIO; otherwise it is built, see -b)
#   -b  catkin build directory to build success_ratio in (default: $HGLASM_BUILD, else <package>/build,
#       as scripts/env.sh; configured with plain cmake if it has no CMakeCache.txt)
#   -d  datasets folder (default: <package>/../shared/datasets)
#   -o  output folder (default: <package>/output/success_ratio)
#   -l  logs: any of intel fr079 aces laserazos (default: "intel fr079 aces")
#   -n  trials per headline and in-box cell (default 500)
#   -s  trials per sweep cell (default 200; 0 skips the sweep; -s 500 gives every cell 500 trials)
#   -c  trials per point of the fitness-evaluation curves (default 500)
#   -S  seed (default 1)
#   -R  report only: print the summary of the outputs already in OUT_DIR (no runs)
set -euo pipefail

package_dir="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
# PATH with Debian's python3 first (catkin), ROS_HOME, HGLASM_BUILD.
# shellcheck source=env.sh
source "$package_dir/scripts/env.sh"
binary="${SUCCESS_RATIO:-}"
build_dir="${HGLASM_BUILD:-$package_dir/build}"
datasets="$package_dir/../shared/datasets"
out_dir="$package_dir/output/success_ratio"
logs="intel fr079 aces"
sweep_algorithms="hglasm_g,hglasm_binary,glasm_g,glasm_binary,mbicp"
headline_trials=500
sweep_trials=200
curve_trials=500
seed=1

usage() { sed -n '2,35p' "$0" | sed 's/^# \{0,1\}//'; }
report_only=0
while getopts "e:b:d:o:l:n:s:c:S:Rh" option; do
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
    R) report_only=1 ;;
    h) usage; exit 0 ;;
    *) usage >&2; exit 2 ;;
  esac
done
for number in "$headline_trials" "$sweep_trials" "$curve_trials" "$seed"; do
  [[ "$number" =~ ^[0-9]+$ ]] || { echo "success_ratio_experiments: not a number: '$number'" >&2; exit 2; }
done
((headline_trials > 0)) || { echo "success_ratio_experiments: -n must be positive" >&2; exit 2; }

if ((report_only)); then
  binary=true  # nothing runs
elif [[ -z "$binary" ]]; then
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
((report_only)) || [[ -x "$binary" ]] || { echo "success_ratio_experiments: no success_ratio binary at '$binary'" >&2; exit 2; }

input=()
set_input() {  # sets `input` to the input flags of one log
  case "$1" in
    intel) input=(--bag "$datasets/intel/intel.orig.bag") ;;
    fr079) input=(--bag "$datasets/fr079/fr079.orig.bag") ;;
    aces) input=(--bag "$datasets/aces/aces.orig.bag") ;;
    laserazos) input=(--carmen "$datasets/laserazos/laserazosSM3.log") ;;
    *) echo "success_ratio_experiments: unknown log '$1' (intel, fr079, aces, laserazos)" >&2; exit 2 ;;
  esac
  [[ -f "${input[1]}" ]] || { echo "success_ratio_experiments: missing ${input[1]}" >&2; exit 2; }
}
for log in $logs; do set_input "$log"; done

mkdir -p "$out_dir"
start_all=$SECONDS
timings=""
((report_only)) && timings="nothing run (-R: the summary of earlier outputs)"$'\n'
for log in $logs; do
  ((report_only)) && break
  set_input "$log"
  dir="$out_dir/$log"
  mkdir -p "$dir/plots"
  echo "== $log: headline 20 deg + 0.57 m and in-box, $headline_trials trials; curves $curve_trials trials" >&2
  start=$SECONDS
  "$binary" "${input[@]}" --trials "$headline_trials" --seed "$seed" --cases 20:0.57 --in-box \
    --curve-trials "$curve_trials" --csv "$dir/headline.csv" --plots "$dir/plots" --title "$log" \
    2> >(tee "$dir/headline.log" >&2)
  timings+="$log headline+in-box+ceiling+curves: $((SECONDS - start)) s"$'\n'
  if [[ "$log" == fr079 ]]; then
    echo "== $log: ceiling with the interlace accounted for (odd beams 14 ms after the even ones)" >&2
    start=$SECONDS
    "$binary" "${input[@]}" --trials "$headline_trials" --seed "$seed" --cases 0:0 --no-ceiling \
      --curve-trials 0 --interlace-seconds 0.014 --csv "$dir/ceiling_interlace.csv" \
      2> >(tee "$dir/ceiling_interlace.log" >&2)
    timings+="$log ceiling with interlace: $((SECONDS - start)) s"$'\n'
  fi
  if ((sweep_trials > 0)); then
    echo "== $log: sweep of the papers' 52 cases, $sweep_trials trials" >&2
    start=$SECONDS
    "$binary" "${input[@]}" --trials "$sweep_trials" --seed "$seed" --cases paper --curve-trials 0 \
      --algorithms "$sweep_algorithms" \
      --csv "$dir/sweep.csv" --plots "$dir/plots" --title "$log" 2> >(tee "$dir/sweep.log" >&2)
    timings+="$log sweep: $((SECONDS - start)) s"$'\n'
  fi
done
wait  # the tee processes

summary() {
  echo "Success-Ratio experiments (seed $seed; success = |dxy| < 0.10 m and |dtheta| < 0.01 rad after MbICP,"
  echo "0.30 m and 0.1 rad for the GA alone: glasm_g, glasm_binary, pga). ms = mean wall time per match,"
  echo "reference preparation (lookup tables; PGA: the angular sort) included, one thread. ceiling = success"
  echo "of the same algorithm and preset at zero initial error (the halves matched from the identity)."
  echo
  echo "== all logs: success at 20 deg + 0.57 m / in the preset's whole box / ceiling (zero initial error)"
  files=()
  for log in $logs; do files+=("$out_dir/$log/headline.csv"); done
  awk -F, -v logs="$logs" 'FNR == 1 { ++file; next }
    {
      key = $1 " " $2; if (!(key in seen)) { seen[key] = 1; order[++n] = key }
      cell = ($3 == "box") ? "box" : "head"
      value[key, file, cell] = sprintf("%5.1f", 100 * $7)
      value[key, file, "ceiling"] = ($11 == "") ? "  -" : sprintf("%5.1f", 100 * $11)
    }
    END {
      count = split(logs, name, " ")
      printf "%-21s", "algorithm preset"
      for (f = 1; f <= count; ++f) printf " | %-19s", name[f] " 20/0.57 box ceil"
      printf "\n"
      for (i = 1; i <= n; ++i) {
        printf "%-21s", order[i]
        for (f = 1; f <= count; ++f)
          printf " | %5s %5s %5s    ", value[order[i], f, "head"], value[order[i], f, "box"], value[order[i], f, "ceiling"]
        printf "\n"
      }
    }' "${files[@]}"
  for log in $logs; do
    dir="$out_dir/$log"
    echo
    echo "== $log: 20 deg + 0.57 m and in-box (errors uniform in the preset's box), $headline_trials trials per cell"
    interlace="$dir/ceiling_interlace.csv"
    [[ -f "$interlace" && "$log" == fr079 ]] || interlace=""
    awk -F, -v interlace="$interlace" 'BEGIN {
        while ((getline line < interlace) > 0) {
          if (++lines == 1) continue
          split(line, field, ",")
          ceiling_interlace[field[1] " " field[2]] = sprintf("%5.1f%%", 100 * field[7])
        }
      }
      NR > 1 {
        key = $1 " " $2; if (!(key in seen)) { seen[key] = 1; order[++n] = key }
        cell = ($3 == "box") ? "box" : "head"
        text[key, cell] = sprintf("%5.1f%% %6.3f %6.2f %7.2f", 100 * $7, $8, $9, $10)
        ceiling[key] = ($11 == "") ? "  -" : sprintf("%5.1f%%", 100 * $11)
      }
      END {
        has_interlace = length(ceiling_interlace) > 0
        printf "%-14s %-6s | %-31s | %-31s | %7s%s\n", "algorithm", "preset", "20deg+0.57m: succ dxy(m) dth(deg) ms", "in-box: succ dxy(m) dth(deg) ms", "ceiling", has_interlace ? "  ceiling(interlace 14 ms)" : ""
        for (i = 1; i <= n; ++i) {
          split(order[i], part, " ")
          printf "%-14s %-6s | %-36s | %-31s | %7s", part[1], part[2], text[order[i], "head"], text[order[i], "box"], ceiling[order[i]]
          if (has_interlace) printf "  %s", ceiling_interlace[order[i]]
          printf "\n"
        }
      }' "$dir/headline.csv"
    if [[ -f "$dir/headline_evaluations.csv" ]]; then
      echo
      echo "-- $log: GA alone, pre-alignment success and median errors vs fitness evaluations (errors uniform in the box, $curve_trials trials)"
      # The GAs spend slightly different evaluations per generation count (elitism, the final polish), so
      # binary GLASM's and PGA's success is read off their curves at GLASM-g's evaluation count (linear
      # interpolation between neighbouring points; points outside a curve's range are not compared).
      awk -F, 'function at(preset, algorithm, e,    j, n, e0, e1) {
          n = count[preset, algorithm]
          for (j = 1; j < n; ++j) {
            e0 = ev[preset, algorithm, j]; e1 = ev[preset, algorithm, j + 1]
            if (e >= e0 && e <= e1 && e1 > e0)
              return su[preset, algorithm, j] + (e - e0) / (e1 - e0) * (su[preset, algorithm, j + 1] - su[preset, algorithm, j])
          }
          return "none"
        }
        NR > 1 {
          preset = $2
          if (!(preset in seen)) { seen[preset] = 1; presets[++np] = preset }
          k = ++count[preset, $1]
          gen[preset, $1, k] = $4; ev[preset, $1, k] = $7; su[preset, $1, k] = 100 * $9
          md[preset, $1, k] = sprintf("%.3f/%.2f", $13, $14)
        }
        END {
          printf "%-6s %4s %8s | %8s %9s %9s | %14s %14s %14s\n", "preset", "gen", "evals", "GLASM-g", "binary@=", "PGA@=", "g med m/deg", "bin med", "PGA med"
          for (p = 1; p <= np; ++p) {
            preset = presets[p]
            for (i = 1; i <= count[preset, "glasm_g"]; ++i) {
              e = ev[preset, "glasm_g", i]; g = su[preset, "glasm_g", i]
              b = at(preset, "glasm_binary", e); q = at(preset, "pga", e)
              printf "%-6s %4s %8.0f | %7.1f%% %9s %9s | %14s %14s %14s\n", preset, gen[preset, "glasm_g", i], e, g, \
                (b == "none") ? "-" : sprintf("%.1f%%", b), (q == "none") ? "-" : sprintf("%.1f%%", q), \
                md[preset, "glasm_g", i], md[preset, "glasm_binary", i], md[preset, "pga", i]
              if (b != "none") { nb++; db += g - b; wb += (g - b > 0.05); lb += (g - b < -0.05) }
              if (q != "none") { nq++; dq += g - q; wq += (g - q > 0.05); lq += (g - q < -0.05) }
            }
          }
          if (nb > 0) printf "GLASM-g vs binary GLASM at equal evaluations: ahead at %d, behind at %d of %d points, mean %+.1f points\n", wb, lb, nb, db / nb
          if (nq > 0) printf "GLASM-g vs PGA at equal evaluations: ahead at %d, behind at %d of %d points, mean %+.1f points\n", wq, lq, nq, dq / nq
        }' "$dir/headline_evaluations.csv"
    fi
    if [[ -f "$dir/headline_time_to_reach.csv" ]]; then
      echo
      echo "-- $log: GA alone, ms per match to reach a success ratio (fewest generations reaching it; search only / with preparation)"
      awk -F, 'NR > 1 {
          key = $2 " " $1; if (!(key in seen)) { seen[key] = 1; order[++n] = key }
          if (!($3 in lseen)) { lseen[$3] = 1; levels[++m] = $3 }
          cell[key, $3] = ($4 == 1) ? sprintf("%.2f/%.2f", $8, $9) : "not reached"
        }
        END {
          printf "%-20s", "preset algorithm"; for (j = 1; j <= m; ++j) printf " %13s", (100 * levels[j]) "%"; printf "\n"
          for (i = 1; i <= n; ++i) { printf "%-20s", order[i]; for (j = 1; j <= m; ++j) printf " %13s", cell[order[i], levels[j]]; printf "\n" }
        }' "$dir/headline_time_to_reach.csv"
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
    echo "plots: $dir/plots/success_<algorithm>_<preset>.png (Figures 7/8), $dir/plots/evaluations_<preset>.png (Figure 5),"
    echo "       $dir/plots/time_to_reach.png (Figure 6)"
  done
  echo
  echo "runtime:"
  printf "%s" "$timings"
  echo "total: $((SECONDS - start_all)) s"
}
summary | tee "$out_dir/summary.txt"
