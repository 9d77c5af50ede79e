"""Image decoders of the tool: every PNG colour type and bit depth (interlaced too), PGM P2/P5
(8/16-bit, comments), through `amscr contour --pixel-chain` on a known rectangle (the chain of
pixel centres reads the decoded classification exactly)."""
import pytest

from imgutil import (blank, extremes, fill_rect, map_img, pgm_bytes, png_bytes, read_points, rect_mask, run,
                     signed_area)

RECT = (5, 7, 24, 19)  # x0, y0, x1, y1 inclusive, in a 40 x 30 image


def contour_of(tmp_path, data, name="img", *extra):
    p = tmp_path / name
    p.write_bytes(data)
    r = run("contour", p, "--pixel-chain", *extra)
    assert r.returncode == 0, r.stderr
    assert r.stderr == ""
    return read_points(r.stdout)


def check_rect(pts, rect=RECT):
    assert extremes(pts) == tuple(float(v) for v in rect)
    assert signed_area(pts) > 0  # counter-clockwise in a y-up frame (header convention)
    # the boundary pixels of a filled rectangle, each once
    x0, y0, x1, y1 = rect
    assert len(pts) == 2 * (x1 - x0 + 1) + 2 * (y1 - y0 + 1) - 4
    assert len(set(pts)) == len(pts)


# ---------------------------------------------------------------------------- gray


@pytest.mark.png
@pytest.mark.parametrize("depth", [1, 2, 4, 8, 16])
@pytest.mark.parametrize("interlace", [False, True])
def test_png_gray(tmp_path, depth, interlace):
    img = rect_mask(fg=(1 << depth) - 1, bg=0)
    check_rect(contour_of(tmp_path, png_bytes(img, 0, depth, interlace=interlace), "g.png"))


@pytest.mark.png
@pytest.mark.parametrize("interlace", [False, True])
def test_png_gray16_scaling(tmp_path, interlace):
    # 40000/65535*255 = 156 > 127 (the shape), 30000 -> 117 (background): a decoder that kept
    # the low byte would see 0x40 = 64 and 0x30 = 48; one that kept the high byte 156 and 117.
    img = blank(40, 30, 0)
    fill_rect(img, 0, 0, 39, 3, 30000)  # decoy band, under the threshold after scaling
    fill_rect(img, *RECT, 40000)
    check_rect(contour_of(tmp_path, png_bytes(img, 0, 16, interlace=interlace), "g16.png"))


@pytest.mark.png
@pytest.mark.parametrize("depth", [8, 16])
@pytest.mark.parametrize("interlace", [False, True])
def test_png_gray_alpha(tmp_path, depth, interlace):
    top = (1 << depth) - 1
    # uniform colour, the silhouette is in the alpha channel
    img = map_img(rect_mask(), lambda v: (0, top if v else 0))
    check_rect(contour_of(tmp_path, png_bytes(img, 4, depth, interlace=interlace), "ga.png"))


@pytest.mark.png
@pytest.mark.parametrize("depth", [8, 16])
def test_png_gray_alpha_opaque(tmp_path, depth):
    top = (1 << depth) - 1
    img = map_img(rect_mask(), lambda v: (top if v else 0, top))
    check_rect(contour_of(tmp_path, png_bytes(img, 4, depth), "gao.png"))


@pytest.mark.png
def test_png_gray_trns(tmp_path):
    # both values are dark; only the tRNS transparency (value 50) separates them
    img = map_img(rect_mask(), lambda v: 60 if v else 50)
    check_rect(contour_of(tmp_path, png_bytes(img, 0, 8, trns=bytes([0, 50])), "gt.png"))


# ---------------------------------------------------------------------------- RGB(A)


@pytest.mark.png
@pytest.mark.parametrize("depth", [8, 16])
@pytest.mark.parametrize("interlace", [False, True])
def test_png_rgb(tmp_path, depth, interlace):
    k = 257 if depth == 16 else 1
    fg, bg = tuple(v * k for v in (200, 180, 255)), tuple(v * k for v in (10, 20, 0))
    img = map_img(rect_mask(), lambda v: fg if v else bg)
    check_rect(contour_of(tmp_path, png_bytes(img, 2, depth, interlace=interlace), "rgb.png"))


@pytest.mark.png
def test_png_rgb_luminance(tmp_path):
    # pure blue has luminance 29 (< 127): a blue decoy region must be background
    img = map_img(rect_mask(), lambda v: (255, 255, 255) if v else (0, 0, 0))
    fill_rect(img, 30, 0, 39, 29, (0, 0, 255))
    check_rect(contour_of(tmp_path, png_bytes(img, 2, 8), "rgbl.png"))


@pytest.mark.png
@pytest.mark.parametrize("depth", [8, 16])
@pytest.mark.parametrize("interlace", [False, True])
def test_png_rgba(tmp_path, depth, interlace):
    top = (1 << depth) - 1
    img = map_img(rect_mask(), lambda v: (0, 0, 0, top if v else 0))
    check_rect(contour_of(tmp_path, png_bytes(img, 6, depth, interlace=interlace), "rgba.png"))


