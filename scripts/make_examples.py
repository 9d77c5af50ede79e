#!/usr/bin/env python3
"""Generates the bundled example silhouettes in examples/ (Python standard library only).

    python3 scripts/make_examples.py [OUTDIR]     (default: examples/ next to scripts/)

Writes small 8-bit grayscale PNGs (shape white on black, written with zlib + struct), one
PGM, text point lists of the exact polygons, an affine-distorted pair with a known map, a
tiny labelled collection, and examples/README.md stating the pair's true map. When the
amscr tool is built (build/tools/amscr, or $AMSCR_TOOL), it also registers the pair and
writes the pictures pair-overlay.png and pair-plot.svg, the contact sheet of a search of the
collection (search-sheet.png) and the plot of its evaluation (eval-plot.svg).

Coordinates are pixel coordinates: x = column, y = row (y down), pixel centres at
integers, as amscr_contour_from_mask reports them. A pixel is inside a shape when its
centre is inside the polygon (even-odd rule). The output is deterministic.
"""
import math
import os
import random
import struct
import subprocess
import sys
import zlib

SIZE = 160

# --------------------------------------------------------------------------- writers


def png_bytes(width, height, rows):
    """8-bit grayscale PNG from a list of `height` bytes objects of `width` bytes."""
    raw = b"".join(b"\x00" + bytes(r) for r in rows)

    def chunk(kind, data):
        c = struct.pack(">I", len(data)) + kind + data
        return c + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF)

    ihdr = struct.pack(">IIBBBBB", width, height, 8, 0, 0, 0, 0)
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", ihdr) + chunk(b"IDAT", zlib.compress(raw, 9))
            + chunk(b"IEND", b""))


def pgm_bytes(width, height, rows, comment=None):
    head = b"P5\n"
    if comment:
        head += b"# " + comment.encode() + b"\n"
    head += b"%d %d\n255\n" % (width, height)
    return head + b"".join(bytes(r) for r in rows)


def write(path, data):
    tmp = path + ".tmp"
    with open(tmp, "wb") as f:
        f.write(data)
    os.replace(tmp, path)


def write_points(path, pts, comment):
    lines = ["# " + comment] + ["%.6f %.6f" % (x, y) for x, y in pts]
    write(path, ("\n".join(lines) + "\n").encode())


# --------------------------------------------------------------------------- geometry


def rasterize(poly, width=SIZE, height=SIZE):
    """Even-odd scanline fill at pixel centres: rows of 0/255."""
    rows = []
    n = len(poly)
    for row in range(height):
        y = float(row)
        xs = []
        for i in range(n):
            x0, y0 = poly[i]
            x1, y1 = poly[(i + 1) % n]
            if (y0 <= y < y1) or (y1 <= y < y0):
                xs.append(x0 + (y - y0) / (y1 - y0) * (x1 - x0))
        xs.sort()
        line = bytearray(width)
        for k in range(0, len(xs) - 1, 2):
            a = max(0, math.ceil(xs[k]))
            b = min(width - 1, math.ceil(xs[k + 1]) - 1)
            for col in range(a, b + 1):
                line[col] = 255
        rows.append(line)
    return rows


def catmull_rom(ctrl, per_segment=8):
    """Closed Catmull-Rom spline through the control points."""
    out = []
    n = len(ctrl)
    for i in range(n):
        p0, p1, p2, p3 = ctrl[i - 1], ctrl[i], ctrl[(i + 1) % n], ctrl[(i + 2) % n]
        for s in range(per_segment):
            t = s / per_segment
            t2, t3 = t * t, t * t * t
            out.append(tuple(
                0.5 * (2 * p1[k] + (-p0[k] + p2[k]) * t + (2 * p0[k] - 5 * p1[k] + 4 * p2[k] - p3[k]) * t2
                       + (-p0[k] + 3 * p1[k] - 3 * p2[k] + p3[k]) * t3) for k in range(2)))
    return out


def apply(m, pts):
    (a11, a12, bx), (a21, a22, by) = m
    return [(a11 * x + a12 * y + bx, a21 * x + a22 * y + by) for x, y in pts]


def bbox(pts):
    xs = [p[0] for p in pts]
    ys = [p[1] for p in pts]
    return min(xs), min(ys), max(xs), max(ys)


def fit_into_canvas(pts, margin=12, size=SIZE):
    """Uniform scale (only if too big) and translation into the canvas: an affine map."""
    x0, y0, x1, y1 = bbox(pts)
    s = min(1.0, (size - 1 - 2 * margin) / max(x1 - x0, y1 - y0))
    cx, cy = (x0 + x1) / 2, (y0 + y1) / 2
    c = (size - 1) / 2
    return [((x - cx) * s + c, (y - cy) * s + c) for x, y in pts]


# --------------------------------------------------------------------------- shapes


