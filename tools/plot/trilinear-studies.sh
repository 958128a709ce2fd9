#!/bin/sh
# Plots the tessellation study of `flexcam bench trilinear` (Vallance 2005, Figures 8.9 to
# 8.12) from its CSV into SVGs beside it (docs/trilinear-raster.md, "Chapter 8 studies").
#   flexcam bench trilinear --study tessellation --csv docs/images/trilinear-tessellation.csv
#   tools/plot/trilinear-studies.sh [docs/images/trilinear-tessellation.csv]
set -eu
csv=${1:-docs/images/trilinear-tessellation.csv}
out=$(dirname "$csv")
plot="python3 $(dirname "$0")/csv_plot.py"
for mode in slice tessellate; do
    case $mode in slice) figure=8-9 ;; *) figure=8-10 ;; esac
    $plot "$csv" "$out/trilinear-figure$figure.svg" --where mode=$mode --x factor \
        --y rgb_error --series configuration --log-x --log-y --x-label "factor ($mode)" \
        --y-label "relative RGB error" --title "Figure $(echo $figure | tr - .): --curves $mode per configuration"
done
$plot "$csv" "$out/trilinear-figure8-11.svg" --where configuration=mean --x factor \
    --y rgb_error,thesis_rgb_error --series mode --log-x --log-y --x-label factor \
    --y-label "relative RGB error,relative RGB error" \
    --title "Figure 8.11 (flexcam): mean of 7,Figure 8.11 (thesis): mean of 7"
$plot "$csv" "$out/trilinear-figure8-12.svg" --where configuration=mean --x factor \
    --y trilinear_ms,thesis_ms --series mode --log-x --log-y --x-label factor \
    --y-label "ms,ms" --title "Figure 8.12 (flexcam): mean time,Figure 8.12 (thesis): mean time"
