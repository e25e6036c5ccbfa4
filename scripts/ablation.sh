#!/usr/bin/env bash
# The ablation and seed tables of doc/accuracy.md: `evaluate` on intel, fr079, aces and fr-clinic with the
# shipped configuration changed by one setting at a time, GA seeds 1 2 3 each, and the mean over the seeds of
# the <= 10 s and all-relations errors (m / deg), with each seed's all-relations figures.
#
# usage: scripts/ablation.sh [-e EVALUATE] [-d DATASETS] [-o OUT_DIR] [-l "intel fr079"] [-n "1 2 3"]
#                            [VARIANT ...]
#   VARIANT  name:key=value[,key=value...] (keys as in config/laser_odometry.yaml, slash-separated), e.g.
#            scan:scan_noise/learn=true   k7:local_map/keyframes=7
#            default: the variants of doc/accuracy.md
set -euo pipefail

package_dir="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
evaluate="$(ls -t "$package_dir"/build*/devel/lib/hglasm_odometry/evaluate 2>/dev/null | head -n1 || true)"
datasets="$package_dir/../shared/datasets"
out_dir=/tmp/hglasm_ablation
logs="intel fr079 aces fr-clinic"
seeds="1 2 3"
while getopts "e:d:o:l:n:h" option; do
  case "$option" in
    e) evaluate="$OPTARG" ;;
    d) datasets="$OPTARG" ;;
    o) out_dir="$OPTARG" ;;
    l) logs="$OPTARG" ;;
    n) seeds="$OPTARG" ;;
    *) sed -n '2,10p' "$0"; exit 2 ;;
  esac
done
shift $((OPTIND - 1))
variants=("$@")
if ((${#variants[@]} == 0)); then
  variants=(default: scan:scan_noise/learn=true "scan_one:scan_noise/learn=true,scan_noise/directional=false"
            nothing_learned:odometry/noise/learn=false no_calibration:odometry/calibration/learn=false
            "calibration_all:odometry/calibration/heading_per_metre=0.02,odometry/calibration/distance_scale=0.05"
            keyframes_7:local_map/keyframes=7)
fi
[[ -x "$evaluate" ]] || { echo "ablation: evaluate not found; build it or pass -e" >&2; exit 2; }
export ROS_PACKAGE_PATH="$package_dir${ROS_PACKAGE_PATH:+:$ROS_PACKAGE_PATH}"
mkdir -p "$out_dir"

# A copy of the shipped YAML with slash-separated keys set (nested maps created as needed).
make_config() {
  /usr/bin/python3 - "$package_dir/config/laser_odometry.yaml" "$1" "$2" <<'PY'
import sys, yaml
base, settings, out = sys.argv[1], sys.argv[2], sys.argv[3]
config = yaml.safe_load(open(base))
for item in filter(None, settings.split(',')):
    key, value = item.split('=', 1)
    node, parts = config, key.split('/')
    for part in parts[:-1]:
        node = node.setdefault(part, {})
    node[parts[-1]] = yaml.safe_load(value)
yaml.safe_dump(config, open(out, 'w'))
PY
}

for variant in "${variants[@]}"; do
  name="${variant%%:*}" settings="${variant#*:}"
  for seed in $seeds; do
    config="$out_dir/${name}_$seed.yaml"
    make_config "${settings:+$settings,}genetic/seed=$seed" "$config"
    for log in $logs; do
      "$evaluate" --bag "$datasets/$log/$log.orig.bag" --relations "$datasets/$log/$log.relations" --quiet \
        --config "$config" --presets "$package_dir/config/presets.yaml" > "$out_dir/${name}_${seed}_$log.log" 2>&1 &
      while (($(jobs -r | wc -l) >= $(nproc))); do sleep 1; done
    done
  done
  wait
  for log in $logs; do
    /usr/bin/python3 - "$name" "$log" $(for seed in $seeds; do echo "$out_dir/${name}_${seed}_$log.log"; done) <<'PY'
import sys
name, log, files = sys.argv[1], sys.argv[2], sys.argv[3:]
rows = []
for path in files:
    line = [l for l in open(path) if l.startswith('SUMMARY')][-1]
    rows.append(dict(f.split('=', 1) for f in line.split()[1:]))
mean = lambda key: sum(float(r[key]) for r in rows) / len(rows)
print(f"{name:16s} {log:9s} <=10s {mean('short_t'):.4f} / {mean('short_r'):.3f}  all {mean('all_t'):.3f} / "
      f"{mean('all_r'):.2f}  (seeds: {', '.join(r['all_t'][:5] + ' / ' + r['all_r'][:4] for r in rows)})  "
      f"calib {mean('calibration'):.2f}  leap max {max(float(r['worst_leap']) for r in rows):.2f}")
PY
  done
done
