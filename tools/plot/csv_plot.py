#!/usr/bin/env python3
"""Plots columns of a CSV file as line series into an SVG file (standard library only).

    python3 tools/plot/csv_plot.py IN.csv OUT.svg --x COL --y COL[,COL...] [--series COL[,COL...]]
        [--log-x] [--log-y] [--title TEXT[,TEXT...]] [--x-label TEXT] [--y-label TEXT[,TEXT...]]
        [--where COL=VALUE ...]

Each --y column is one panel, side by side; rows are grouped into series by the values of the
--series columns; --where (repeatable) keeps only the rows whose column COL is VALUE. Used for docs/images/camtri-figure6.svg and camtri-figure7.svg from
`flexcam bench camera-triangles --figure 6|7 --csv FILE` (docs/camera-triangles.md), and by
tools/plot/trilinear-studies.sh for `flexcam bench trilinear --study` (docs/trilinear-raster.md).
"""

import argparse
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from lineplot import csv_series, figure  # noqa: E402


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("csv")
    parser.add_argument("svg")
    parser.add_argument("--x", required=True)
    parser.add_argument("--y", required=True, help="comma-separated: one panel each")
    parser.add_argument("--series", default="", help="comma-separated columns")
    parser.add_argument("--log-x", action="store_true")
    parser.add_argument("--log-y", action="store_true")
    parser.add_argument("--title", default="", help="comma-separated: one per panel")
    parser.add_argument("--x-label")
    parser.add_argument("--y-label", help="comma-separated: one per panel")
    parser.add_argument("--where", action="append", default=[], metavar="COL=VALUE",
                        help="keep only rows whose COL is VALUE (repeatable)")
    args = parser.parse_args(argv)
    where = []
    for condition in args.where:
        column, equals, value = condition.partition("=")
        if not equals or not column:
            parser.error("--where needs COL=VALUE, got %r" % condition)
        where.append((column, value))
    ys = args.y.split(",")
    titles = args.title.split(",") if args.title else [""] * len(ys)
    y_labels = args.y_label.split(",") if args.y_label else ys
    if len(titles) != len(ys) or len(y_labels) != len(ys):
        parser.error("--title and --y-label need one entry per --y column")
    series = [c for c in args.series.split(",") if c]
    try:
        panels = [dict(series=csv_series(args.csv, args.x, y, series, where),
                       x_label=args.x_label or args.x, y_label=label, title=title,
                       log_x=args.log_x, log_y=args.log_y)
                  for y, label, title in zip(ys, y_labels, titles)]
        svg = figure(panels)
    except (OSError, ValueError) as e:
        sys.exit("csv_plot: %s" % e)
    with open(args.svg, "w") as f:
        f.write(svg)


if __name__ == "__main__":
    main()