@pytest.mark.png
@pytest.mark.parametrize("tones", [((0, 0, 0), (90, 90, 90)), ((200, 220, 210), (255, 255, 255))])
def test_png_rgba_two_tone_on_transparent(tmp_path, tones):
    # not a uniform colour: composited over a background that contrasts with the shape
    a, b = tones
    img = [[(0, 0, 0, 0)] * 40 for _ in range(30)]
    x0, y0, x1, y1 = RECT
    for y in range(y0, y1 + 1):
        for x in range(x0, x1 + 1):
            img[y][x] = (a if x < 15 else b) + (255,)
    check_rect(contour_of(tmp_path, png_bytes(img, 6, 8), "two.png"))


@pytest.mark.png
@pytest.mark.parametrize("color_type", [4, 6])
def test_png_alpha_antialiased_edge_subpixel(tmp_path, color_type):
    # a cut-out as editors export it: one colour, the silhouette in an antialiased alpha
    # channel. It is traced as the same coverage in grey levels (sub-pixel, column 20 at 30 %),
    # not as the alpha cut to a binary mask (the edge at 19.5 whatever the coverage)
    cover = fill_rect(fill_rect(blank(40, 30), 5, 5, 19, 24, 255), 20, 5, 20, 24, 77)
    grey = tmp_path / "grey.png"
    grey.write_bytes(png_bytes(cover, 0, 8))
    alpha = tmp_path / "alpha.png"
    alpha.write_bytes(png_bytes(map_img(cover, lambda a: (40, a) if color_type == 4 else (200, 40, 10, a)),
                                color_type, 8))
    want, got = (run("contour", p) for p in (grey, alpha))
    assert want.returncode == 0 and got.returncode == 0, got.stderr
    assert read_points(got.stdout) == read_points(want.stdout)
    assert abs(max(x for x, y in read_points(got.stdout) if 8 <= y <= 20) - 19.8) < 0.09


@pytest.mark.png
@pytest.mark.parametrize("parts", ["halves", "outline"])
def test_png_rgba_light_and_dark_cutout_on_transparent(tmp_path, parts):
    # an object of dark and light parts cut out on a transparent background (a photo cut-out,
    # an icon with a dark outline and a light fill): the alpha is the silhouette, the object
    # stays whole (composited over one background, its light or its dark parts went with it)
    img = [[(0, 0, 0, 0)] * 40 for _ in range(30)]
    x0, y0, x1, y1 = RECT
    for y in range(y0, y1 + 1):
        for x in range(x0, x1 + 1):
            light = x >= 15 if parts == "halves" else x0 < x < x1 and y0 < y < y1
            img[y][x] = (240, 235, 250, 255) if light else (20, 10, 30, 255)
    check_rect(contour_of(tmp_path, png_bytes(img, 6, 8), "cut.png"))


@pytest.mark.png
def test_png_rgba_transparent_corners_of_a_picture(tmp_path):
    # transparency that is not the background (rounded-off corners of an opaque picture): the
    # picture is composited as before, its dark rectangle traced
    img = map_img(rect_mask(), lambda v: (10, 10, 10, 255) if v else (250, 250, 250, 255))
    for y, x in ((0, 0), (0, 39), (29, 0), (29, 39)):
        img[y][x] = (0, 0, 0, 0)
    check_rect(contour_of(tmp_path, png_bytes(img, 6, 8), "corners.png"))


@pytest.mark.png
def test_png_rgba_opaque_dark_shape(tmp_path):
    img = map_img(rect_mask(), lambda v: (0, 0, 0, 255) if v else (255, 255, 255, 255))
    check_rect(contour_of(tmp_path, png_bytes(img, 6, 8), "rgbao.png"))


@pytest.mark.png
def test_png_rgb_trns(tmp_path):
    img = map_img(rect_mask(), lambda v: (30, 30, 30) if v else (20, 20, 20))
    check_rect(contour_of(tmp_path, png_bytes(img, 2, 8, trns=bytes([0, 20, 0, 20, 0, 20])), "rgbt.png"))


# ---------------------------------------------------------------------------- palette


@pytest.mark.png
@pytest.mark.parametrize("depth", [1, 2, 4, 8])
@pytest.mark.parametrize("interlace", [False, True])
def test_png_palette(tmp_path, depth, interlace):
    pal = [(0, 0, 0), (250, 240, 230)]
    if depth > 1:
        pal += [(40, 40, 40)]  # a dark decoy index
    img = rect_mask(fg=1, bg=0)
    if depth > 1:
        fill_rect(img, 30, 0, 39, 29, 2)
    check_rect(contour_of(tmp_path, png_bytes(img, 3, depth, palette=pal, interlace=interlace), "pal.png"))


@pytest.mark.png
def test_png_palette_trns(tmp_path):
    pal = [(255, 255, 255), (255, 255, 255)]
    img = rect_mask(fg=1, bg=0)
    check_rect(contour_of(tmp_path, png_bytes(img, 3, 8, palette=pal, trns=bytes([0, 255])), "palt.png"))


