#!/usr/bin/env python3
"""Regenerates the hand-made seeds of tests/fuzz/corpus/ (files named seed-*). Regression
inputs (regress-*) found by fuzzing are committed next to them and never regenerated.
    python3 tests/fuzz/make_corpus.py [BUILD_DIR]     (BUILD_DIR/libamscr.so for dbload seeds)
"""
import ctypes
import math
import os
import struct
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.normpath(os.path.join(HERE, '..', '..'))
sys.path.insert(0, os.path.join(ROOT, 'tests', 'tool'))
from imgutil import blank, fill_rect, pgm_bytes, png_bytes  # noqa: E402


def put(target, name, data):
    d = os.path.join(HERE, 'corpus', target)
    os.makedirs(d, exist_ok=True)
    if isinstance(data, str):
        data = data.encode()
    with open(os.path.join(d, 'seed-' + name), 'wb') as f:
        f.write(data)


def polygon(n, rx=10.0, ry=6.0, wobble=0.0, phase=0.0):
    pts = []
    for i in range(n):
        t = 2 * math.pi * i / n + phase
        r = 1.0 + wobble * math.cos(3 * t)
        pts.append((rx * r * math.cos(t), ry * r * math.sin(t)))
    return pts


def text(pts, sep=' ', fmt='%.6g'):
    return ''.join((fmt + sep + fmt + '\n') % p for p in pts)


def shape_img(w=16, h=12, fg=255, bg=0):
    img = blank(w, h, bg)
    fill_rect(img, 3, 2, 11, 9, fg)
    fill_rect(img, 6, 5, 8, 6, bg)       # a hole (ignored by the tracer)
    fill_rect(img, 13, 1, 13, 1, fg)     # a speck (dropped)
    return img


# ------------------------------------------------------------------ text
put('text', 'square', '0 0\n1 0\n1 1\n0 1\n')
put('text', 'commas-crlf', '# a comment\r\n0,0\r\n2, 0 # trailing\r\n\r\n2,\t2\r\n0 ,2\r\n')
put('text', 'exponents', '1e3 -2.5E-3\n+4.0 .5\n-0 0x1p3\n1e-320 7\n')
put('text', 'bad-line', '0 0\n1 0\n1 1 1\n')
put('text', 'utf8-bom', b'\xef\xbb\xbf0 0\r\n1 0\r\n1 1\r\n')
put('text', 'ellipse', text(polygon(24, wobble=0.2)))

put('manifest', 'file-class', 'file\tclass\nbird-1.png\tbird\nbird-2.png\tbird\nbone-1.txt\tbone\n')
put('manifest', 'class-first-groups', '# comment\r\nclass\tgroup\tfile\r\n\r\ncup\tcup1\tcup/1.png\r\n'
    'car\tcar1\t/abs/car.png\r\ncup\tcup2\tcup/2.png\r\n')
put('manifest', 'header-only', 'file\tclass\n')
put('manifest', 'short-row', 'file\tclass\tgroup\na.png\tx\n')
put('manifest', 'no-header', 'a.png\tx\n')
put('manifest', 'nul-byte', 'file\tclass\na\0.png\tx\n')
put('manifest', 'utf8-bom', b'\xef\xbb\xbffile\tclass\r\nb\xc3\xa9-1.png\tb\xc3\xa9\r\n')
put('manifest', 'listed-twice', 'file\tclass\na.png\tx\nb.png\ty\na.png\ty\n')
# the same bytes as a folder's .txt (taken when its first line is a point, else skipped)
put('manifest', 'points-after-comments', b'\xef\xbb\xbf# ' + b'c' * 600 + b'\n\n  1.5, -2 # a point\n3 4\n5 6\n')
put('manifest', 'readme-text', 'Shapes of stars.\n1 2\n')

# ------------------------------------------------------------------ pgm
img = shape_img()
put('pgm', 'p5-8bit.pgm', pgm_bytes(img))
put('pgm', 'p2-comments.pgm', pgm_bytes(shape_img(fg=7, bg=1), maxval=7, ascii=True, comments=True))
put('pgm', 'p5-16bit.pgm', pgm_bytes(shape_img(fg=40000, bg=100), maxval=65535, comments=True))
put('pgm', 'truncated.pgm', pgm_bytes(img)[:40])
put('pgm', 'huge-header.pgm', b'P5\n32768 8192\n255\n\0\0\0')