def fish():
    ctrl = [(18, 80), (30, 64), (48, 54), (68, 47), (80, 30), (92, 46), (106, 54), (121, 72), (146, 46),
            (137, 80), (146, 114), (121, 88), (104, 104), (88, 112), (84, 126), (72, 113), (48, 106), (30, 96)]
    return catmull_rom(ctrl)


def bird():
    ctrl = [(22, 50), (40, 44), (48, 32), (62, 30), (70, 40), (74, 56), (100, 60), (128, 66), (152, 58),
            (142, 78), (120, 92), (100, 100), (96, 106), (97, 132), (91, 132), (88, 108), (80, 108),
            (80, 132), (74, 132), (72, 104), (60, 92), (54, 72), (50, 58), (40, 54)]
    return catmull_rom(ctrl, 6)


def leaf():
    pts = []
    m = 72
    for i in range(m + 1):  # upper edge, left to right
        u = i / m
        x = 28 + 110 * u
        y = 80 - 38 * math.sin(math.pi * u) ** 0.8 * (1 - 0.25 * u) - 1.5 * math.sin(14 * math.pi * u)
        pts.append((x, y))
    for i in range(m - 1, 0, -1):  # lower edge, right to left
        u = i / m
        x = 28 + 110 * u
        y = 80 + 30 * math.sin(math.pi * u) ** 0.9 * (1 - 0.1 * u) + 1.5 * math.sin(14 * math.pi * u)
        pts.append((x, y))
    # stem on the left
    pts += [(28, 82.5), (12, 86), (10, 83), (28, 78.5)]
    return pts


def star():
    pts = []
    for k in range(10):
        r = 70 if k % 2 == 0 else 29
        a = -math.pi / 2 + k * math.pi / 5
        pts.append((79.5 + r * math.cos(a), 82 + r * math.sin(a)))
    return pts


SHAPES = {"fish": fish, "bird": bird, "leaf": leaf, "star": star}

# The pair: target = A * source + B (pixel coordinates), with shear and anisotropic scale.
PAIR_A = ((0.75, 0.35), (-0.2, 0.65))


def random_affine(rng):
    th = rng.uniform(-math.pi, math.pi)
    s1, s2 = rng.uniform(0.75, 1.0), rng.uniform(0.55, 0.9)
    h = rng.uniform(-0.35, 0.35)
    c, s = math.cos(th), math.sin(th)
    # R(th) * diag(s1, s2) * shear(h)
    m = [[c * s1, c * s1 * h - s * s2], [s * s1, s * s1 * h + c * s2]]
    return ((m[0][0], m[0][1], 0.0), (m[1][0], m[1][1], 0.0))


def write_silhouettes(out):
    """The single silhouettes (PNG) and one small binary PGM with a header comment."""
    for name, make in SHAPES.items():
        write(os.path.join(out, name + ".png"), png_bytes(SIZE, SIZE, rasterize(make())))
    small = [((x - 10) * 0.4 + 1, (y - 40) * 0.4 + 2) for x, y in leaf()]
    write(os.path.join(out, "leaf-small.pgm"),
          pgm_bytes(64, 40, rasterize(small, 64, 40), "leaf, made by scripts/make_examples.py"))


def write_pair(out):
    """The affine pair (images and exact polygons); returns its map ((a11, a12, bx), (a21, a22, by))."""
    src = fish()
    (a11, a12), (a21, a22) = PAIR_A
    moved = apply(((a11, a12, 0.0), (a21, a22, 0.0)), src)
    x0, y0, x1, y1 = bbox(moved)
    bx = round((SIZE - 1) / 2 - (x0 + x1) / 2, 1)
    by = round((SIZE - 1) / 2 - (y0 + y1) / 2, 1)
    pair_m = ((a11, a12, bx), (a21, a22, by))
    tgt = apply(pair_m, src)
    write(os.path.join(out, "pair-source.png"), png_bytes(SIZE, SIZE, rasterize(src)))
    write(os.path.join(out, "pair-target.png"), png_bytes(SIZE, SIZE, rasterize(tgt)))
    write_points(os.path.join(out, "pair-source.txt"), src, "fish polygon (source), x = column, y = row")
    write_points(os.path.join(out, "pair-target.txt"), tgt,
                 "the source under x' = %g x + %g y + %g, y' = %g x + %g y + %g" % (a11, a12, bx, a21, a22, by))
    return pair_m


def write_collection(out):
    """A tiny labelled collection: 3 seeded random affine copies of each shape."""
    cdir = os.path.join(out, "collection")
    os.makedirs(cdir, exist_ok=True)
    rng = random.Random(20240607)
    for name, make in SHAPES.items():
        for k in range(1, 4):
            pts = fit_into_canvas(apply(random_affine(rng), make()))
            write(os.path.join(cdir, "%s-%d.png" % (name, k)), png_bytes(SIZE, SIZE, rasterize(pts)))


