"""examples/ is what scripts/make_examples.py writes with the current tool: the silhouettes, the
pair's polygons, the README's stated map, and the tool's pictures (pair-overlay.png,
pair-plot.svg, search-sheet.png, eval-plot.svg) from the commands examples/README.md names.
A picture compares by its pixels (PNG) or its text with numbers to 0.05 (SVG), so that another
zlib or the last bits of another libm do not fail it; a changed drawing or ranking does."""
import os
import re
import subprocess
import sys
import zlib

import pytest

from imgutil import REPO, tool_path

EXAMPLES = os.path.join(REPO, "examples")
NUMBER = re.compile(r"-?\d+(?:\.\d+)?(?:e[-+]?\d+)?")


def png_pixels(path):
    """(width, height, colour type, the unfiltered rows) of an 8-bit non-interlaced PNG."""
    data = open(path, "rb").read()
    assert data[:8] == b"\x89PNG\r\n\x1a\n", path
    i, idat, head = 8, b"", None
    while i < len(data):
        n = int.from_bytes(data[i:i + 4], "big")
        kind, body = data[i + 4:i + 8], data[i + 8:i + 8 + n]
        if kind == b"IHDR":
            head = body
        elif kind == b"IDAT":
            idat += body
        i += 12 + n
    w, h = int.from_bytes(head[0:4], "big"), int.from_bytes(head[4:8], "big")
    depth, ctype, interlace = head[8], head[9], head[12]
    assert depth == 8 and interlace == 0 and ctype in (0, 2, 6), (path, depth, ctype, interlace)
    bpp = {0: 1, 2: 3, 6: 4}[ctype]
    raw, stride, rows, prev = zlib.decompress(idat), w * bpp, [], bytearray(w * bpp)
    for y in range(h):
        f, line = raw[y * (stride + 1)], bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
        for x in range(stride):
            a = line[x - bpp] if x >= bpp else 0
            b, c = prev[x], prev[x - bpp] if x >= bpp else 0
            if f == 1:
                line[x] = (line[x] + a) & 255
            elif f == 2:
                line[x] = (line[x] + b) & 255
            elif f == 3:
                line[x] = (line[x] + (a + b) // 2) & 255
            elif f == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                line[x] = (line[x] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
        rows.append(bytes(line))
        prev = line
    return w, h, ctype, rows


def same_svg(a, b):
    ta, tb = open(a).read(), open(b).read()
    if NUMBER.sub("#", ta) != NUMBER.sub("#", tb):
        return False
    na, nb = NUMBER.findall(ta), NUMBER.findall(tb)
    return all(abs(float(x) - float(y)) <= 0.05 for x, y in zip(na, nb))


@pytest.mark.png
def test_examples_are_what_make_examples_writes(tmp_path):
    env = dict(os.environ, AMSCR_TOOL=tool_path())
    r = subprocess.run([sys.executable, os.path.join(REPO, "scripts", "make_examples.py"), str(tmp_path)],
                       capture_output=True, text=True, env=env, timeout=300)
    assert r.returncode == 0 and r.stderr == "", r.stderr
    for picture in ["pair-overlay.png", "pair-plot.svg", "search-sheet.png", "eval-plot.svg"]:
        assert picture in r.stdout, r.stdout  # "wrote ... with TOOL"

    def files(top):
        return sorted(os.path.relpath(os.path.join(d, f), top) for d, _, fs in os.walk(top) for f in fs)

    assert files(str(tmp_path)) == files(EXAMPLES)
    stale = []
    for name in files(EXAMPLES):
        bundled, made = os.path.join(EXAMPLES, name), os.path.join(str(tmp_path), name)
        if name.endswith(".png"):
            same = png_pixels(bundled) == png_pixels(made)
        elif name.endswith(".svg"):
            same = same_svg(bundled, made)
        else:
            same = open(bundled, "rb").read() == open(made, "rb").read()
        if not same:
            stale.append(name)
    assert stale == [], "examples/ drifted from scripts/make_examples.py (run it): %s" % stale
