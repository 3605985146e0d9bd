#!/usr/bin/env bash
# tools/scripts/report.sh — rebuilds the experiment report from scratch into out/report/: the paper's
# Table 1 and Figs. 8, 9, 10, the uniqueness figure (§6.3), speed against accuracy (crystal_balls
# and a sakura_tree snapshot), tolerance against force error, scaling, and the near field
# (two balls against exact magnetostatics; cost per step of dipole and pair, per scene), as CSV/JSON + PNG
# charts + index.md. About 10–25 minutes on 2 cores.
#
#   bash tools/scripts/report.sh            reduced Fig. 9 grid (11 × 101 cells × 64 directions)
#   bash tools/scripts/report.sh --quick    shorter benchmark windows, no 10,000-ball scaling point
# The full-resolution Fig. 9 is separate (hours):
#   build/release/tools/experiments fig9 --dt-steps 51 --h-steps 1001 --dirs 10000 --shard i/n
set -euo pipefail
cd "$(dirname "$0")/../.."
quick=0
for a in "$@"; do
  case "$a" in
    --quick) quick=1 ;;
    -h|--help) awk 'NR > 1 && /^#/ { sub(/^# ?/, ""); print; next } NR > 1 { exit }' "$0"; exit 0 ;;
    *) echo "report.sh: unknown option '$a' (try --help)" >&2; exit 2 ;;
  esac
done
bash tools/scripts/setup.sh --no-demo
out=out/report
rm -rf "$out"
mkdir -p "$out"
bin=build/release/tools
t0=$(date +%s)
echo "== Fig. 8 and uniqueness";  $bin/experiments fig8 --out "$out" | tee "$out/fig8.txt"
echo "== Fig. 9 (reduced grid)";  $bin/experiments fig9 --out "$out" --methods all | tee "$out/fig9.txt"
echo "== Fig. 10";                $bin/experiments fig10 --out "$out" | tee "$out/fig10.txt"
echo "== speed against accuracy"; $bin/experiments speed --out "$out" | tee "$out/speed.txt"
# both step sakura_tree to the same snapshot (cached in $out/sakura_snapshot.json): ~1 min together
echo "== speed against accuracy, sakura_tree snapshot"
$bin/experiments snapshot-speed --out "$out" | tee "$out/snapshot_speed.txt"
echo "== tolerance against force error and scene outcome"
$bin/experiments tolerance --out "$out" | tee "$out/tolerance.txt"
if [ "$quick" -eq 1 ]; then
  echo "== Table 1 and scaling (quick)"
  $bin/bench --warmup 300 --steps 50 --scaling 250,1000,2500 --json "$out/bench.json" | tee "$out/bench.txt"
else
  echo "== Table 1 and scaling"
  $bin/bench --json "$out/bench.json" | tee "$out/bench.txt"
fi
if [ -x $bin/bench_kernel ]; then
  echo "== kernel throughput"
  $bin/bench_kernel --json "$out/kernel.json" | tee "$out/kernel.txt"
fi
echo "== two balls: dipole and pair model against exact magnetostatics"
/usr/bin/python3 tools/reference/near_field_chart.py --out "$out" --magsolve $bin/magsolve | tee "$out/near_field.txt"
echo "== near field: cost per step of dipole and pair, per scene"
$bin/bench --scenes balls_up,falling_magnet,sakura_tree --methods anderson --scaling none --near-field-cost \
    --json "$out/near_field_cost.json" | tee "$out/near_field_cost.txt"
/usr/bin/python3 tools/scripts/charts.py "$out"
/usr/bin/python3 tools/scripts/report_index.py "$out"
echo "report: $out/index.md ($(( $(date +%s) - t0 )) s)"
