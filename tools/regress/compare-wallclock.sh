#!/usr/bin/env bash
# Wall-clock speed of two flexcam binaries in one run: each render is timed N times (default
# 5) by the old and the new binary in turn, so that both see the same machine state, and the
# best time of each is printed with new / old. Renders include loading, preparing and
# writing the PNG, as a user runs them. Use an idle machine; on a loaded one prefer
# compare-instructions.sh.
#
#   tools/regress/compare-wallclock.sh OLD_FLEXCAM NEW_FLEXCAM [N]
set -uo pipefail
if [ $# -lt 2 ]; then
  echo "usage: $0 OLD_FLEXCAM NEW_FLEXCAM [N]" >&2
  exit 2
fi
old=$(realpath "$1"); new=$(realpath "$2"); n=${3:-5}
cd "$(dirname "$0")/../.."
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
specs=(
  "scenes/cube-floor.toml --width 1600 --height 1600 --method raycast"
  "scenes/cube-floor.toml --width 1600 --height 1600 --method raster"
  "scenes/trilinear-fan.toml --width 1600 --height 1200 --method trilinear"
  "scenes/reflect-sphere-cube.toml --width 1280 --height 960 --method raycast"
  "scenes/reflect-sphere-cube.toml --width 1280 --height 960 --method trilinear"
  "scenes/refract-lens.toml --width 1280 --height 960 --method raycast"
  "scenes/teapot-room.toml --width 1600 --height 1200 --method raycast"
  "scenes/teapot-room.toml --width 1600 --height 1200 --method raster"
  "scenes/flexible-panorama-cubic.toml --width 2048 --height 1024 --method raster"
)
# Seconds one render takes.
t() { local s=$(date +%s.%N); "$@" -o "$out/out.png" >/dev/null 2>&1; local e=$(date +%s.%N); echo "$e - $s" | bc; }
printf "%-75s %8s %8s %6s\n" render old_s new_s ratio
for spec in "${specs[@]}"; do
  bo=999; bn=999
  for i in $(seq $n); do
    a=$(t $old render $spec); b=$(t $new render $spec)
    bo=$(echo "if ($a < $bo) $a else $bo" | bc); bn=$(echo "if ($b < $bn) $b else $bn" | bc)
  done
  printf "%-75s %8.3f %8.3f %6.3f\n" "$spec" $bo $bn $(echo "$bn / $bo" | bc -l)
done