@pytest.mark.png
def test_png_odd_size_interlaced(tmp_path):
    # sizes that leave some Adam7 passes empty or partial
    img = rect_mask(w=9, h=5, rect=(2, 1, 6, 3), fg=255)
    check_rect(contour_of(tmp_path, png_bytes(img, 0, 8, interlace=True), "odd.png"), (2, 1, 6, 3))


@pytest.mark.png
def test_png_ancillary_chunks_ignored(tmp_path):
    img = rect_mask(fg=255)
    data = png_bytes(img, 0, 8, extra_chunks=[(b"tEXt", b"Comment\x00hello"), (b"gAMA", b"\x00\x00\xb1\x8f")])
    check_rect(contour_of(tmp_path, data, "anc.png"))


@pytest.mark.png
def test_format_by_magic_not_extension(tmp_path):
    img = rect_mask(fg=255)
    check_rect(contour_of(tmp_path, png_bytes(img, 0, 8), "really_a_png.txt"))
    check_rect(contour_of(tmp_path, pgm_bytes(img), "really_a_pgm.png"))


# ---------------------------------------------------------------------------- PGM


@pytest.mark.parametrize("ascii", [False, True])
@pytest.mark.parametrize("comments", [False, True])
@pytest.mark.parametrize("maxval", [1, 255, 1000, 65535])
def test_pgm(tmp_path, ascii, comments, maxval):
    img = rect_mask(fg=maxval, bg=0)
    check_rect(contour_of(tmp_path, pgm_bytes(img, maxval, ascii, comments), "i.pgm"))


@pytest.mark.parametrize("ascii", [False, True])
def test_pgm16_scaling(tmp_path, ascii):
    # maxval 1000: 600 -> 153 (shape), 400 -> 102 (background)
    img = blank(40, 30, 0)
    fill_rect(img, 0, 0, 39, 3, 400)
    fill_rect(img, *RECT, 600)
    check_rect(contour_of(tmp_path, pgm_bytes(img, 1000, ascii), "s.pgm"))


def test_pgm_comment_after_maxval(tmp_path):
    img = rect_mask(fg=255)
    data = b"P5 40 30 255#comment right after maxval\n" + b"".join(bytes(r) for r in img)
    check_rect(contour_of(tmp_path, data, "c.pgm"))


def test_text_point_list_passthrough(tmp_path):
    p = tmp_path / "pts.csv"
    p.write_text("# a square\n0,0\n10,0\n10,10\n0,10\n")
    r = run("contour", p)
    assert r.returncode == 0, r.stderr
    assert read_points(r.stdout) == [(0, 0), (10, 0), (10, 10), (0, 10)]


def test_contour_output_file(tmp_path):
    img = tmp_path / "r.pgm"
    img.write_bytes(pgm_bytes(rect_mask(fg=255)))
    out = tmp_path / "out.txt"
    r = run("contour", img, "-o", out, "--pixel-chain")
    assert r.returncode == 0, r.stderr
    assert r.stdout == ""
    check_rect(read_points(out.read_text()))
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out.txt", "r.pgm"]


def test_threshold_option(tmp_path):
    img = tmp_path / "dim.pgm"
    img.write_bytes(pgm_bytes(rect_mask(fg=100, bg=0)))
    r = run("contour", img)  # default 127: nothing is on
    assert r.returncode == 1
    assert "dim.pgm" in r.stderr
    assert "the brightest is 100 of 255" in r.stderr and "--threshold below 100" in r.stderr  # what to set
    check_rect(read_points(run("contour", img, "--threshold", "50", "--pixel-chain").stdout))
    check_rect(read_points(run("contour", img, "--threshold=auto", "--pixel-chain").stdout))
    r = run("contour", img, "--all")  # every contour: the same message
    assert r.returncode == 1 and "the brightest is 100" in r.stderr


@pytest.mark.parametrize("maxval", [255, 65535])
@pytest.mark.parametrize("fg,bg", [(1, 0), (0, 1)])
def test_zero_one_mask_by_default(tmp_path, maxval, fg, bg):
    # an image whose samples are all 0 or 1 (NumPy's mask.astype(np.uint8), label images) is a
    # 0/1 mask by default: traced at 0.5, either polarity, at 8 and 16 bits
    img = tmp_path / "m01.pgm"
    img.write_bytes(pgm_bytes(rect_mask(fg=fg, bg=bg), maxval=maxval))
    check_rect(contour_of(tmp_path, img.read_bytes(), "m01.pgm"))
    r = run("contour", img, "--threshold", "127")  # asked for: nothing is above it
    assert r.returncode == 1 and "the brightest is 1 of %d" % maxval in r.stderr
    assert ("--threshold below 1," if maxval == 255 else "use --threshold auto") in r.stderr
    ones = tmp_path / "ones.pgm"
    ones.write_bytes(pgm_bytes(blank(10, 10, 1), maxval=maxval))
    r = run("contour", ones)
    assert r.returncode == 1 and "foreground everywhere" in r.stderr
