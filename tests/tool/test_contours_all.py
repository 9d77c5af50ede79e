"""`amscr contour --all` (every component and hole with its parent, text and JSON) and the
`--component N` of register and search. The exact areas and points below are those of the
chain of pixel centres (--pixel-chain); the default sub-pixel contours are checked at the end."""
import json

import pytest

from imgutil import blank, fill_rect, pgm_bytes, run, run_peak_memory, write_points
from test_collection import AFFINE
from test_protocols import make_manifest


@pytest.fixture
def nested(tmp_path):
    """A square ring with a blob in its hole, and a small separate square (4 x 4 pixels)."""
    img = blank(50, 40, 0)
    fill_rect(img, 4, 4, 35, 35, 255)
    fill_rect(img, 10, 10, 29, 29, 0)
    fill_rect(img, 15, 15, 24, 24, 255)
    fill_rect(img, 42, 5, 45, 8, 255)
    p = tmp_path / "nested.pgm"
    p.write_bytes(pgm_bytes(img))
    return p


def test_all_json_hierarchy(nested):
    r = run("contour", nested, "--all", "--json", "--min-area", "0", "--pixel-chain")
    assert r.returncode == 0, r.stderr
    j = json.loads(r.stdout)
    got = [(c["index"], c["parent"], c["hole"], c["area"]) for c in j["contours"]]
    assert j["count"] == 4
    assert got == [(0, None, False, 961), (1, None, False, 9), (2, 0, True, 361), (3, 2, False, 81)]
    hole = j["contours"][2]["points"]
    assert all(10 <= x <= 29 and 10 <= y <= 29 for x, y in hole)  # through the hole's own pixels


def test_all_text_matches_json_and_min_area(nested, tmp_path):
    j = json.loads(run("contour", nested, "--all", "--json", "--pixel-chain").stdout)
    assert [c["area"] for c in j["contours"]] == [961, 361, 81]  # the default --min-area 10 drops the speck
    out = tmp_path / "all.txt"
    r = run("contour", nested, "--all", "-o", out, "--pixel-chain")
    assert r.returncode == 0 and r.stdout == ""
    blocks = out.read_text().strip().split("\n\n")
    assert len(blocks) == 3
    head = [b.splitlines()[0] for b in blocks]
    assert head == ["# contour 0: outer, parent -, area 961, 124 points",
                    "# contour 1: hole, parent 0, area 361, 76 points",
                    "# contour 2: outer, parent 1, area 81, 36 points"]
    for b, c in zip(blocks, j["contours"]):
        pts = [tuple(float(v) for v in line.split()) for line in b.splitlines()[1:]]
        assert pts == [tuple(p) for p in c["points"]]
    assert run("contour", nested, "--all", "--min-area", "400", "--pixel-chain").stdout.count("# contour") == 1


@pytest.mark.parametrize("args,code,msg", [
    (("--json",), 2, "only with --all"),
    (("--min-area", "5"), 2, "--min-area: only with --all"),  # it filters nothing else: ignored before 0.22.8
    (("--all", "--min-area", "-1"), 2, "--min-area"),
    (("--all", "--min-area", "x"), 2, "--min-area"),
    (("--all", "--min-area", "1e9"), 1, "no contour"),
])
def test_all_bad_input(nested, args, code, msg):
    r = run("contour", nested, *args)
    assert r.returncode == code and msg in r.stderr and r.stdout == ""


def test_min_area_needs_component_in_register(nested):
    r = run("register", nested, nested, "--min-area", "5")
    assert r.returncode == 2 and "--min-area: only with --component" in r.stderr and r.stdout == ""
    assert run("register", nested, nested, "--component", "0", "--min-area", "5").returncode == 0


def test_all_needs_an_image(tmp_path):
    p = tmp_path / "pts.txt"
    write_points(p, [(0, 0), (10, 0), (10, 10), (0, 10)])
    r = run("contour", p, "--all")
    assert r.returncode == 1 and "not an image" in r.stderr
    blank_img = tmp_path / "blank.pgm"
    blank_img.write_bytes(pgm_bytes(blank(10, 10, 0)))
    r = run("contour", blank_img, "--all")
    assert r.returncode == 1 and "no contour" in r.stderr


def test_register_component(nested):
    default = json.loads(run("register", nested, nested, "--json").stdout)
    first = json.loads(run("register", nested, nested, "--json", "--component", "0").stdout)
    assert default["distance"] == first["distance"] and default["A"] == first["A"]
    hole = run("register", nested, nested, "--json", "--component", "1", "--pixel-chain")
    assert hole.returncode == 0, hole.stderr
    assert json.loads(hole.stdout)["distance"] < 1e-6  # the hole onto itself
    r = run("register", nested, nested, "--component", "3", "--pixel-chain")
    assert r.returncode == 1 and "--component 3" in r.stderr and "0..2" in r.stderr


def test_search_component(nested, tmp_path):
    m = make_manifest(tmp_path)
    r = run("search", nested, m, "--component", "2", "--json", *AFFINE)
    assert r.returncode == 0, r.stderr
    assert len(json.loads(r.stdout)["results"]) == 9
    r = run("search", nested, m, "--component", "9", *AFFINE)
    assert r.returncode == 1 and "--component 9" in r.stderr


def test_all_subpixel_areas(nested):
    """The default iso-lines run halfway between foreground and background pixel centres: a
    square of n x n pixels encloses n^2 less its four cut corners (1/8 each)."""
    j = json.loads(run("contour", nested, "--all", "--json", "--min-area", "0").stdout)
    got = [(c["index"], c["parent"], c["hole"], c["area"]) for c in j["contours"]]
    assert got == [(0, None, False, 1023.5), (1, None, False, 15.5), (2, 0, True, 399.5), (3, 2, False, 99.5)]
    hole = j["contours"][2]["points"]
    assert min(x for x, _ in hole) == 9.5 and max(x for x, _ in hole) == 29.5  # between the pixels
    chain = json.loads(run("contour", nested, "--all", "--json", "--min-area", "0", "--pixel-chain").stdout)
    assert [c["parent"] for c in chain["contours"]] == [c["parent"] for c in j["contours"]]


def test_all_many_specks_memory(tmp_path):
    """40,000 specks of 2 x 2 pixels, each a contour of 8 points: the set holds their points, not
    a 256-point buffer each (4 KiB a contour: 160 MiB here, gigabytes for a large image)."""
    img = blank(600, 600, 0)
    for y in range(0, 600, 3):
        for x in range(0, 600, 3):
            img[y][x] = img[y][x + 1] = img[y + 1][x] = img[y + 1][x + 1] = 255
    p = tmp_path / "specks.pgm"
    p.write_bytes(pgm_bytes(img))
    code, err, peak_kib = run_peak_memory("contour", p, "--all", "--min-area", "0", "--json")
    assert code == 0, err
    assert peak_kib < 64 * 1024, f"{peak_kib / 1024:.0f} MiB"
