"""End-to-end `amscr register`: the JSON recovers a known affine map; methods, options and
pictures; the bundled example pair."""
import json
import math
import os
import xml.etree.ElementTree as ET

import pytest

from imgutil import REPO, affine, have_png, image_bytes, img_ext, rasterize, run, smooth_shape, write_points

TRUE = ((1.3, 0.4, 15.0), (-0.2, 0.8, -7.0))  # shear + anisotropic scale, det > 0


def check_png(data):
    """A valid 8-bit RGB PNG: signature, chunk CRCs, IDAT inflates to the right size."""
    import struct
    import zlib
    assert data.startswith(b"\x89PNG\r\n\x1a\n")
    i, idat, kinds = 8, b"", []
    while i < len(data):
        n = struct.unpack(">I", data[i:i + 4])[0]
        kind, body = data[i + 4:i + 8], data[i + 8:i + 8 + n]
        assert struct.unpack(">I", data[i + 8 + n:i + 12 + n])[0] == zlib.crc32(kind + body) & 0xFFFFFFFF
        if kind == b"IHDR":
            w, h, depth, ctype = struct.unpack(">IIBB", body[:10])
        if kind == b"IDAT":
            idat += body
        kinds.append(kind)
        i += 12 + n
    assert kinds[0] == b"IHDR" and kinds[-1] == b"IEND"
    assert (depth, ctype) == (8, 2) and w > 100 and h > 100
    assert len(zlib.decompress(idat)) == h * (1 + 3 * w)


def rel_err_A(got, true):
    (a, b), (c, d) = got
    (ta, tb, _), (tc, td, _) = true
    num = math.sqrt((a - ta) ** 2 + (b - tb) ** 2 + (c - tc) ** 2 + (d - td) ** 2)
    return num / math.sqrt(ta * ta + tb * tb + tc * tc + td * td)


def size_of(pts):
    xs = [p[0] for p in pts]
    ys = [p[1] for p in pts]
    return max(max(xs) - min(xs), max(ys) - min(ys))


@pytest.fixture
def pair(tmp_path):
    src = smooth_shape(300)
    tgt = affine(TRUE, src)
    # start the target at another point (the start-point search must find it)
    tgt = tgt[77:] + tgt[:77]
    s, t = tmp_path / "src.txt", tmp_path / "tgt.txt"
    write_points(s, src)
    write_points(t, tgt)
    return s, t, size_of(tgt)


def register_json(*args):
    r = run("register", *args, "--json")
    assert r.returncode == 0, r.stderr
    assert r.stderr == ""
    lines = r.stdout.strip().splitlines()
    assert len(lines) == 1  # exactly one JSON object
    return json.loads(lines[0])


def test_recovers_known_affine_map(pair):
    s, t, size = pair
    j = register_json(s, t)
    assert rel_err_A(j["A"], TRUE) < 1e-3, j["A"]
    assert abs(j["B"][0] - TRUE[0][2]) < 1e-2 * size and abs(j["B"][1] - TRUE[1][2]) < 1e-2 * size, j["B"]
    assert j["distance"] < 1e-6
    assert j["reflected"] is False
    assert j["method"] == "multiclass-em"
    assert len(j["residuals"]) == len(j["scales"])
    assert set(j["kept"]) <= set(j["scales"]) and len(j["kept"]) >= 1
    assert isinstance(j["shift"], int) and 0 <= j["shift"] < j["samples"]
    for key in ["k", "threshold", "sse", "mixture", "samples", "source_points", "target_points"]:
        assert key in j


@pytest.mark.parametrize("method", ["acma", "amscr", "binary-em", "multiclass-em"])
def test_methods(pair, method):
    s, t, size = pair
    j = register_json(s, t, "--method", method, "--points", "64")
    assert j["method"] == method
    assert j["samples"] == 64
    assert rel_err_A(j["A"], TRUE) < 1e-3


def test_options(pair):
    s, t, _ = pair
    j = register_json(s, t, "--scales", "0,1,2,4,8", "--refine", "2", "--threads", "1", "--kmax", "3")
    assert j["scales"] == [0, 1, 2, 4, 8]
    assert len(j["residuals"]) == 5
    assert rel_err_A(j["A"], TRUE) < 1e-3


def test_inverse_direction(pair):
    s, t, _ = pair
    j = register_json(t, s)
    (a, b), (c, d) = j["A"]
    (ta, tb, _), (tc, td, _) = TRUE
    # A * TRUE_A = I
    prod = [[a * ta + b * tc, a * tb + b * td], [c * ta + d * tc, c * tb + d * td]]
    assert all(abs(prod[i][k] - (i == k)) < 1e-3 for i in range(2) for k in range(2)), prod


