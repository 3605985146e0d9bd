#!/usr/bin/env bash
# tools/scripts/setup.sh — installs magsim's Debian packages, builds it (Release), and runs the
# main job: the demo scene rendered to PNG frames and assembled into a video.
#
#   bash tools/scripts/setup.sh               install, build, run the demo  → out/demo/
#   bash tools/scripts/setup.sh --no-demo     install and build only
#   bash tools/scripts/setup.sh --deps-only   install the packages only
# Idempotent: packages already installed are not reinstalled; the build is incremental.
set -euo pipefail
cd "$(dirname "$0")/../.."

deps_only=0
demo=1
for a in "$@"; do
  case "$a" in
    --deps-only) deps_only=1 ;;
    --no-demo) demo=0 ;;
    -h|--help) awk 'NR > 1 && /^#/ { sub(/^# ?/, ""); print; next } NR > 1 { exit }' "$0"; exit 0 ;;
    *) echo "setup.sh: unknown option '$a' (try --help)" >&2; exit 2 ;;
  esac
done

PKGS=(build-essential cmake pkg-config git
      libode-dev libeigen3-dev libccd-dev catch2 libosmesa6-dev libpng-dev
      nlohmann-json3-dev libcli11-dev libtinygltf-dev ffmpeg fonts-dejavu-core
      python3 python3-matplotlib python3-numpy python3-dev python3-pytest pybind11-dev)
missing=()
for p in "${PKGS[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  SUDO=""
  [ "$(id -u)" -ne 0 ] && SUDO="sudo"
  echo "setup: installing ${missing[*]}" >&2
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi
[ "$deps_only" -eq 1 ] && exit 0

cmake -S . -B build/release -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build/release -j"$(nproc)"
[ "$demo" -eq 1 ] || exit 0

# the main job: a demo scene → PNG frames → H.264 video
out=out/demo
build/release/tools/magsim-scene balls_up --seconds 2 --out "$out"
bash tools/scripts/make_video.sh "$out" "$out/balls_up.mp4"
echo "setup: demo frames in $out/, video $out/balls_up.mp4, summary $out/summary.json"
