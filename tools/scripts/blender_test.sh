#!/usr/bin/env bash
# tools/scripts/blender_test.sh — the blender label of CTest: a short run of every registry scene
# and of scenes/examples/two_balls.json written with --gltf, each imported into headless Blender
# and checked against its states.csv by tools/scripts/blender_check.py.
#
#   bash tools/scripts/blender_test.sh MAGSIM_SCENE_BIN [OUT_DIR]    (default OUT_DIR: out/blender_test)
#
# Exit 77 (CTest's SKIP_RETURN_CODE: "skipped") only where no `blender` is on PATH; 0 when every
# check passes, 1 when one fails.
set -euo pipefail
case "${1:-}" in -h|--help|"") awk 'NR > 1 && /^#/ { sub(/^# ?/, ""); print; next } NR > 1 { exit }' "$0"; exit 0 ;; esac
bin=$1
out=${2:-out/blender_test}
src=$(cd "$(dirname "$0")/../.." && pwd)
if ! command -v blender >/dev/null 2>&1; then
  echo "blender_test: no blender on PATH: skipped"
  exit 77
fi
mkdir -p "$out"
# name | magsim-scene arguments | --gltf-channels (empty: none)
runs=(
  "two_balls|$src/scenes/examples/two_balls.json --seconds 0.5|m_norm,speed,spin"
  "balls_up|balls_up --count 60 --seconds 0.3|m_norm,speed"
  "alphabets|alphabets --count 8 --seconds 0.3|"
  "falling_magnet|falling_magnet --count 60 --seconds 0.3|spin"
  "sakura_tree|sakura_tree --count 100 --seconds 0.3|m_norm"
  "crystal_balls|crystal_balls --seconds 0.1|"
)
failed=0
for r in "${runs[@]}"; do
  IFS='|' read -r name args channels <<< "$r"
  glb="$out/$name.glb"
  flags=()
  [ -n "$channels" ] && flags=(--gltf-channels "$channels")
  # shellcheck disable=SC2086  # the arguments are words
  "$bin" $args --no-render --threads 1 --out "$out/$name" --gltf "$glb" "${flags[@]}" 2>"$out/$name.log" || {
    echo "blender_test: $name: magsim-scene failed"; cat "$out/$name.log"; failed=1; continue; }
  check=(blender -b --factory-startup --python-exit-code 2 --python "$src/tools/scripts/blender_check.py" --
         "$glb" "$out/$name/states.csv" 60)
  [ -n "$channels" ] && check+=(--channels "$channels")
  echo "== $name: ${check[*]}"
  if ! "${check[@]}" > "$out/$name.blender.log" 2>&1; then failed=1; fi
  grep -E '^(ok|FAIL|import|blender_check)|Error' "$out/$name.blender.log" || true
done
exit $failed
