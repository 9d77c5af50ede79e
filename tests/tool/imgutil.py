"""Test helpers: PNG (every colour type, bit depth, Adam7) and PGM writers with zlib + struct,
masks, shapes, and running the amscr tool. Standard library only (no Pillow)."""
import math
import os
import struct
import subprocess
import tempfile
import zlib

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def tool_path():
    return os.environ.get("AMSCR_TOOL") or os.path.join(REPO, "build", "tools", "amscr")


def datasets_dir():
    d = os.environ.get("AMSCR_DATASETS") or os.path.join(REPO, "..", "shared", "datasets")
    return d if os.path.isdir(d) else None


def run(*args, cwd=None, timeout=300):
    """Runs the tool; returns CompletedProcess with text stdout/stderr."""
    return subprocess.run([tool_path()] + [str(a) for a in args], capture_output=True, text=True, cwd=cwd,
                          timeout=timeout)


def run_peak_memory(*args):
    """Runs the tool; returns (exit status, stderr, the child's peak resident memory in KiB)."""
    with tempfile.TemporaryFile() as err:
        p = subprocess.Popen([tool_path()] + [str(a) for a in args], stdout=subprocess.DEVNULL, stderr=err)
        _, status, usage = os.wait4(p.pid, 0)
        p.returncode = os.waitstatus_to_exitcode(status)
        err.seek(0)
        return p.returncode, err.read().decode(), usage.ru_maxrss


# --------------------------------------------------------------------------- masks


def blank(w, h, v=0):
    return [[v] * w for _ in range(h)]


def fill_rect(img, x0, y0, x1, y1, v):
    """Inclusive rectangle."""
    for y in range(y0, y1 + 1):
        for x in range(x0, x1 + 1):
            img[y][x] = v
    return img


def rect_mask(w=40, h=30, rect=(5, 7, 24, 19), fg=1, bg=0):
    return fill_rect(blank(w, h, bg), *rect, fg)


def map_img(img, f):
    return [[f(v) for v in row] for row in img]


# --------------------------------------------------------------------------- PNG

ADAM7 = [(0, 0, 8, 8), (4, 0, 8, 8), (0, 4, 4, 8), (2, 0, 4, 4), (0, 2, 2, 4), (1, 0, 2, 2), (0, 1, 1, 2)]
CHANNELS = {0: 1, 2: 3, 3: 1, 4: 2, 6: 4}


def _chunk(kind, data):
    return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF)


def _pack_row(pixels, depth, channels):
    """pixels: list of tuples (or ints when channels == 1)."""
    if depth >= 8:
        out = bytearray()
        for p in pixels:
            vals = p if isinstance(p, (tuple, list)) else (p,)
            assert len(vals) == channels
            for v in vals:
                out += struct.pack(">H", v) if depth == 16 else bytes([v])
        return bytes(out)
    out = bytearray()
    acc, nbits = 0, 0
    for p in pixels:
        v = p if not isinstance(p, (tuple, list)) else p[0]
        assert 0 <= v < (1 << depth)
        acc = (acc << depth) | v
        nbits += depth
        if nbits == 8:
            out.append(acc)
            acc, nbits = 0, 0
    if nbits:
        out.append(acc << (8 - nbits))
    return bytes(out)


def png_bytes(img, color_type=0, depth=8, palette=None, trns=None, interlace=False, extra_chunks=()):
    """img: rows of pixel values (int for 1-channel types, tuples otherwise)."""
    h, w = len(img), len(img[0])
    channels = CHANNELS[color_type]
    raw = bytearray()
    if not interlace:
        for row in img:
            raw += b"\x00" + _pack_row(row, depth, channels)
    else:
        for x0, y0, dx, dy in ADAM7:
            xs = list(range(x0, w, dx))
            ys = list(range(y0, h, dy))
            if not xs or not ys:
                continue
            for y in ys:
                raw += b"\x00" + _pack_row([img[y][x] for x in xs], depth, channels)
    ihdr = struct.pack(">IIBBBBB", w, h, depth, color_type, 0, 0, 1 if interlace else 0)
    out = b"\x89PNG\r\n\x1a\n" + _chunk(b"IHDR", ihdr)
    if palette is not None:
        out += _chunk(b"PLTE", b"".join(bytes(c) for c in palette))
    if trns is not None:
        out += _chunk(b"tRNS", trns)
    for kind, data in extra_chunks:
        out += _chunk(kind, data)
    out += _chunk(b"IDAT", zlib.compress(bytes(raw), 6)) + _chunk(b"IEND", b"")
    return out


def png_header_only(w, h, depth=8, color_type=0):
    ihdr = struct.pack(">IIBBBBB", w, h, depth, color_type, 0, 0, 0)
    return b"\x89PNG\r\n\x1a\n" + _chunk(b"IHDR", ihdr)


