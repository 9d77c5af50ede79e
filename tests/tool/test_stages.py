"""`amscr register`: the pipeline's stages in --json ("stages", name -> ran, in pipeline order),
--stage NAME=on|off, and the distinct maps that fit about as well ("alternatives") of symmetric
shapes against an asymmetric one."""
import json
import math

from imgutil import run, write_points

PIPELINE = ["despike", "search", "method", "recovery", "final_solve", "symmetric", "polish", "order",
            "even_spacing", "alternatives", "correspondences", "pixel_grid"]
MAP = ((1.3, 0.4, 15.0), (-0.2, 0.8, -7.0))


def outline(vertices, per_edge):
    pts = []
    for i, (x0, y0) in enumerate(vertices):
        x1, y1 = vertices[(i + 1) % len(vertices)]
        pts += [(x0 + (x1 - x0) * k / per_edge, y0 + (y1 - y0) * k / per_edge) for k in range(per_edge)]
    return pts


def mapped(pts, m=MAP):
    (a, b, tx), (c, d, ty) = m
    return [(a * x + b * y + tx, c * x + d * y + ty) for x, y in pts]


def register_json(tmp_path, src, tgt, *args):
    s, t = tmp_path / "src.txt", tmp_path / "tgt.txt"
    write_points(s, src)
    write_points(t, tgt)
    r = run("register", s, t, "--json", *args)
    assert r.returncode == 0, r.stderr
    return json.loads(r.stdout)


SQUARE = [(0, 0), (100, 0), (100, 100), (0, 100)]
CROSS = [(100, 0), (200, 0), (200, 100), (300, 100), (300, 200), (200, 200), (200, 300), (100, 300), (100, 200),
         (0, 200), (0, 100), (100, 100)]
TRIANGLE = [(0, 0), (100, 0), (50, 86.60254037844386)]
ELL = [(0, 0), (300, 0), (300, 100), (100, 100), (100, 250), (0, 250)]


def test_stages_in_pipeline_order(tmp_path):
    src = outline(ELL, 50)
    j = register_json(tmp_path, src, mapped(src))
    assert list(j["stages"]) == PIPELINE
    assert all(isinstance(v, bool) for v in j["stages"].values())
    for name in ("search", "method", "final_solve", "polish", "alternatives", "correspondences"):
        assert j["stages"][name], name
    assert not j["stages"]["symmetric"] and not j["stages"]["recovery"]


def test_stage_switch(tmp_path):
    src = outline(ELL, 50)
    on = register_json(tmp_path, src, mapped(src))
    off = register_json(tmp_path, src, mapped(src), "--stage", "polish=off", "--stage", "despike=on")
    assert on["stages"]["polish"] and not off["stages"]["polish"]
    assert off["stages"]["despike"]
    assert (on["A"], on["B"]) != (off["A"], off["B"])
    no_polish = register_json(tmp_path, src, mapped(src), "--no-polish")
    assert not no_polish["stages"]["polish"]


def test_stage_switch_refused(tmp_path):
    s = tmp_path / "s.txt"
    write_points(s, outline(ELL, 20))
    for bad in ("search=off", "nonsense=on", "polish", "polish=maybe", "=on"):
        r = run("register", s, s, "--stage", bad)
        assert r.returncode == 2, (bad, r.returncode, r.stderr)
        assert "--stage" in r.stderr and r.stdout == "", bad


def vertex_gap(m, vertices, targets):
    """Largest distance from a vertex mapped by alternative m to the nearest target vertex."""
    (a, b), (c, d) = m["A"]
    tx, ty = m["B"]
    worst = 0.0
    for x, y in vertices:
        u, v = a * x + b * y + tx, c * x + d * y + ty
        worst = max(worst, min(math.hypot(u - p, v - q) for p, q in targets))
    return worst


def test_symmetric_shapes_list_alternatives(tmp_path):
    for name, poly, count in (("square", SQUARE, 4), ("cross", CROSS, 4), ("triangle", TRIANGLE, 3)):
        src = outline(poly, 480 // len(poly))
        j = register_json(tmp_path, src, mapped(src))
        alts = j["alternatives"]
        assert len(alts) == count, (name, len(alts))  # each symmetry once
        assert j["confidence"] <= 0.25 and j["ambiguity"] >= 0.75, name
        assert (alts[0]["A"], alts[0]["B"]) == (j["A"], j["B"])  # the chosen map first
        targets = mapped(poly)
        for i, m in enumerate(alts):
            assert set(m) == {"A", "B", "cost"}
            assert vertex_gap(m, poly, targets) < 1.0, (name, i)  # each a symmetry of the shape
            assert (alts[0]["cost"] + 1e-9) / (m["cost"] + 1e-9) >= 0.75, (name, i)
        maps = {(round(m["A"][0][0], 2), round(m["A"][0][1], 2), round(m["B"][0])) for m in alts}
        assert len(maps) == len(alts), name  # distinct


def test_asymmetric_shape_lists_the_chosen_map_only(tmp_path):
    src = outline(ELL, 50)
    j = register_json(tmp_path, src, mapped(src))
    assert len(j["alternatives"]) == 1
    assert (j["alternatives"][0]["A"], j["alternatives"][0]["B"]) == (j["A"], j["B"])
    assert j["confidence"] > 0.9


def test_text_output_names_the_stages_and_alternatives(tmp_path):
    s, t = tmp_path / "s.txt", tmp_path / "t.txt"
    src = outline(SQUARE, 100)
    write_points(s, src)
    write_points(t, mapped(src))
    r = run("register", s, t)
    assert r.returncode == 0, r.stderr
    lines = {ln.split()[0]: ln for ln in r.stdout.splitlines() if ln.strip()}
    assert "search method" in lines["stages"] and "alternatives" in lines
