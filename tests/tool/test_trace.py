"""Contour tracing through the tool on synthetic masks: holes, specks, several components,
border contact, inverted polarity, orientation, no repeated points."""
import pytest

from imgutil import blank, extremes, fill_rect, image_bytes, img_ext, read_points, run, signed_area


def trace(tmp_path, img, name=None, *extra):
    name = name or "m" + img_ext()
    p = tmp_path / name
    p.write_bytes(image_bytes(img, name))
    r = run("contour", p, *extra)
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
    r = run("contour", p)
    assert r.returncode == 1
    assert len(r.stderr.splitlines()) == 1 and "dot.pgm" in r.stderr