def png_short_claim(w, h):
    """An interlaced 1-bit palette image with transparency (expanded to 4 bytes a pixel) whose
    header claims w x h pixels while its image data is a few kilobytes of compressed zeros."""
    ihdr = struct.pack(">IIBBBBB", w, h, 1, 3, 0, 0, 1)
    return (b"\x89PNG\r\n\x1a\n" + _chunk(b"IHDR", ihdr) + _chunk(b"PLTE", b"\x00\x00\x00\xff\xff\xff") +
            _chunk(b"tRNS", b"\x00\xff") + _chunk(b"IDAT", zlib.compress(bytes(4000000), 9)) + _chunk(b"IEND", b""))


# --------------------------------------------------------------------------- PGM


def pgm_bytes(img, maxval=255, ascii=False, comments=False):
    h, w = len(img), len(img[0])
    if ascii:
        if comments:
            head = "P2\n# a comment\n%d # width\n# between\n%d\n# before maxval\n%d\n" % (w, h, maxval)
        else:
            head = "P2\n%d %d\n%d\n" % (w, h, maxval)
        body = "\n".join(" ".join(str(v) for v in row) for row in img) + "\n"
        return (head + body).encode()
    if comments:
        head = b"P5\n# made by a test\n%d %d # size\n# the maxval follows\n%d\n" % (w, h, maxval)
    else:
        head = b"P5\n%d %d\n%d\n" % (w, h, maxval)
    if maxval < 256:
        body = b"".join(bytes(row) for row in img)
    else:
        body = b"".join(struct.pack(">%dH" % w, *row) for row in img)
    return head + body


# --------------------------------------------------------------------------- points


def read_points(text):
    pts = []
    for line in text.splitlines():
        line = line.strip()
        if not line or line.startswith("#"):
            continue
        x, y = line.replace(",", " ").split()
        pts.append((float(x), float(y)))
    return pts


def extremes(pts):
    xs = [p[0] for p in pts]
    ys = [p[1] for p in pts]
    return min(xs), min(ys), max(xs), max(ys)


def signed_area(pts):
    a = 0.0
    n = len(pts)
    for i in range(n):
        x0, y0 = pts[i]
        x1, y1 = pts[(i + 1) % n]
        a += x0 * y1 - x1 * y0
    return a / 2


def smooth_shape(n=300, seed=0):
    """A smooth, asymmetric closed curve (no symmetry, so the registration is unique)."""
    pts = []
    for i in range(n):
        t = 2 * math.pi * i / n
        r = 1 + 0.30 * math.cos(3 * t + 0.4) + 0.12 * math.sin(5 * t + seed) + 0.07 * math.cos(2 * t + 1.1)
        pts.append((60 * r * math.cos(t), 60 * r * math.sin(t)))
    return pts


def affine(m, pts):
    (a11, a12, bx), (a21, a22, by) = m
    return [(a11 * x + a12 * y + bx, a21 * x + a22 * y + by) for x, y in pts]


def write_points(path, pts):
    with open(path, "w") as f:
        for x, y in pts:
            f.write("%.17g %.17g\n" % (x, y))


def rasterize(poly, w, h, fg=255, bg=0):
    img = blank(w, h, bg)
    n = len(poly)
    for row in range(h):
        xs = []
        for i in range(n):
            x0, y0 = poly[i]
            x1, y1 = poly[(i + 1) % n]
            if (y0 <= row < y1) or (y1 <= row < y0):
                xs.append(x0 + (row - y0) / (y1 - y0) * (x1 - x0))
        xs.sort()
        for k in range(0, len(xs) - 1, 2):
            for col in range(max(0, math.ceil(xs[k])), min(w - 1, math.ceil(xs[k + 1]) - 1) + 1):
                img[row][col] = fg
    return img


_HAVE_PNG = None


def have_png():
    """Whether the tool decodes PNG (it is built without libpng when libpng is absent)."""
    global _HAVE_PNG
    if _HAVE_PNG is None:
        import tempfile
        with tempfile.TemporaryDirectory() as d:
            p = os.path.join(d, "probe.png")
            with open(p, "wb") as f:
                f.write(png_bytes(rect_mask(fg=255), 0, 8))
            r = run("contour", p)
            _HAVE_PNG = r.returncode == 0 or "without libpng" not in r.stderr
    return _HAVE_PNG


def image_bytes(img, name):
    """PNG or PGM by the name's extension (8-bit gray)."""
    return png_bytes(img, 0, 8) if name.endswith(".png") else pgm_bytes(img)


def img_ext():
    """The image extension tests should use: .png when the tool reads PNG, else .pgm."""
    return ".png" if have_png() else ".pgm"