def test_reflected_pair(tmp_path):
    src = smooth_shape(300, seed=1)
    mirror = ((-1.1, 0.2, 300.0), (0.1, 0.9, 20.0))  # det < 0
    s, t = tmp_path / "s.txt", tmp_path / "t.txt"
    write_points(s, src)
    write_points(t, affine(mirror, src))
    j = register_json(s, t, "--reflections")
    assert j["reflected"] is True
    assert rel_err_A(j["A"], mirror) < 1e-3, j["A"]
    assert j["distance"] < 1e-6
    j0 = register_json(s, t)  # reflections off (the default for register)
    assert j0["reflected"] is False
    assert j0["distance"] > j["distance"]


def test_open_curves(tmp_path):
    src = smooth_shape(300)[:180]  # an open arc
    tgt = affine(TRUE, src)
    s, t = tmp_path / "s.txt", tmp_path / "t.txt"
    write_points(s, src)
    write_points(t, tgt)
    j = register_json(s, t, "--open")
    assert j["closed"] is False
    assert rel_err_A(j["A"], TRUE) < 1e-2, j["A"]


def test_human_output(pair):
    s, t, _ = pair
    r = run("register", s, t)
    assert r.returncode == 0, r.stderr
    for word in ["distance", "A ", "B ", "method", "kept", "shift", "reflected", "threshold"]:
        assert word in r.stdout


def test_human_output_keeps_b_far_from_the_origin(tmp_path):
    """Far from the origin the text report gives B as many digits as the map needs to stay within a
    millionth of the target's size (6 significant digits moved it by whole units); near the origin
    it keeps 6, as --json keeps 17."""
    src = smooth_shape(300)
    tgt = affine(TRUE, src)
    for off, want_digits in ((0.0, 6), (6.5e6, 13)):
        s, t = tmp_path / "s.txt", tmp_path / "t.txt"
        write_points(s, [(x + off, y + 0.3 * off) for x, y in src])
        write_points(t, [(x + off, y - 0.2 * off) for x, y in tgt])
        r = run("register", s, t)
        assert r.returncode == 0, r.stderr
        line = [ln for ln in r.stdout.splitlines() if ln.startswith("B ")][0]
        b = [float(v) for v in line.split("[")[1].split("]")[0].split()]
        js = register_json(s, t)["B"]
        size = size_of(tgt)
        assert all(abs(x - y) <= 1e-6 * size for x, y in zip(b, js)), (line, js)
        digits = len(line.split("[")[1].split()[0].replace("-", "").replace(".", "").lstrip("0"))
        assert digits <= want_digits, line


@pytest.mark.parametrize("ext", [".png", ".svg", ".PNG"])
def test_overlay_and_plot(pair, tmp_path, ext):
    s, t, _ = pair
    ov, pl = tmp_path / ("overlay" + ext), tmp_path / "plot.svg"
    r = run("register", s, t, "--overlay", ov, "--plot", pl)
    assert r.returncode == 0, r.stderr
    data = ov.read_bytes()
    if ext.lower() == ".png":
        check_png(data)
    else:
        assert b"<svg" in data and b"source registered" in data
        ET.fromstring(data)  # well-formed XML
    svg = pl.read_text()
    ET.fromstring(svg)
    assert svg.count("<svg") == 1 and "Residual per scale" in svg and "Elbow" in svg
    # no temporary files left next to the outputs
    assert not [n for n in os.listdir(tmp_path) if n.startswith(".")]


def test_overlay_open_png(tmp_path):
    src = smooth_shape(200)[:120]
    s, t = tmp_path / "s.txt", tmp_path / "t.txt"
    write_points(s, src)
    write_points(t, affine(TRUE, src))
    r = run("register", s, t, "--open", "--overlay", tmp_path / "o.png", "--method", "acma", "--plot",
            tmp_path / "p.svg")
    assert r.returncode == 0, r.stderr
    assert "no elbow" in (tmp_path / "p.svg").read_text()


def test_partial_reports_no_scale_selection(tmp_path):
    """--partial: the report says how the fragment was placed, not scale-selection figures the
    partial match does not compute; the overlay draws the fragment open; no plot."""
    src = smooth_shape(300)
    frag = src[40:220]
    s, t = tmp_path / "frag.txt", tmp_path / "whole.txt"
    write_points(s, frag)
    write_points(t, affine(TRUE, src))
    r = run("register", s, t, "--partial", "--overlay", tmp_path / "o.svg")
    assert r.returncode == 0, r.stderr
    assert "method      partial" in r.stdout and "part " in r.stdout
    for absent in ("kept ", "residuals", "threshold", "shift"):
        assert absent not in r.stdout, r.stdout
    svg = (tmp_path / "o.svg").read_text()
    assert svg.count("<polyline") == 2 and svg.count("<polygon") == 1  # before, after open; the target
    j = register_json(s, t, "--partial")
    assert j["partial"] is True and j["residuals"] is None and j["kept"] == [] and j["threshold"] is None
    assert rel_err_A(j["A"], TRUE) < 1e-2
    r = run("register", s, t, "--partial", "--plot", tmp_path / "p.svg")
    assert r.returncode == 2 and "--plot" in r.stderr and not (tmp_path / "p.svg").exists()


