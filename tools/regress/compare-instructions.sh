#!/usr/bin/env bash
# Counts the instructions two flexcam binaries execute to render the same frames (valgrind's
# callgrind, one thread), and prints old, new and new / old per render. Instruction counts do
# not depend on what else the machine is doing, so this compares speed on a loaded machine,
# where wall times do not; it does not see cache or memory effects, so confirm a change with
# a same-run wall-time comparison (`flexcam bench`) on an idle machine.
#
#   tools/regress/compare-instructions.sh OLD_FLEXCAM NEW_FLEXCAM
#
# Each render is small (a few seconds under callgrind); the set covers every renderer and the
# scene kinds they are tuned on and beyond it. Exits 1 if a binary fails a render.
set -uo pipefail
if [ $# -ne 2 ]; then
  echo "usage: $0 OLD_FLEXCAM NEW_FLEXCAM" >&2
  exit 2
fi
command -v valgrind >/dev/null || { echo "$0: valgrind is needed (apt-get install valgrind)" >&2; exit 2; }
old=$(realpath "$1")
new=$(realpath "$2")
cd "$(dirname "$0")/../.."
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

renders=(
  "scenes/cube-floor.toml --width 300 --height 300 --method raycast"
  "scenes/cube-floor.toml --width 300 --height 300 --method raster"
  "scenes/cube-floor.toml --width 300 --height 300 --method raycast --shading flat"
  "scenes/trilinear-fan.toml --method trilinear"
  "scenes/trilinear-fan.toml --method raycast"
  "scenes/reflect-sphere-cube.toml --width 200 --height 150 --method raycast"
  "scenes/reflect-sphere-cube.toml --width 200 --height 150 --method trilinear"
  "scenes/refract-lens.toml --width 200 --height 150 --method raycast"
  "scenes/teapot-room.toml --width 200 --height 150 --method raycast"
  "scenes/teapot-room.toml --width 200 --height 150 --method raster"
  "scenes/flexible-panorama-cubic.toml --width 320 --height 160 --method raster"
  "scenes/flexible-quadratic.toml --width 160 --height 160 --method raycast"
)

# Instructions of one render by binary $1 (the remaining arguments), or "failed".
count() {
  local bin=$1
  shift
  if ! RAYON_NUM_THREADS=1 valgrind --tool=callgrind --callgrind-out-file="$work/cg.out" \
    "$bin" render "$@" -o "$work/out.png" >/dev/null 2>"$work/err"; then
    echo failed
    return
  fi
  sed -n 's/^summary: //p' "$work/cg.out"
}

status=0
printf "%-80s %14s %14s %7s\n" render old new new/old
for spec in "${renders[@]}"; do
  # shellcheck disable=SC2086
  o=$(count "$old" $spec)
  # shellcheck disable=SC2086
  n=$(count "$new" $spec)
  if [ "$o" = failed ] || [ "$n" = failed ]; then
    printf "%-80s %14s %14s\n" "$spec" "$o" "$n"
    status=1
    continue
  fi
  printf "%-80s %14d %14d %7.3f\n" "$spec" "$o" "$n" "$(echo "$n / $o" | bc -l)"
done
exit $status
