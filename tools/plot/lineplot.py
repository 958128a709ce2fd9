"""Line plots as SVG, with Python's standard library alone (no matplotlib).

`line_plot` draws one panel: axes with ticks and labels (linear or log-10 on either axis),
several series as coloured polylines with markers, a legend in the corner of the plot
area that hides the fewest points. `figure` lays out panels side
by side into one SVG document. `csv_series` groups a CSV's rows into series.

Degenerate cases: a series of one point is drawn as its marker alone; an axis whose data
span is zero is widened to one unit (linear) or one decade (log) around the value; points
with a value that is not a finite number (or not positive on a log axis) are skipped.
"""

import csv
import math
from xml.sax.saxutils import escape

COLOURS = ["#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e", "#17becf",
           "#8c564b", "#e377c2", "#7f7f7f", "#bcbd22"]
MARKERS = ["circle", "square", "triangle", "diamond"]


def _fmt(v):
    """A tick label: short, without trailing zeros."""
    if v == 0:
        return "0"
    if abs(v) >= 1e5 or abs(v) < 1e-3:
        return "%.0e" % v
    return ("%.4f" % v).rstrip("0").rstrip(".")


def _nice_step(span, count):
    """A step of 1, 2 or 5 times a power of ten giving about `count` ticks over `span`."""
    raw = span / max(count, 1)
    power = 10 ** math.floor(math.log10(raw))
    for m in (1, 2, 5, 10):
        if m * power >= raw:
            return m * power
    return 10 * power


def ticks(lo, hi, log=False, count=5):
    """Tick values covering [lo, hi] (the axis range is widened to the outer ticks): for a
    log axis (lo > 0) the powers of ten (with 2 and 5 between when there are fewer than
    three decades), else multiples of a 1-2-5 step."""
    if log:
        a, b = math.floor(math.log10(lo)), math.ceil(math.log10(hi))
        if a == b:
            b = a + 1
        values = [10.0 ** e for e in range(a, b + 1)]
        if b - a < 3:
            values = sorted(set(values + [m * 10.0 ** e for e in range(a, b) for m in (2, 5)]))
        return values
    if hi == lo:
        lo, hi = lo - 0.5, hi + 0.5
    step = _nice_step(hi - lo, count)
    first, last = math.floor(lo / step + 1e-9), math.ceil(hi / step - 1e-9)
    values = [float("%.12g" % (k * step)) for k in range(first, last + 1)]
    return values


def _finite(v, log):
    return isinstance(v, (int, float)) and math.isfinite(v) and (v > 0 or not log)


