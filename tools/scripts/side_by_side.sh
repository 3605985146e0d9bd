#!/usr/bin/env bash
# tools/scripts/side_by_side.sh — two folders of rendered frames side by side in one H.264 MP4,
# each half labelled (default "ours" on the left, "Kim 2018" on the right).
set -euo pipefail

usage() {
  cat <<'USAGE'
usage: side_by_side.sh LEFT_DIR RIGHT_DIR OUT.mp4 [LEFT_LABEL] [RIGHT_LABEL] [FPS]

Stacks LEFT_DIR/frame_*.png and RIGHT_DIR/frame_*.png horizontally (the right video is
scaled to the left one's height), writes a label at the top of each half and encodes
H.264 (libx264, yuv420p, CRF 20). Stops at the end of the shorter sequence.
Defaults: LEFT_LABEL "ours", RIGHT_LABEL "Kim 2018", FPS 60.

  -h, --help   show this help
USAGE
}

die() {
  echo "side_by_side.sh: $*" >&2
  exit 1
}

if [[ $# -ge 1 && ($1 == -h || $1 == --help) ]]; then
  usage
  exit 0
fi
if [[ $# -lt 3 || $# -gt 6 ]]; then
  usage >&2
  exit 2
fi
left=${1%/}
right=${2%/}
out=$3
left_label=${4:-ours}
right_label=${5:-Kim 2018}
fps=${6:-60}

command -v ffmpeg >/dev/null || die "ffmpeg not found (Debian: apt-get install ffmpeg)"
if ! [[ $fps =~ ^[0-9]+([.][0-9]+)?$ && $fps =~ [1-9] ]]; then
  die "FPS must be a positive number, got '$fps'"
fi
count_frames() {
  [[ -d $1 ]] || die "'$1' is not a folder"
  shopt -s nullglob
  local frames=("$1"/frame_*.png)
  shopt -u nullglob
  ((${#frames[@]} > 0)) || die "'$1' holds no frame_*.png"
  echo "${#frames[@]}"
}
n_left=$(count_frames "$left")
n_right=$(count_frames "$right")
out_dir=$(dirname -- "$out")
[[ -d $out_dir ]] || die "output folder '$out_dir' does not exist"

# drawtext needs a font file: DejaVu Sans (Debian package fonts-dejavu-core) if present,
# else the first TrueType/OpenType font under /usr/share/fonts whose path needs no
# escaping in a filter graph
font=/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf
if [[ ! -f $font ]]; then
  font=$(find /usr/share/fonts -type f \( -name '*.ttf' -o -name '*.otf' \) 2>/dev/null |
    grep -E '^[A-Za-z0-9_./-]+$' | sort | head -n 1 || true)
  [[ -n $font ]] || die "no font under /usr/share/fonts for the labels (Debian: apt-get install fonts-dejavu-core)"
fi

# labels go through files, so any characters are fine
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
printf '%s' "$left_label" >"$tmp/left.txt"
printf '%s' "$right_label" >"$tmp/right.txt"

glob() { printf '%s/frame_*.png' "$(printf '%s' "$1" | sed 's/[][*?\\]/\\&/g')"; }
label="fontfile=$font:expansion=none:fontcolor=white:fontsize=h/18:box=1:boxcolor=black@0.55:boxborderw=10:x=(w-text_w)/2:y=h/30"
# scale2ref: iw/ih are the reference's (left) size, main_w/main_h the scaled input's
filter="[1:v][0:v]scale2ref=w=trunc(main_w*ih/main_h/2)*2:h=ih[r][l];"
filter+="[l]drawtext=textfile=$tmp/left.txt:${label}[lt];"
filter+="[r]drawtext=textfile=$tmp/right.txt:${label}[rt];"
filter+="[lt][rt]hstack=inputs=2:shortest=1,pad=ceil(iw/2)*2:ceil(ih/2)*2[v]"

ffmpeg -hide_banner -loglevel error -y \
  -framerate "$fps" -pattern_type glob -i "$(glob "$left")" \
  -framerate "$fps" -pattern_type glob -i "$(glob "$right")" \
  -filter_complex "$filter" -map "[v]" \
  -c:v libx264 -pix_fmt yuv420p -crf 20 -movflags +faststart \
  "$out" || die "ffmpeg failed"
n=$((n_left < n_right ? n_left : n_right))
echo "side_by_side.sh: $n frames ('$left_label' | '$right_label') at $fps fps -> $out"
