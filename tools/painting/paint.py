#!/usr/bin/env python3
"""Turns a render into a "painting": an 8-bit RGB PNG in, an 8-bit RGB PNG of the same size out.

Usage: tools/painting/paint.py IN.png OUT.png

The filter is deterministic (no randomness beyond a fixed integer hash), so the painting of
docs/fitting.md, "A worked example", is reproduced byte for byte by tools/painting/make.sh:
- a Kuwahara filter of radius 2 (each pixel takes the mean of the least varied of its four
  3 x 3 quadrants): flat patches of paint with the edges kept;
- brush strokes: the brightness modulated by +-9 % value noise stretched along the diagonal;
- a canvas weave (every third row and column 4 % darker);
- colours rounded to steps of 10 (of 255).

Pure Python (zlib and struct only): PNG read (colour types 2 and 6, bit depth 8,
non-interlaced) and write.
"""

import struct
import sys
import zlib


def read_png(path):
    data = open(path, "rb").read()
    if data[:8] != b"\x89PNG\r\n\x1a\n":
        sys.exit(f"{path}: not a PNG")
    pos, idat, header = 8, b"", None
    while pos < len(data):
        (length,) = struct.unpack(">I", data[pos:pos + 4])
        kind = data[pos + 4:pos + 8]
        body = data[pos + 8:pos + 8 + length]
        pos += 12 + length
        if kind == b"IHDR":
            header = struct.unpack(">IIBBBBB", body)
        elif kind == b"IDAT":
            idat += body
    width, height, depth, color, _, _, interlace = header
    if depth != 8 or color not in (2, 6) or interlace:
        sys.exit(f"{path}: expected an 8-bit RGB or RGBA PNG, not interlaced")
    channels = 3 if color == 2 else 4
    raw = zlib.decompress(idat)
    stride = width * channels
    rows, prev = [], bytearray(stride)
    for y in range(height):
        kind = raw[y * (stride + 1)]
        line = bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
        for i in range(stride):
            a = line[i - channels] if i >= channels else 0
            b = prev[i]
            c = prev[i - channels] if i >= channels else 0
            if kind == 1:
                line[i] = (line[i] + a) & 255
            elif kind == 2:
                line[i] = (line[i] + b) & 255
            elif kind == 3:
                line[i] = (line[i] + (a + b) // 2) & 255
            elif kind == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                pred = a if pa <= pb and pa <= pc else (b if pb <= pc else c)
                line[i] = (line[i] + pred) & 255
        rows.append([tuple(line[x * channels:x * channels + 3]) for x in range(width)])
        prev = line
    return width, height, rows


def write_png(path, width, height, rows):
    raw = b"".join(b"\x00" + bytes(v for px in row for v in px) for row in rows)

    def chunk(kind, body):
        return struct.pack(">I", len(body)) + kind + body + struct.pack(">I", zlib.crc32(kind + body))

    png = b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0))
    png += chunk(b"IDAT", zlib.compress(raw, 9)) + chunk(b"IEND", b"")
    open(path, "wb").write(png)


def kuwahara(width, height, rows, radius=2):
    """Each pixel: the mean colour of the least varied (in brightness) of its four quadrants."""
    # Summed-area tables of the three channels and of brightness and its square.
    w1 = width + 1
    sums = [[0.0] * (w1 * (height + 1)) for _ in range(5)]
    for y in range(height):
        acc = [0.0] * 5
        for x in range(width):
            r, g, b = rows[y][x]
            lum = 0.3 * r + 0.59 * g + 0.11 * b
            for k, v in enumerate((r, g, b, lum, lum * lum)):
                acc[k] += v
                sums[k][(y + 1) * w1 + x + 1] = sums[k][y * w1 + x + 1] + acc[k]

    def box(k, x0, y0, x1, y1):
        return sums[k][y1 * w1 + x1] - sums[k][y0 * w1 + x1] - sums[k][y1 * w1 + x0] + sums[k][y0 * w1 + x0]

    out = []
    for y in range(height):
        line = []
        for x in range(width):
            best = None
            for dx0, dy0 in ((-radius, -radius), (0, -radius), (-radius, 0), (0, 0)):
                x0, y0 = max(0, x + dx0), max(0, y + dy0)
                x1, y1 = min(width, x + dx0 + radius + 1), min(height, y + dy0 + radius + 1)
                n = (x1 - x0) * (y1 - y0)
                mean = box(3, x0, y0, x1, y1) / n
                var = box(4, x0, y0, x1, y1) / n - mean * mean
                if best is None or var < best[0]:
                    best = (var, tuple(box(k, x0, y0, x1, y1) / n for k in range(3)))
            line.append(best[1])
        out.append(line)
    return out


def hash01(i, j):
    """A fixed integer hash of (i, j) in [0, 1)."""
    h = (i * 374761393 + j * 668265263) & 0xFFFFFFFF
    h = ((h ^ (h >> 13)) * 1274126177) & 0xFFFFFFFF
    return ((h ^ (h >> 16)) & 0xFFFF) / 65536.0


def value_noise(s, t):
    i, j = int(s // 1), int(t // 1)
    fs, ft = s - i, t - j
    fs, ft = fs * fs * (3 - 2 * fs), ft * ft * (3 - 2 * ft)
    a, b = hash01(i, j), hash01(i + 1, j)
    c, d = hash01(i, j + 1), hash01(i + 1, j + 1)
    return (a + (b - a) * fs) + ((c + (d - c) * fs) - (a + (b - a) * fs)) * ft


def paint(width, height, rows):
    smooth = kuwahara(width, height, rows)
    out = []
    for y in range(height):
        line = []
        for x in range(width):
            # Strokes about 10 px long along the diagonal, 2 px wide across it.
            stroke = value_noise((x - y) / 2.0, (x + y) / 10.0) - 0.5
            weave = 0.96 if (x % 3 == 0) != (y % 3 == 0) else 1.0
            gain = (1.0 + 0.18 * stroke) * weave
            line.append(tuple(min(250, max(0, int(round(v * gain / 10.0)) * 10)) for v in smooth[y][x]))
        out.append(line)
    return out


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__.split("\n\n")[1])
    width, height, rows = read_png(sys.argv[1])
    write_png(sys.argv[2], width, height, paint(width, height, rows))


if __name__ == "__main__":
    main()