def test_outputs_checked_before_any_is_written(pair, tmp_path):
    """A picture that cannot be written fails the run before the other is written; an output
    that names an input is refused, the input left as it was."""
    s, t, _ = pair
    ov = tmp_path / "ov.svg"
    r = run("register", s, t, "--overlay", ov, "--plot", tmp_path / "no" / "p.svg")
    assert r.returncode == 1 and "p.svg" in r.stderr and not ov.exists() and r.stdout == ""
    before = s.read_bytes()
    r = run("register", s, t, "--overlay", tmp_path / "." / "src.svg")  # a new file: fine
    assert r.returncode == 0, r.stderr
    sv = tmp_path / "src.svg"
    r = run("register", sv, t, "--overlay", sv)  # the source itself
    assert r.returncode == 1 and "would overwrite an input" in r.stderr
    r = run("contour", s, "-o", s)
    assert r.returncode == 1 and "would overwrite an input" in r.stderr and s.read_bytes() == before


def test_image_pair(tmp_path):
    # the smooth shape, rasterized, and its affine image: the map is recovered approximately
    src = [(x + 100, y + 100) for x, y in smooth_shape(400)]
    m = ((0.8, 0.3, 20.0), (-0.15, 0.7, 40.0))
    a, b = tmp_path / ("a" + img_ext()), tmp_path / ("b" + img_ext())
    a.write_bytes(image_bytes(rasterize(src, 200, 200), a.name))
    b.write_bytes(image_bytes(rasterize(affine(m, src), 200, 200), b.name))
    j = register_json(a, b)
    assert rel_err_A(j["A"], m) < 0.03, j["A"]
    assert abs(j["B"][0] - 20) < 3 and abs(j["B"][1] - 40) < 3, j["B"]


def test_bundled_example_pair():
    ex = os.path.join(REPO, "examples")
    if not os.path.exists(os.path.join(ex, "pair-source.txt")):
        pytest.skip("examples/ not generated")
    j = register_json(os.path.join(ex, "pair-source.txt"), os.path.join(ex, "pair-target.txt"))
    true = ((0.75, 0.35, -15.7), (-0.2, 0.65, 46.6))  # examples/README.md
    assert rel_err_A(j["A"], true) < 1e-3
    assert abs(j["B"][0] + 15.7) < 0.1 and abs(j["B"][1] - 46.6) < 0.1
    if have_png():
        j = register_json(os.path.join(ex, "pair-source.png"), os.path.join(ex, "pair-target.png"))
        assert rel_err_A(j["A"], true) < 0.05


def test_odd_file_names(tmp_path):
    src = smooth_shape(120)
    s, t = tmp_path / 'a&b <"q">\t.txt', tmp_path / "é ü\\x.txt"
    write_points(s, src)
    write_points(t, affine(TRUE, src))
    ov, pl = tmp_path / "o.svg", tmp_path / "p.svg"
    j = register_json(s, t, "--overlay", ov, "--plot", pl)
    assert j["source"] == str(s) and j["target"] == str(t)
    ET.fromstring(ov.read_bytes())
    ET.fromstring(pl.read_bytes())


def test_register_joins_the_pieces_of_a_cut_target(tmp_path):
    """A target an occluder cut in two (a T whose bar is severed): register joins the pieces to
    the largest one's outline and recovers the shift; `contour` still traces the largest only."""
    from imgutil import blank, fill_rect
    whole = fill_rect(fill_rect(blank(100, 60), 10, 20, 79, 31, 255), 70, 14, 79, 37, 255)
    cut = fill_rect(fill_rect(blank(100, 60), 15, 23, 84, 34, 255), 75, 17, 84, 40, 255)
    fill_rect(cut, 43, 0, 48, 59, 0)
    src, tgt = tmp_path / ("whole" + img_ext()), tmp_path / ("cut" + img_ext())
    src.write_bytes(image_bytes(whole, src.name))
    tgt.write_bytes(image_bytes(cut, tgt.name))
    r = run("register", src, tgt, "--json")
    assert r.returncode == 0, r.stderr
    j = json.loads(r.stdout)
    assert rel_err_A(j["A"], ((1, 0, 5), (0, 1, 3))) < 0.02
    assert abs(j["B"][0] - 5) < 0.3 and abs(j["B"][1] - 3) < 0.3
    out = tmp_path / "c.txt"
    assert run("contour", tgt, "-o", out).returncode == 0
    xs = [float(l.split()[0]) for l in out.read_text().splitlines() if l and not l.startswith("#")]
    assert min(xs) > 45  # the largest piece alone