README = """# Example silhouettes

Generated by `python3 scripts/make_examples.py` (standard library only; deterministic).
All images are 8-bit grayscale, shape white (255) on black (0). Coordinates are pixel
coordinates: x = column, y = row (pointing down), pixel centres at integers.

| file | what |
|---|---|
| `fish.png`, `bird.png`, `leaf.png`, `star.png` | 160 x 160 silhouettes |
| `leaf-small.pgm` | a 64 x 40 binary PGM (P5, with a header comment) |
| `pair-source.png`, `pair-target.png` | an affine-distorted pair (below) |
| `pair-source.txt`, `pair-target.txt` | the exact polygons of the pair, as text point lists |
| `collection/` | 4 classes (fish, bird, leaf, star) x 3 random affine copies, for `search` and `eval` |
| `pair-overlay.png`, `pair-plot.svg` | `amscr register` pictures of the pair (written when the tool is built) |
| `search-sheet.png` | `amscr search fish.png collection --top 7 --sheet search-sheet.png` (written when the tool is built) |
| `eval-plot.svg` | `amscr eval collection --plot eval-plot.svg` (written when the tool is built) |

## The affine pair

`pair-target` is `pair-source` (the fish) under the affine map, in pixel coordinates,

    x' = {a11} x + {a12} y {sbx}
    y' = {a21} x + {a22} y {sby}

that is A = [[{a11}, {a12}], [{a21}, {a22}]] (shear and anisotropic scale, det {det:.4f}) and
B = [{bx}, {by}]. `amscr register pair-source.png pair-target.png` should report this
(A, B) up to the pixel rasterization; on the `.txt` polygons the map is exact.

![overlay](pair-overlay.png)

![scale selection](pair-plot.svg)

## A search and an evaluation of the collection

Every hit is drawn in red registered onto the query (grey), with its rank, class and distance:

![contact sheet](search-sheet.png)

![per-class scores and precision-recall](eval-plot.svg)

Try:

    amscr register examples/pair-source.png examples/pair-target.png --overlay overlay.png --plot plot.svg
    amscr register examples/pair-source.txt examples/pair-target.txt --json
    amscr search examples/fish.png examples/collection --top 5 --sheet sheet.png
    amscr eval examples/collection --plot scores.svg
"""


def write_readme(out, pair_m):
    """examples/README.md, stating the pair's true map."""
    (a11, a12, bx), (a21, a22, by) = pair_m
    readme = README.format(a11=a11, a12=a12, a21=a21, a22=a22, bx=bx, by=by, det=a11 * a22 - a12 * a21,
                           sbx=("- %g" % -bx) if bx < 0 else ("+ %g" % bx),
                           sby=("- %g" % -by) if by < 0 else ("+ %g" % by))
    write(os.path.join(out, "README.md"), readme.encode())


def run_tool(cmd, what, tool):
    """Runs one tool command that writes a picture; says what it wrote or why it failed."""
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode == 0:
        print("wrote %s with %s" % (what, tool))
    else:
        print("%s failed: %s" % (" ".join(cmd[:2]), r.stderr.strip()), file=sys.stderr)


def write_pictures(out, tool):
    """The tool's pictures: the pair registered, a search's contact sheet, an evaluation's plot."""
    cmd = [tool, "register", os.path.join(out, "pair-source.png"), os.path.join(out, "pair-target.png"),
           "--overlay", os.path.join(out, "pair-overlay.png"), "--plot", os.path.join(out, "pair-plot.svg")]
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode == 0:
        print("wrote pair-overlay.png and pair-plot.svg with %s" % tool)
    else:
        print("amscr register failed, pictures not written: %s" % r.stderr.strip(), file=sys.stderr)
    coll = os.path.join(out, "collection")
    run_tool([tool, "search", os.path.join(out, "fish.png"), coll, "--top", "7", "--sheet",
              os.path.join(out, "search-sheet.png")], "search-sheet.png", tool)
    run_tool([tool, "eval", coll, "--plot", os.path.join(out, "eval-plot.svg")], "eval-plot.svg", tool)


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    if len(sys.argv) > 2 or (len(sys.argv) == 2 and sys.argv[1].startswith("-")):
        print(__doc__.split("\n\n")[1].strip(), file=sys.stderr if sys.argv[1] not in ("-h", "--help") else sys.stdout)
        sys.exit(0 if sys.argv[1] in ("-h", "--help") else 2)
    out = sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(here), "examples")
    os.makedirs(out, exist_ok=True)
    write_silhouettes(out)
    pair_m = write_pair(out)
    write_collection(out)
    write_readme(out, pair_m)
    (_, _, bx), (_, _, by) = pair_m
    print("wrote examples to %s (pair: A = %s, B = [%g, %g])" % (out, PAIR_A, bx, by))
    tool = os.environ.get("AMSCR_TOOL") or os.path.join(os.path.dirname(here), "build", "tools", "amscr")
    if os.access(tool, os.X_OK):
        write_pictures(out, tool)


if __name__ == "__main__":
    main()
