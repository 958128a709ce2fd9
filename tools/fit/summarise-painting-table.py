#!/usr/bin/env python3
"""Summarises a table printed by `fits_of_noisy_pinhole_clicks`
(crates/flexcam-cli/tests/fit_painting.rs) for docs/fitting.md.

Usage: summarise-painting-table.py TABLE.md [AUTO_COLUMN ...]

Reads the markdown table (its header names the columns: seed, points, noise px, then one
column per model, "99.87 P" = per cent of pixels away from object edges whose object id
matches the truth's, and the model's letter), and prints per model its worst seed, and for
each AUTO_COLUMN (default: `auto`, and any column whose name starts with `auto`) on how many
seeds it is at least as good as the best of the single models (kept, eye, free, pinhole),
the points it is behind summed over the others, and on how many seeds it reaches 97 %.
A cell that is an error counts as 0 %.
"""
import sys

SINGLE = ("kept", "eye", "free", "pinhole")


def cells(line):
    return [c.strip() for c in line.strip().strip("|").split("|")]


def percent(cell):
    try:
        return float(cell.split()[0])
    except (ValueError, IndexError):
        return 0.0


def main():
    if len(sys.argv) < 2:
        sys.exit("usage: summarise-painting-table.py TABLE.md [AUTO_COLUMN ...]")
    header, rows = None, []
    with open(sys.argv[1]) as table:
        for line in table:
            if not line.startswith("|"):
                continue
            row = cells(line)
            if row[0] == "seed":
                header = row
            elif row[0].isdigit():
                rows.append(row)
    if header is None or not rows:
        sys.exit(f"{sys.argv[1]}: no table of seeds found")
    columns = {name: k for k, name in enumerate(header)}
    singles = [columns[m] for m in SINGLE if m in columns]
    autos = sys.argv[2:] or [name for name in header if name.startswith("auto")]
    for name in header[3:]:
        worst = min(rows, key=lambda r: percent(r[columns[name]]))
        print(f"{name}: worst {percent(worst[columns[name]]):.2f} (seed {worst[0]})")
    if not singles:
        return
    for name in autos:
        k = columns[name]
        ties, behind, reach = 0, 0.0, 0
        for row in rows:
            best = max(percent(row[j]) for j in singles)
            got = percent(row[k])
            ties += got >= best
            behind += max(0.0, best - got)
            reach += got >= 97.0
        print(
            f"{name}: at least as good as the best single model on {ties} of {len(rows)} "
            f"seeds, behind by {behind:.2f} points summed, 97 % reached on {reach}"
        )


if __name__ == "__main__":
    main()