# ------------------------------------------------------------------ png
put('png', 'gray8.png', png_bytes(shape_img(), 0, 8))
put('png', 'gray1-interlaced.png', png_bytes(shape_img(fg=1), 0, 1, interlace=True))
put('png', 'gray16.png', png_bytes(shape_img(fg=50000, bg=10), 0, 16))
rgb = [[(v, v // 2, 255 - v) for v in row] for row in shape_img()]
put('png', 'rgb8.png', png_bytes(rgb, 2, 8))
rgba = [[(200, 30, 30, 255 if v else 0) for v in row] for row in shape_img()]
put('png', 'rgba8-alpha.png', png_bytes(rgba, 6, 8, interlace=True))
pal = [[1 if v else 0 for v in row] for row in shape_img()]
put('png', 'palette-trns.png', png_bytes(pal, 3, 4, palette=[(0, 0, 0), (250, 250, 250)], trns=b'\xff\x80'))
ga = [[(v, 255) for v in row] for row in shape_img()]
put('png', 'gray-alpha.png', png_bytes(ga, 4, 8))

# ------------------------------------------------------------------ mask
def mask_input(img, stride_extra=0, threshold=255):
    w, h = len(img[0]), len(img)
    rows = b''.join(bytes(row) + b'\x99' * stride_extra for row in img)
    return bytes([w - 1, h - 1, stride_extra, threshold]) + rows


put('mask', 'rect-auto', mask_input(shape_img()))
put('mask', 'rect-thr100-stride3', mask_input(shape_img(), 3, 100))
put('mask', 'inverted', mask_input(shape_img(fg=0, bg=255), 0, 127))
ring = blank(12, 12, 0)
fill_rect(ring, 0, 0, 11, 11, 200)
fill_rect(ring, 1, 1, 10, 10, 0)
fill_rect(ring, 4, 4, 7, 7, 200)
put('mask', 'border-ring', mask_input(ring, 1, 100))
line = blank(9, 5, 0)
fill_rect(line, 1, 2, 7, 2, 255)
put('mask', 'thin-line', mask_input(line, 0, 0))

# ------------------------------------------------------------------ subpixel (iso-lines)
def subpixel_input(img, stride_extra=0, level=255, mode=0, bits=8):
    w, h = len(img[0]), len(img)
    if bits == 8:
        rows = b''.join(bytes(row) + b'\x99' * stride_extra for row in img)
    else:
        rows = b''.join(b''.join(int(v).to_bytes(2, sys.byteorder) for v in row) + b'\x99\x99' * stride_extra
                        for row in img)
    return bytes([w - 1, h - 1, stride_extra | (0x80 if bits == 16 else 0), level, mode]) + rows


put('subpixel', 'rect-auto', subpixel_input(shape_img()))
put('subpixel', 'rect-127-stride3-chain', subpixel_input(shape_img(), 3, 127, 2))
grey = [[min(255, max(0, 128 + 40 * (6 - abs(x - 8)) - 30 * abs(y - 6))) for x in range(17)] for y in range(13)]
put('subpixel', 'grey-auto', subpixel_input(grey))
put('subpixel', 'grey16-all', subpixel_input([[v * 257 for v in row] for row in grey], 1, 127, 1, 16))
put('subpixel', 'ring-all', subpixel_input(ring, 1, 100, 1))
pieces = blank(20, 12, 0)
fill_rect(pieces, 2, 3, 9, 6, 255)
fill_rect(pieces, 12, 3, 16, 6, 255)
fill_rect(pieces, 18, 10, 18, 10, 255)
put('subpixel', 'pieces-join', subpixel_input(pieces, 0, 127, 4))
put('subpixel', 'pieces-join-chain', subpixel_input(pieces, 2, 255, 6))
put('subpixel', 'checker-all', subpixel_input([[255 * ((x + y) % 2) for x in range(6)] for y in range(5)], 0, 127, 1))

# ------------------------------------------------------------------ contours (every component)
def contours_input(img, stride_extra=0, threshold=255, min_area=0):
    m = mask_input(img, stride_extra, threshold)
    return m[:4] + bytes([min_area]) + m[4:]


put('contours', 'rect-auto', contours_input(shape_img()))
put('contours', 'ring-with-core', contours_input(ring, 1, 100))
put('contours', 'ring-min-area', contours_input(ring, 0, 100, 30))
nest = blank(20, 16, 0)
fill_rect(nest, 1, 1, 18, 14, 255)
fill_rect(nest, 3, 3, 16, 12, 0)
fill_rect(nest, 5, 5, 14, 10, 255)
fill_rect(nest, 7, 7, 12, 8, 0)
fill_rect(nest, 2, 2, 2, 2, 0)
put('contours', 'nested-holes', contours_input(nest, 2, 127))
put('contours', 'thin-line', contours_input(line, 0, 0))

# ------------------------------------------------------------------ register
def reg(b0, b1, a, b=None):
    s = text(a) + ('|' + text(b) if b is not None else '')
    return bytes([b0, b1]) + s.encode()


src = polygon(20, wobble=0.25)
m = (1.2, 0.3, 4.0, -0.2, 0.8, -1.0)
dst = [(m[0] * x + m[1] * y + m[2], m[3] * x + m[4] * y + m[5]) for x, y in src]
dst = dst[7:] + dst[:7]
put('register', 'affine-pair', reg(0x06, 0x30, src, dst))
put('register', 'self-n32-binary', reg(0x05, 0x34, src))
put('register', 'open-similarity', reg(0x40 | 0x02, 0x01 | 0x10, src[:12], dst[:15]))
put('register', 'reflect-refine', reg(0x20 | 0x18, 0x0e | 0x40, src, [(-x, y) for x, y in dst]))
put('register', 'square-vs-ellipse', reg(0x80, 0x20, [(0, 0), (4, 0), (4, 4), (0, 4), (0, 2), (2, 2)], polygon(10)))
# a target traced from a small binary image (pixels x 1-6, y 1-4 but (6, 1)): its points on the
# pixel lattice, so the polished registration runs the pixel_grid stage
lattice = [(x, 0.5) for x in range(1, 6)] + [(5.5, 1), (6, 1.5)] + [(6.5, y) for y in (2, 3, 4)] + \
    [(x, 4.5) for x in range(6, 0, -1)] + [(0.5, y) for y in (4, 3, 2, 1)]
put('register', 'pixel-lattice', reg(0x06, 0x30, polygon(24, 3.0, 2.0, wobble=0.2), lattice))
# the same image's pixel chain (its boundary pixel centres): traced again at sub-pixel first
chain = [(x, 1) for x in range(1, 6)] + [(6, y) for y in (2, 3, 4)] + [(x, 4) for x in range(5, 0, -1)] + \
    [(1, 3), (1, 2)]
put('register', 'pixel-chain', reg(0x06, 0x30, polygon(24, 3.0, 2.0, wobble=0.2), chain))

# ------------------------------------------------------------------ dbload
build = sys.argv[1] if len(sys.argv) > 1 else os.path.join(ROOT, 'build')
lib = ctypes.CDLL(os.path.join(build, 'libamscr.so'))
P = ctypes.c_void_p


def ok(st):
    if st != 0:
        raise RuntimeError('amscr call failed: %d' % st)


def db_bytes(shapes, n=16, scales=(1.0, 2.0), closed=1, closing=0.0, view=0.0):
    prm = P()
    ok(lib.amscr_params_new(ctypes.byref(prm)))
    ok(lib.amscr_params_set_num_samples(prm, ctypes.c_size_t(n)))
    arr = (ctypes.c_double * len(scales))(*scales)
    ok(lib.amscr_params_set_scales(prm, arr, ctypes.c_size_t(len(scales))))
    ok(lib.amscr_params_set_closed(prm, closed))
    ok(lib.amscr_params_set_num_threads(prm, 1))
    ok(lib.amscr_params_set_inner_closing(prm, ctypes.c_double(closing)))  # > 0: each shape keeps its outline
    ok(lib.amscr_params_set_channel_affine_view(prm, ctypes.c_double(view)))
    db = P()
    ok(lib.amscr_db_new(prm, ctypes.byref(db)))
    for label, pts in enumerate(shapes):
        xy = (ctypes.c_double * (2 * len(pts)))(*[v for p in pts for v in p])
        c = P()
        ok(lib.amscr_contour_new(xy, ctypes.c_size_t(len(pts)), ctypes.byref(c)))
        ok(lib.amscr_db_add_contour(db, c, label + 1, None))
        lib.amscr_contour_free(c)
    buf = P()
    ln = ctypes.c_size_t()
    ok(lib.amscr_db_save_memory(db, ctypes.byref(buf), ctypes.byref(ln)))
    data = ctypes.string_at(buf, ln.value)
    lib.amscr_free(buf)
    lib.amscr_db_free(db)
    lib.amscr_params_free(prm)
    return data[:-8]  # the harness appends the checksum


put('dbload', 'two-shapes', db_bytes([src, polygon(30, 5, 9, 0.1)]))
put('dbload', 'one-shape-scale0', db_bytes([src], scales=(0.0,)))
put('dbload', 'empty', db_bytes([]))
put('dbload', 'open-curve', db_bytes([src[:15]], scales=(1.0,), closed=0))
put('dbload', 'two-shapes-closing', db_bytes([src, polygon(30, 5, 9, 0.1)], closing=0.08))
put('dbload', 'two-shapes-view', db_bytes([src, polygon(30, 5, 9, 0.1)], closing=0.08, view=3.0))
print('seeds written under', os.path.join(HERE, 'corpus'))
