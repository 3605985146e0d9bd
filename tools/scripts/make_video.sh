#!/usr/bin/env bash
# tools/scripts/make_video.sh — encode a folder of rendered frames (frame_000000.png, …) as an
# H.264 MP4 that plays everywhere (yuv420p; odd frame sizes are padded to even).
set -euo pipefail

usage() {
  cat <<'USAGE'
usage: make_video.sh FRAME_DIR OUT.mp4 [FPS]

Encodes FRAME_DIR/frame_*.png (in name order, gaps allowed) into OUT.mp4 with
ffmpeg: H.264 (libx264), yuv420p, CRF 20. FPS defaults to 60.

  -h, --help   show this help
USAGE
}

die() {
  echo "make_video.sh: $*" >&2
  exit 1
}

if [[ $# -ge 1 && ($1 == -h || $1 == --help) ]]; then
  usage
  exit 0
fi
if [[ $# -lt 2 || $# -gt 3 ]]; then
  usage >&2
  exit 2
fi
dir=${1%/}
out=$2
fps=${3:-60}

command -v ffmpeg >/dev/null || die "ffmpeg not found (Debian: apt-get install ffmpeg)"
if ! [[ $fps =~ ^[0-9]+([.][0-9]+)?$ && $fps =~ [1-9] ]]; then
  die "FPS must be a positive number, got '$fps'"
fi
[[ -d $dir ]] || die "'$dir' is not a folder"
shopt -s nullglob
frames=("$dir"/frame_*.png)
shopt -u nullglob
((${#frames[@]} > 0)) || die "'$dir' holds no frame_*.png"
out_dir=$(dirname -- "$out")
[[ -d $out_dir ]] || die "output folder '$out_dir' does not exist"

# the glob pattern goes to ffmpeg unexpanded; escape glob characters in the folder name
pattern="$(printf '%s' "$dir" | sed 's/[][*?\\]/\\&/g')/frame_*.png"
ffmpeg -hide_banner -loglevel error -y \
  -framerate "$fps" -pattern_type glob -i "$pattern" \
  -vf "pad=ceil(iw/2)*2:ceil(ih/2)*2" \
  -c:v libx264 -pix_fmt yuv420p -crf 20 -movflags +faststart \
  "$out" || die "ffmpeg failed"
echo "make_video.sh: ${#frames[@]} frames at $fps fps -> $out"
