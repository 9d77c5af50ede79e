"""Contour tracing through the tool on synthetic masks: holes, specks, several components,
border contact, inverted polarity, orientation, no repeated points."""
import pytest

from imgutil import blank, extremes, fill_rect, image_bytes, img_ext, read_points, run, signed_area


def trace(tmp_path, img, name=None, *extra):
    """The chain of boundary pixel centres (--pixel-chain; the default iso-line is tested by the
    sub-pixel tests at the end)."""
    name = name or "m" + img_ext()
    p = tmp_path / name
    p.write_bytes(image_bytes(img, name))
    r = run("contour", p, "--pixel-chain", *extra)
    assert r.returncode == 0, r.stderr
    pts = read_points(r.stdout)
    assert len(pts) >= 3
    assert signed_area(pts) > 0  # counter-clockwise, y up (header convention)
    # no repeated consecutive point, no closing duplicate (a pixel on a one-pixel-wide
    # part is visited twice by the boundary walk, legitimately)
    assert all(pts[i] != pts[(i + 1) % len(pts)] for i in range(len(pts)))
    # 8-connected chain of boundary pixel centres
    for i in range(len(pts)):
        (x0, y0), (x1, y1) = pts[i], pts[(i + 1) % len(pts)]
        assert max(abs(x1 - x0), abs(y1 - y0)) == 1, (pts[i], pts[(i + 1) % len(pts)])
    return pts


def on_rect_boundary(pts, rect):
    x0, y0, x1, y1 = rect
    return all(x in (x0, x1) or y in (y0, y1) for x, y in pts)


def test_hole_ignored(tmp_path):
    img = fill_rect(blank(50, 40), 5, 5, 40, 30, 255)
    fill_rect(img, 15, 12, 30, 22, 0)  # a hole
    pts = trace(tmp_path, img)
    assert extremes(pts) == (5, 5, 40, 30)
    assert on_rect_boundary(pts, (5, 5, 40, 30))
    assert len(pts) == 2 * 36 + 2 * 26 - 4


def test_pinholes_ignored(tmp_path):
    img = fill_rect(blank(50, 40), 5, 5, 40, 30, 255)
    for x, y in [(10, 10), (20, 25), (35, 6)]:
        img[y][x] = 0
    pts = trace(tmp_path, img)
    assert on_rect_boundary(pts, (5, 5, 40, 30))


def test_specks_and_smaller_components_dropped(tmp_path):
    img = fill_rect(blank(60, 50), 20, 15, 50, 40, 255)  # the largest component
    img[2][2] = 255  # single-pixel speck
    fill_rect(img, 5, 44, 6, 45, 255)  # 2x2 speck
    fill_rect(img, 2, 10, 12, 30, 255)  # a smaller component
    pts = trace(tmp_path, img)
    assert extremes(pts) == (20, 15, 50, 40)


def test_diagonal_neighbours_connect(tmp_path):
    # two blocks touching only at a corner are one 8-connected component
    img = blank(40, 40)
    fill_rect(img, 5, 5, 14, 14, 255)
    fill_rect(img, 15, 15, 24, 24, 255)
    fill_rect(img, 30, 2, 37, 8, 255)  # a smaller separate block
    pts = trace(tmp_path, img)
    assert extremes(pts) == (5, 5, 24, 24)


@pytest.mark.parametrize("rect", [(0, 0, 20, 15), (10, 8, 39, 29), (0, 5, 39, 20), (0, 0, 39, 12)])
def test_border_contact(tmp_path, rect):
    img = fill_rect(blank(40, 30), *rect, 255)
    pts = trace(tmp_path, img)
    assert extremes(pts) == tuple(float(v) for v in rect)


def test_inverted_polarity(tmp_path):
    img = fill_rect(blank(40, 30, 255), 8, 6, 30, 22, 0)  # dark shape on a light background
    pts = trace(tmp_path, img, "inv.pgm")
    assert extremes(pts) == (8, 6, 30, 22)


def test_ring_outer_boundary(tmp_path):
    import math
    img = blank(61, 61)
    for y in range(61):
        for x in range(61):
            r = math.hypot(x - 30, y - 30)
            if 12 <= r <= 25:
                img[y][x] = 255
    pts = trace(tmp_path, img)
    assert extremes(pts) == (5, 5, 55, 55)
    assert min(math.hypot(x - 30, y - 30) for x, y in pts) > 20  # the inner boundary is not traced


def test_thin_structures(tmp_path):
    # a one-pixel-wide line attached to a block: traced around (both sides of the line)
    img = fill_rect(blank(40, 30), 5, 5, 15, 15, 255)
    fill_rect(img, 16, 10, 35, 10, 255)
    pts = trace(tmp_path, img)
    assert extremes(pts) == (5, 5, 35, 15)


def test_single_pixel_rejected_cleanly(tmp_path):
    img = blank(20, 20)
    img[10][10] = 255
    p = tmp_path / "dot.pgm"
    p.write_bytes(image_bytes(img, "dot.pgm"))
    r = run("contour", p, "--pixel-chain")
    assert r.returncode == 1
    assert len(r.stderr.splitlines()) == 1 and "dot.pgm" in r.stderr


# ------------------------------------------------------------------ sub-pixel (the default)
def subpixel(tmp_path, data, name, *extra):
    p = tmp_path / name
    p.write_bytes(data)
    r = run("contour", p, *extra)
    assert r.returncode == 0, r.stderr
    pts = read_points(r.stdout)
    assert signed_area(pts) > 0
    assert all(pts[i] != pts[(i + 1) % len(pts)] for i in range(len(pts)))
    return pts


