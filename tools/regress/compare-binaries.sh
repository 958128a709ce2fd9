#!/usr/bin/env bash
# Renders every scenes/*.toml with every method (raycast, raster, trilinear), flat and lit,
# with colour, depth and ids, by two flexcam binaries, and reports every difference: a
# different image, depth or id file (compared byte for byte), a different exit status, or a
# different error message. A method that refuses a scene must refuse it the same way in both.
# A scene the old binary cannot parse (a key it does not know: a newer feature) is counted
# and not compared.
#
#   tools/regress/compare-binaries.sh OLD_FLEXCAM NEW_FLEXCAM [WIDTH HEIGHT]
#
# WIDTH and HEIGHT (optional) override every scene's size, for a quicker run; without them
# each scene renders at its own size. Exits 0 when nothing differs, 1 otherwise. Build the old
# binary from the commit before a change (git worktree add ../old COMMIT; cargo build
# --release there) and the new one from the working tree.
set -uo pipefail
if [ $# -ne 2 ] && [ $# -ne 4 ]; then
  echo "usage: $0 OLD_FLEXCAM NEW_FLEXCAM [WIDTH HEIGHT]" >&2
  exit 2
fi
old=$(realpath "$1")
new=$(realpath "$2")
size=()
[ $# -eq 4 ] && size=(--width "$3" --height "$4")
cd "$(dirname "$0")/../.."
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

renders=0
differ=0
refused=0
unknown=0
for scene in scenes/*.toml; do
  for method in raycast raster trilinear; do
    for shading in flat lit; do
      renders=$((renders + 1))
      for side in old new; do
        bin=${!side}
        dir="$work/$side"
        rm -rf "$dir" && mkdir -p "$dir"
        "$bin" render "$scene" --method "$method" --shading "$shading" "${size[@]}" \
          -o "$dir/color.png" --depth "$dir/depth.pfm" --ids "$dir/ids.png" \
          >"$dir/stdout" 2>"$dir/stderr" </dev/null
        echo "exit $?" >"$dir/status"
        # Progress bars are drawn on a terminal only; keep the error lines.
        grep -a 'flexcam:' "$dir/stderr" >"$dir/messages" || true
      done
      grep -q 'exit 0' "$work/old/status" || refused=$((refused + 1))
      # A scene written for a newer feature: the old binary cannot even parse it.
      if grep -q 'unknown field\|unknown variant' "$work/old/messages"; then
        unknown=$((unknown + 1))
        continue
      fi
      what=()
      for f in status messages color.png depth.pfm ids.png; do
        a="$work/old/$f" b="$work/new/$f"
        if [ -e "$a" ] || [ -e "$b" ]; then
          cmp -s "$a" "$b" || what+=("$f")
        fi
      done
      if [ ${#what[@]} -gt 0 ]; then
        differ=$((differ + 1))
        echo "DIFFERS $scene --method $method --shading $shading: ${what[*]}"
        for f in status messages; do
          if [[ " ${what[*]} " == *" $f "* ]]; then
            echo "  old $f: $(head -c 300 "$work/old/$f")"
            echo "  new $f: $(head -c 300 "$work/new/$f")"
          fi
        done
      fi
    done
  done
done
echo "$renders renders compared ($refused refused by the old binary, $unknown of them with scene keys it does not know: not compared), $differ differ"
[ "$differ" -eq 0 ]
