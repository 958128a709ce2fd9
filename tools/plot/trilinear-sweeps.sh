#!/bin/sh
# Plots the Figure 7.4 sweeps of `flexcam bench trilinear --sweep` (Vallance 2005: the view
# through a mirror ball, and through a glass ball, as N x N trilinear grids against the exact
# ball) from their CSVs into SVGs beside them (docs/trilinear-surfaces.md, "Views through a
# ball").
#   flexcam bench trilinear --sweep reflection --csv docs/images/trilinear-sweep-reflection.csv
#   flexcam bench trilinear --sweep refraction --csv docs/images/trilinear-sweep-refraction.csv
#   tools/plot/trilinear-sweeps.sh [docs/images]
set -eu
dir=${1:-docs/images}
plot="python3 $(dirname "$0")/csv_plot.py"
labels="relative RGB error,id agreement away from id edges"
$plot "$dir/trilinear-sweep-reflection.csv" "$dir/trilinear-figure7-4-sweep.svg" --x n \
    --y rgb_error,ids_interior --log-x --log-y --x-label "N (N x N grid)" --y-label "$labels" \
    --title "Figure 7.4: mirror ball against N,Figure 7.4: mirror ball against N"
$plot "$dir/trilinear-sweep-refraction.csv" "$dir/trilinear-sweep-refraction.svg" --x n \
    --y rgb_error,ids_interior --log-x --log-y --x-label "N (N x N grid)" --y-label "$labels" \
    --title "7.3.3: glass ball against N,7.3.3: glass ball against N"