def test_subpixel_binary_edges_between_pixel_centres(tmp_path):
    img = fill_rect(blank(50, 40), 5, 5, 40, 30, 255)
    pts = subpixel(tmp_path, image_bytes(img, "r" + img_ext()), "r" + img_ext())
    assert extremes(pts) == (4.5, 4.5, 40.5, 30.5)
    assert signed_area(pts) == 36 * 26 - 0.5  # four corners cut by 1/8 each
    chain = trace(tmp_path, img)
    assert extremes(chain) == (5, 5, 40, 30)


def test_subpixel_single_pixel_is_a_diamond(tmp_path):
    img = blank(20, 20)
    img[10][10] = 255
    pts = subpixel(tmp_path, image_bytes(img, "dot.pgm"), "dot.pgm")
    assert sorted(pts) == [(9.5, 10.0), (10.0, 9.5), (10.0, 10.5), (10.5, 10.0)]


def _grey_step(v):
    """Columns 5..19 full, column 20 at v, the rest 0 (16-bit values), rows 5..24."""
    img = blank(40, 30)
    fill_rect(img, 5, 5, 19, 24, 65535)
    fill_rect(img, 20, 5, 20, 24, v)
    return img


@pytest.mark.parametrize("fmt", ["png", "pgm"])
def test_subpixel_keeps_16_bits(tmp_path, fmt):
    # column 20 at 32800: just above the level (127 + 0.5) * 257 = 32767.5; the edge lies at
    # 20 + 32.5 / 32800 (8 bits would round the value to 128 and put it at 20 + 0.5 / 128)
    img = _grey_step(32800)
    if fmt == "png":
        from imgutil import have_png, png_bytes
        if not have_png():
            pytest.skip("tool built without libpng")
        data = png_bytes(img, 0, 16)
    else:
        from imgutil import pgm_bytes
        data = pgm_bytes(img, 65535)
    pts = subpixel(tmp_path, data, "g16." + fmt)
    right = max(x for x, y in pts if 8 <= y <= 20)
    assert abs(right - (20 + 32.5 / 32800)) < 1e-9, right
    chain = read_points(run("contour", tmp_path / ("g16." + fmt), "--pixel-chain").stdout)
    assert max(x for x, _ in chain) == 20


def test_subpixel_antialiased_edge(tmp_path):
    # column 20 covered 30 % (77 of 255): the iso-line at 127.5 is interpolated between
    # column 19 (255) and column 20 (77); linear interpolation of a box-filtered edge is off by
    # c (0.5 - c) / (1 - c) <= 0.09 px (c: the coverage), here 0.086 of the true 19.5 + 0.3
    img = blank(40, 30)
    fill_rect(img, 5, 5, 19, 24, 255)
    fill_rect(img, 20, 5, 20, 24, 77)
    pts = subpixel(tmp_path, image_bytes(img, "aa.pgm"), "aa.pgm")
    right = max(x for x, y in pts if 8 <= y <= 20)
    assert abs(right - (19 + (255 - 127.5) / (255 - 77))) < 1e-9
    assert abs(right - 19.8) < 0.09
    fill_rect(img, 20, 5, 20, 24, 128)  # half covered: exact
    pts = subpixel(tmp_path, image_bytes(img, "ab.pgm"), "ab.pgm")
    assert abs(max(x for x, y in pts if 8 <= y <= 20) - 20.0) < 0.01


def test_pixel_chain_option_everywhere(tmp_path):
    img = fill_rect(blank(50, 40), 5, 5, 40, 30, 255)
    p = tmp_path / ("r" + img_ext())
    p.write_bytes(image_bytes(img, p.name))
    for cmd in (("contour", p), ("register", p, p)):
        r = run(*cmd, "--pixel-chain")
        assert r.returncode == 0, r.stderr


def test_contour_join(tmp_path):
    """`contour --join` traces the outline the retrieval commands and `register` use: a piece
    broken off by a 2-pixel gap is joined to the largest component (its area counts, by zero-width
    bridges), a shape in one piece is traced as without it, and --join with --all or
    --pixel-chain is a usage error."""
    def write(name, *rects):
        img = blank(110, 80)
        for x0, y0, x1, y1 in rects:
            fill_rect(img, x0, y0, x1, y1, 255)
        p = tmp_path / (name + img_ext())
        p.write_bytes(image_bytes(img, p.name))
        return p
    broken = write("broken", (10, 20, 70, 50), (72, 28, 95, 42))
    body = write("body", (10, 20, 70, 50))
    area = {}
    for name, p, extra in (("body", body, ()), ("largest", broken, ()), ("joined", broken, ("--join",)),
                           ("body joined", body, ("--join",))):
        r = run("contour", p, *extra)
        assert r.returncode == 0, r.stderr
        area[name] = signed_area(read_points(r.stdout))
    assert area["largest"] == pytest.approx(area["body"])  # the piece dropped
    assert area["body joined"] == pytest.approx(area["body"])  # nothing to join
    piece = (95 - 72 + 1) * (42 - 28 + 1)
    assert area["joined"] == pytest.approx(area["body"] + piece, rel=0.02)
    for extra in (("--all",), ("--pixel-chain",)):
        r = run("contour", broken, "--join", *extra)
        assert r.returncode == 2 and "--join" in r.stderr, (extra, r.stderr)
