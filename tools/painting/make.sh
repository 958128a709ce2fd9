#!/bin/sh
# Makes the painting of the painting-workflow example (docs/fitting.md, "A worked example"):
# renders the painter's scene (scenes/painting-bedroom-painter.toml, a non-pinhole flexible
# projection), turns the render into a painting (tools/painting/paint.py: deterministic), and
# prints the `fit` entries of 30 clicks spread over it (6 columns x 5 rows of pixel centres),
# each with the scene point the painter's projection sees there (`flexcam pick --fit`), the
# pixel then moved by up to 2 px in steps of 0.5 (a fixed pseudo-random sequence), as a
# person's clicks on a feature would be. scenes/painting-bedroom.toml holds those entries.
#
# Usage: tools/painting/make.sh [FLEXCAM]   (default target/release/flexcam), from the
# repository root. Writes scenes/photos/painting-bedroom.png.
set -eu
flexcam=${1:-target/release/flexcam}
painter=scenes/painting-bedroom-painter.toml
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
"$flexcam" render "$painter" -o "$tmp/render.png"
python3 tools/painting/paint.py "$tmp/render.png" scenes/photos/painting-bedroom.png
clicks=""
for y in 24.5 72.5 120.5 168.5 216.5; do
    for x in 26.5 79.5 133.5 186.5 240.5 293.5; do
        clicks="$clicks $x,$y"
    done
done
# shellcheck disable=SC2086
"$flexcam" pick "$painter" --fit $clicks | awk '
    BEGIN { s = 1 }
    function step() { s = (s * 75 + 74) % 65537; return (s % 9 - 4) * 0.5 }
    /^\{ pixel = \[/ {
        split($0, a, /[][,]/)
        x = a[2] + step(); y = a[3] + step()
        sub(/pixel = \[[^]]*\]/, sprintf("pixel = [%.1f, %.1f]", x, y))
    }
    { print }'
