#!/usr/bin/env bash
# The trilinear rasteriser against the ray caster on the same frame, for every trilinear
# example scene and every reflector / refractor example (scenes/trilinear-*.toml,
# reflect-*.toml, refract-*.toml), at 320 x 240 and 800 x 800, flat and lit shading: each
# cell renders R times (default 3) by both methods in turn, so that both see the same
# machine state, and prints the median `render_ms` of `flexcam render --stats -` of each
# (the render alone: no loading, scene preparation or PNG writing), the ratio ray / trilinear
# (above 1: trilinear wins) and LOSES where it does not. The load average at the start and
# end is printed too: on a shared machine the times are only comparable within one run.
# With -B OLD_FLEXCAM the old binary's trilinear render is timed in the same turns too (a
# before / after column, and its ratio).
#
# With -C each cell is instead the CPU time of the render on one thread (`--threads 1`): the
# process's task-clock (`perf stat`) less that of a 4 x 3 ray-cast render of the same scene
# (loading, preparing, process start), the least of the R renders. Far steadier than wall
# time on a loaded machine (a process waiting for a core is not charged), but blind to what
# parallelism gains or loses.
#
#   tools/bench/trilinear-vs-raycast.sh [-C] [-b FLEXCAM] [-B OLD_FLEXCAM] [-r R] [-s SIZE] [-S SHADING] [-c CSV] [SCENE...]
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
old=
cpu=
defines=()
while getopts "Cb:B:r:s:S:c:D:" opt; do
  case $opt in
    C) cpu=1 ;;
    b) flexcam=$OPTARG ;;
    B) old=$OPTARG ;;
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

# render_ms of one render: METHOD SCENE W H SHADING [FLEXCAM]; with -C its CPU ms.
render_ms() {
  if [ -n "$cpu" ]; then
    local all base
    all=$(task_clock "${6:-$flexcam}" "$1" "$2" "$3" "$4" "$5")
    base=$(task_clock "$flexcam" raycast "$2" 4 3 "$5")
    awk -v a="$all" -v b="$base" 'BEGIN {print a - b}'
  else
    "${6:-$flexcam}" render "$2" --method "$1" --width "$3" --height "$4" --shading "$5" \
      "${defines[@]}" --stats - -o "$out/frame.png" | jq -r .render_ms
  fi
}
# Task-clock ms of one single-threaded render process: FLEXCAM METHOD SCENE W H SHADING.
task_clock() {
  perf stat -x, -e task-clock "$1" render "$3" --method "$2" --width "$4" --height "$5" \
    --shading "$6" --threads 1 "${defines[@]}" -o "$out/frame.png" 2>&1 >/dev/null \
    | grep task-clock | cut -d, -f1
}
# The median of the numbers given (with -C the least: waiting is not charged, disturbance is).
median() {
  if [ -n "$cpu" ]; then
    printf '%s\n' "$@" | sort -g | head -1
  else
    printf '%s\n' "$@" | sort -g | awk '{a[NR]=$1} END {print (NR % 2) ? a[(NR+1)/2] : (a[NR/2] + a[NR/2+1]) / 2}'
  fi
}

echo "load average at start: $(cut -d' ' -f1-3 /proc/loadavg); $(nproc) cores; $repeat renders per cell; $flexcam${cpu:+; CPU ms of one thread, least of the renders}"
[ -n "$old" ] && echo "old binary: $old"
printf "%-42s %-8s %-5s %10s %10s %7s" scene size shading raycast_ms trilinear_ms ratio
[ -n "$old" ] && printf " %12s %9s" old_tri_ms old_ratio
echo
[ -n "$csv" ] && echo "scene,width,height,shading,raycast_ms,trilinear_ms,ratio${old:+,old_trilinear_ms,old_ratio}" > "$csv"
losers=0
for scene in "${scenes[@]}"; do
  for size in "${sizes[@]}"; do
    w=${size%x*}; h=${size#*x}
    for shading in "${shadings[@]}"; do
      ray=(); tri=(); was=()
      for _ in $(seq "$repeat"); do
        ray+=("$(render_ms raycast "$scene" "$w" "$h" "$shading")")
        tri+=("$(render_ms trilinear "$scene" "$w" "$h" "$shading")")
        [ -n "$old" ] && was+=("$(render_ms trilinear "$scene" "$w" "$h" "$shading" "$old")")
      done
      r=$(median "${ray[@]}"); t=$(median "${tri[@]}")
      ratio=$(awk -v r="$r" -v t="$t" 'BEGIN {printf "%.2f", r / t}')
      flag=$(awk -v x="$ratio" 'BEGIN {print (x > 1) ? "" : "LOSES"}')
      [ -n "$flag" ] && losers=$((losers + 1))
      printf "%-42s %-8s %-5s %10.2f %10.2f %6sx" "$(basename "$scene")" "$size" "$shading" "$r" "$t" "$ratio"
      row="$(basename "$scene"),$w,$h,$shading,$r,$t,$ratio"
      if [ -n "$old" ]; then
        o=$(median "${was[@]}")
        oratio=$(awk -v r="$r" -v t="$o" 'BEGIN {printf "%.2f", r / t}')
        printf " %12.2f %8sx" "$o" "$oratio"
        row="$row,$o,$oratio"
      fi
      echo " $flag"
      [ -n "$csv" ] && echo "$row" >> "$csv"
    done
  done
done
echo "load average at end: $(cut -d' ' -f1-3 /proc/loadavg); rows losing: $losers"