def line_plot(series, x_label, y_label, title="", log_x=False, log_y=False,
              width=420, height=300, x=0, y=0):
    """One panel as SVG elements (a string), its top left corner at (x, y).

    `series`: a list of (name, [(x, y), ...]); points are drawn in the given order."""
    left, right, top, bottom = 62, 12, 28, 46
    pw, ph = width - left - right, height - top - bottom
    points = [(px, py) for _, pts in series for px, py in pts
              if _finite(px, log_x) and _finite(py, log_y)]
    if not points:
        raise ValueError("nothing to plot: no point with finite coordinates")
    xs, ys = [p[0] for p in points], [p[1] for p in points]
    xt = ticks(min(xs), max(xs), log_x)
    # A linear y axis starts at 0 when the data lie well above it.
    y_low = min(ys)
    if not log_y and 0 <= y_low < 0.3 * max(ys):
        y_low = 0.0
    yt = ticks(y_low, max(ys), log_y)
    x0, x1, y0, y1 = xt[0], xt[-1], yt[0], yt[-1]
    tx = (lambda v: math.log10(v)) if log_x else (lambda v: v)
    ty = (lambda v: math.log10(v)) if log_y else (lambda v: v)

    def sx(v):
        return x + left + (tx(v) - tx(x0)) / (tx(x1) - tx(x0)) * pw

    def sy(v):
        return y + top + ph - (ty(v) - ty(y0)) / (ty(y1) - ty(y0)) * ph

    out = []
    if title:
        out.append('<text x="%.1f" y="%.1f" text-anchor="middle" font-size="13" '
                   'font-weight="bold">%s</text>' % (x + left + pw / 2, y + 16, escape(title)))
    out.append('<rect x="%.1f" y="%.1f" width="%.1f" height="%.1f" fill="none" '
               'stroke="#333"/>' % (x + left, y + top, pw, ph))
    for v in xt:
        out.append('<line x1="%.1f" y1="%.1f" x2="%.1f" y2="%.1f" stroke="#ddd"/>'
                   % (sx(v), y + top, sx(v), y + top + ph))
        out.append('<text x="%.1f" y="%.1f" text-anchor="middle" font-size="10">%s</text>'
                   % (sx(v), y + top + ph + 14, _fmt(v)))
    for v in yt:
        out.append('<line x1="%.1f" y1="%.1f" x2="%.1f" y2="%.1f" stroke="#ddd"/>'
                   % (x + left, sy(v), x + left + pw, sy(v)))
        out.append('<text x="%.1f" y="%.1f" text-anchor="end" font-size="10">%s</text>'
                   % (x + left - 4, sy(v) + 3, _fmt(v)))
    out.append('<text x="%.1f" y="%.1f" text-anchor="middle" font-size="11">%s</text>'
               % (x + left + pw / 2, y + height - 8, escape(x_label)))
    out.append('<text x="%.1f" y="%.1f" text-anchor="middle" font-size="11" '
               'transform="rotate(-90 %.1f %.1f)">%s</text>'
               % (x + 14, y + top + ph / 2, x + 14, y + top + ph / 2, escape(y_label)))
    drawn = [[(sx(px), sy(py)) for px, py in pts if _finite(px, log_x) and _finite(py, log_y)]
             for _, pts in series]
    lx, ly0 = _legend_corner(drawn, len(series), x + left, y + top, pw, ph)
    for i, (name, pts) in enumerate(series):
        colour = COLOURS[i % len(COLOURS)]
        kept = drawn[i]
        if len(kept) > 1:
            out.append('<polyline fill="none" stroke="%s" stroke-width="1.6" points="%s"/>'
                       % (colour, " ".join("%.1f,%.1f" % p for p in kept)))
        for px, py in kept:
            out.append(_marker(MARKERS[i // len(COLOURS) % len(MARKERS)], px, py, colour))
        ly = ly0 + 14 * i
        out.append('<line x1="%.1f" y1="%.1f" x2="%.1f" y2="%.1f" stroke="%s" '
                   'stroke-width="1.6"/>' % (lx, ly, lx + 18, ly, colour))
        out.append(_marker(MARKERS[i // len(COLOURS) % len(MARKERS)], lx + 9, ly, colour))
        out.append('<text x="%.1f" y="%.1f" font-size="10">%s</text>'
                   % (lx + 22, ly + 3, escape(name)))
    return "\n".join(out)


LEGEND_WIDTH = 140


def _legend_corner(drawn, count, px, py, pw, ph):
    """The left end and first line's height of the legend: the corner of the plot area
    (top right, bottom right, top left, bottom left, in that order of preference) whose
    legend box covers the fewest drawn points."""
    height = 14 * count + 6
    corners = [(px + pw - LEGEND_WIDTH, py + 10), (px + pw - LEGEND_WIDTH, py + ph - height + 4),
               (px + 8, py + 10), (px + 8, py + ph - height + 4)]

    def covered(corner):
        cx, cy = corner
        return sum(1 for pts in drawn for qx, qy in pts
                   if cx - 4 <= qx <= cx + LEGEND_WIDTH and cy - 10 <= qy <= cy + height)
    return min(corners, key=covered)


def _marker(shape, px, py, colour):
    r = 3.0
    if shape == "square":
        return ('<rect x="%.1f" y="%.1f" width="%.1f" height="%.1f" fill="%s"/>'
                % (px - r, py - r, 2 * r, 2 * r, colour))
    if shape == "triangle":
        return ('<polygon points="%.1f,%.1f %.1f,%.1f %.1f,%.1f" fill="%s"/>'
                % (px, py - r, px - r, py + r, px + r, py + r, colour))
    if shape == "diamond":
        return ('<polygon points="%.1f,%.1f %.1f,%.1f %.1f,%.1f %.1f,%.1f" fill="%s"/>'
                % (px, py - r, px + r, py, px, py + r, px - r, py, colour))
    return '<circle cx="%.1f" cy="%.1f" r="%.1f" fill="%s"/>' % (px, py, r, colour)


def figure(panels, width=420, height=300):
    """An SVG document of `panels` (keyword arguments of `line_plot`) side by side."""
    body = [line_plot(width=width, height=height, x=i * width, y=0, **panel)
            for i, panel in enumerate(panels)]
    return ('<svg xmlns="http://www.w3.org/2000/svg" width="%d" height="%d" '
            'viewBox="0 0 %d %d" font-family="sans-serif">\n'
            '<rect width="100%%" height="100%%" fill="white"/>\n%s\n</svg>\n'
            % (width * len(panels), height, width * len(panels), height, "\n".join(body)))


def csv_series(path, x, y, series, where=()):
    """The series of the CSV file at `path`: rows grouped by the values of the columns
    `series` (a list; their values joined by ", " name the series, in order of first
    appearance), each the points (float(row[x]), float(row[y])) in file order. `where` is a
    list of (column, value) pairs: only rows whose cells equal every value count."""
    groups = {}
    with open(path, newline="") as f:
        reader = csv.DictReader(f)
        for column in [x, y] + list(series) + [c for c, _ in where]:
            if column not in (reader.fieldnames or []):
                raise ValueError("%s: no column %r (columns: %s)"
                                 % (path, column, ", ".join(reader.fieldnames or [])))
        for row in reader:
            if any(row[c] != v for c, v in where):
                continue
            name = ", ".join(row[c] for c in series) if series else y
            groups.setdefault(name, []).append((float(row[x]), float(row[y])))
    return list(groups.items())
