#!/usr/bin/env bash
# tools/scripts/scene_matrix.sh — every scene under every method for S simulated seconds (default 2),
# frames included, then a Markdown table of the per-step medians and final metrics.
#
#   bash tools/scripts/scene_matrix.sh [--seconds S] [--scenes a,b] [--methods a,b] [--no-render] [--out DIR]
# Writes DIR/<scene>_<method>/ (summary.json, states.csv, moments.csv, frames) and
# DIR/table.md (default DIR: out/matrix). Sequential; at 2 s the five scenes × five methods take
# about 40–60 minutes on 2 cores (sakura_tree under the methods that hit their cap dominates).
set -euo pipefail
cd "$(dirname "$0")/../.."
seconds=2
scenes=balls_up,alphabets,falling_magnet,sakura_tree,crystal_balls
methods=ours-realigned,ours,kim2018,damping-llg,anderson
out=out/matrix
render=()
while [ $# -gt 0 ]; do
  case "$1" in
    --seconds) seconds="$2"; shift 2 ;;
    --scenes) scenes="$2"; shift 2 ;;
    --methods) methods="$2"; shift 2 ;;
    --out) out="$2"; shift 2 ;;
    --no-render) render=(--no-render); shift ;;
    -h|--help) awk 'NR > 1 && /^#/ { sub(/^# ?/, ""); print; next } NR > 1 { exit }' "$0"; exit 0 ;;
    *) echo "scene_matrix.sh: unknown option '$1' (try --help)" >&2; exit 2 ;;
  esac
done
bin=build/release/tools/magsim-scene
[ -x "$bin" ] || { echo "scene_matrix.sh: $bin not built (run tools/scripts/setup.sh --no-demo)" >&2; exit 1; }
mkdir -p "$out"
IFS=, read -ra S <<< "$scenes"
IFS=, read -ra M <<< "$methods"
status=0
for s in "${S[@]}"; do
  for m in "${M[@]}"; do
    d="$out/${s}_${m}"
    rm -rf "$d"
    echo "== $s $m" >&2
    if ! "$bin" "$s" --method "$m" --seconds "$seconds" --out "$d" "${render[@]}"; then
      echo "scene_matrix.sh: $s $m failed (see $d/summary.json)" >&2
      status=1
    fi
  done
done
/usr/bin/python3 tools/scripts/matrix_table.py "$out" > "$out/table.md"
cat "$out/table.md"
exit $status
