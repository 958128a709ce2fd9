#!/usr/bin/env bash
# The trilinear rasteriser against the ray caster on the same frame, for every trilinear
# example scene and every reflector / refractor example (scenes/trilinear-*.toml,
# reflect-*.toml, refract-*.toml), at 320 x 240 and 800 x 800, flat and lit shading: each
# cell renders R times (default 3) by both methods in turn, so that both see the same
# machine state, and prints the median `render_ms` of `flexcam render --stats -` of each
# (the render alone: no loading, scene preparation or PNG writing), the ratio ray / trilinear
# (above 1: trilinear wins) and LOSES where it does not. The load average at the start and
# end is printed too: on a shared machine the times are only comparable within one run.
#
#   tools/bench/trilinear-vs-raycast.sh [-b FLEXCAM] [-r R] [-s SIZE] [-S SHADING] [-c CSV] [SCENE...]
#
# -s 320x240 or -S flat restricts the sizes or shadings; SCENE... replaces the scene list;
# -D KEY=VALUE passes a scene key (e.g. -D projection.grid=32) to every render.
set -euo pipefail
cd "$(dirname "$0")/../.."
flexcam=target/release/flexcam
repeat=3
sizes=(320x240 800x800)
shadings=(flat lit)
csv=
defines=()
while getopts "b:r:s:S:c:D:" opt; do
  case $opt in
    b) flexcam=$OPTARG ;;
    r) repeat=$OPTARG ;;
    s) sizes=("$OPTARG") ;;
    S) shadings=("$OPTARG") ;;
    c) csv=$OPTARG ;;
    D) defines+=(-D "$OPTARG") ;;
    *) echo "usage: $0 [-b FLEXCAM] [-r R] [-s WxH] [-S flat|lit] [-c CSV] [-D KEY=VALUE] [SCENE...]" >&2; exit 2 ;;
  esac
done
shift $((OPTIND - 1))
if [ $# -gt 0 ]; then
  scenes=("$@")
else
  scenes=(scenes/trilinear-*.toml scenes/reflect-*.toml scenes/refract-*.toml)
fi
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT

# render_ms of one render: METHOD SCENE W H SHADING.
render_ms() {
  "$flexcam" render "$2" --method "$1" --width "$3" --height "$4" --shading "$5" \
    "${defines[@]}" --stats - -o "$out/frame.png" | jq -r .render_ms
}
# The median of the numbers given.
median() { printf '%s\n' "$@" | sort -g | awk '{a[NR]=$1} END {print (NR % 2) ? a[(NR+1)/2] : (a[NR/2] + a[NR/2+1]) / 2}'; }

echo "load average at start: $(cut -d' ' -f1-3 /proc/loadavg); $(nproc) cores; $repeat renders per cell; $flexcam"
printf "%-42s %-8s %-5s %10s %10s %7s\n" scene size shading raycast_ms trilinear_ms ratio
[ -n "$csv" ] && echo "scene,width,height,shading,raycast_ms,trilinear_ms,ratio" > "$csv"
losers=0
for scene in "${scenes[@]}"; do
  for size in "${sizes[@]}"; do
    w=${size%x*}; h=${size#*x}
    for shading in "${shadings[@]}"; do
      ray=(); tri=()
      for _ in $(seq "$repeat"); do
        ray+=("$(render_ms raycast "$scene" "$w" "$h" "$shading")")
        tri+=("$(render_ms trilinear "$scene" "$w" "$h" "$shading")")
      done
      r=$(median "${ray[@]}"); t=$(median "${tri[@]}")
      ratio=$(awk -v r="$r" -v t="$t" 'BEGIN {printf "%.2f", r / t}')
      flag=$(awk -v x="$ratio" 'BEGIN {print (x > 1) ? "" : "LOSES"}')
      [ -n "$flag" ] && losers=$((losers + 1))
      printf "%-42s %-8s %-5s %10.2f %10.2f %6sx %s\n" "$(basename "$scene")" "$size" "$shading" "$r" "$t" "$ratio" "$flag"
      [ -n "$csv" ] && echo "$(basename "$scene"),$w,$h,$shading,$r,$t,$ratio" >> "$csv"
    done
  done
done
echo "load average at end: $(cut -d' ' -f1-3 /proc/loadavg); rows losing: $losers"
