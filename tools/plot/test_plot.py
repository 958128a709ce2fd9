#!/usr/bin/env python3
"""Tests of tools/plot (run by .ci/run): python3 tools/plot/test_plot.py"""

import os
import subprocess
import sys
import tempfile
import unittest
import xml.etree.ElementTree as ET

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
from lineplot import csv_series, figure, line_plot, ticks  # noqa: E402

SVG = "{http://www.w3.org/2000/svg}"


class Ticks(unittest.TestCase):
    def test_linear_ticks_cover_the_range_in_1_2_5_steps(self):
        self.assertEqual(ticks(0.0, 1.0), [0.0, 0.2, 0.4, 0.6, 0.8, 1.0])
        t = ticks(3.0, 47.0)
        self.assertLessEqual(t[0], 3.0)
        self.assertGreaterEqual(t[-1], 47.0)
        self.assertEqual(t[1] - t[0], 10.0)

    def test_log_ticks_are_decades_and_a_single_value_gets_one(self):
        self.assertEqual(ticks(8, 960, log=True), [1, 10, 100, 1000])
        self.assertEqual(ticks(5.0, 5.0, log=True), [1, 2, 5, 10])
        # A linear axis of one value spans one unit around it.
        t = ticks(2.0, 2.0)
        self.assertIn(2.0, t)
        self.assertLessEqual(t[0], 1.5)
        self.assertGreaterEqual(t[-1], 2.5)


class Plot(unittest.TestCase):
    def test_each_series_is_a_polyline_in_a_parsable_svg(self):
        svg = figure([dict(series=[("a", [(1, 1), (2, 4), (4, 2)]), ("b", [(1, 3), (4, 5)]),
                                   ("one", [(2, 2)])],
                           x_label="x", y_label="y", title="t", log_x=True)])
        root = ET.fromstring(svg)
        polylines = root.findall(".//%spolyline" % SVG)
        self.assertEqual(len(polylines), 2)  # a single point has a marker alone
        self.assertEqual(len(polylines[0].get("points").split()), 3)
        texts = [t.text for t in root.iter("%stext" % SVG)]
        for label in ("a", "b", "one", "x", "y", "t"):
            self.assertIn(label, texts)

    def test_larger_values_are_drawn_higher(self):
        root = ET.fromstring(figure([dict(series=[("s", [(0, 0), (1, 10)])],
                                          x_label="x", y_label="y")]))
        points = root.find(".//%spolyline" % SVG).get("points").split()
        (x0, y0), (x1, y1) = [tuple(map(float, p.split(","))) for p in points]
        self.assertLess(x0, x1)
        self.assertGreater(y0, y1)  # SVG's y runs down

    def test_the_legend_goes_to_an_empty_corner(self):
        def legend_at(points):
            root = ET.fromstring(figure([dict(series=[("s", points)], x_label="x",
                                              y_label="y")]))
            line = root.findall(".//%sline" % SVG)[-1]
            return float(line.get("x1")), float(line.get("y1"))
        # Rising data leave the bottom right empty, falling data the top right (the first
        # choice).
        x, y = legend_at([(i, i) for i in range(10)])
        self.assertGreater(x, 200)
        self.assertGreater(y, 150)
        x, y = legend_at([(i, -i) for i in range(10)])
        self.assertGreater(x, 200)
        self.assertLess(y, 100)

    def test_points_off_a_log_axis_are_skipped_and_nothing_is_an_error(self):
        svg = line_plot([("s", [(0, 1), (1, 2), (2, float("nan")), (3, 3)])], "x", "y",
                        log_x=True)
        self.assertEqual(svg.count("<circle"), 3)  # two points and the legend's marker
        with self.assertRaises(ValueError):
            line_plot([("s", [(1, float("nan"))])], "x", "y")


class CsvPlot(unittest.TestCase):
    def test_the_command_plots_a_csv_into_one_panel_per_y_column(self):
        with tempfile.TemporaryDirectory() as d:
            data = os.path.join(d, "f.csv")
            with open(data, "w") as f:
                f.write("scene,camera_mesh,agreement,rgb_error\n"
                        "ball,8,0.5,0.2\nball,16,0.8,0.1\nball,32,0.9,0.05\n"
                        "torus,8,0.4,0.3\ntorus,16,0.7,0.2\n")
            series = csv_series(data, "camera_mesh", "agreement", ["scene"])
            self.assertEqual(series, [("ball", [(8, 0.5), (16, 0.8), (32, 0.9)]),
                                      ("torus", [(8, 0.4), (16, 0.7)])])
            out = os.path.join(d, "f.svg")
            tool = os.path.join(HERE, "csv_plot.py")
            subprocess.run([sys.executable, tool, data, out, "--x", "camera_mesh",
                            "--y", "agreement,rgb_error", "--series", "scene", "--log-x"],
                           check=True)
            root = ET.parse(out).getroot()
            self.assertEqual(len(root.findall(".//%spolyline" % SVG)), 4)
            bad = subprocess.run([sys.executable, tool, data, out, "--x", "nope", "--y",
                                  "agreement"], capture_output=True, text=True)
            self.assertNotEqual(bad.returncode, 0)
            self.assertIn("no column 'nope'", bad.stderr)

    def test_where_keeps_only_the_matching_rows(self):
        with tempfile.TemporaryDirectory() as d:
            data = os.path.join(d, "t.csv")
            with open(data, "w") as f:
                f.write("configuration,mode,factor,rgb_error\n"
                        "a,slice,1,0.5\na,slice,10,0.1\na,tessellate,1,0.6\n"
                        "mean,slice,1,0.4\nmean,slice,10,0.2\nmean,tessellate,1,0.7\n")
            self.assertEqual(csv_series(data, "factor", "rgb_error", ["configuration"],
                                        [("mode", "slice")]),
                             [("a", [(1, 0.5), (10, 0.1)]), ("mean", [(1, 0.4), (10, 0.2)])])
            self.assertEqual(csv_series(data, "factor", "rgb_error", ["mode"],
                                        [("configuration", "mean"), ("mode", "tessellate")]),
                             [("tessellate", [(1, 0.7)])])
            with self.assertRaises(ValueError):
                csv_series(data, "factor", "rgb_error", [], [("nope", "x")])
            tool = os.path.join(HERE, "csv_plot.py")
            out = os.path.join(d, "t.svg")
            subprocess.run([sys.executable, tool, data, out, "--x", "factor", "--y",
                            "rgb_error", "--series", "mode", "--where", "configuration=mean"],
                           check=True)
            root = ET.parse(out).getroot()
            # slice has two points (a polyline), tessellate one (a marker alone).
            self.assertEqual(len(root.findall(".//%spolyline" % SVG)), 1)
            bad = subprocess.run([sys.executable, tool, data, out, "--x", "factor", "--y",
                                  "rgb_error", "--where", "mode"], capture_output=True, text=True)
            self.assertNotEqual(bad.returncode, 0)
            self.assertIn("COL=VALUE", bad.stderr)


if __name__ == "__main__":
    unittest.main()
