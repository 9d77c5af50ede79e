"""`amscr index` and an index wherever search, matrix and eval take a collection: the same
results as the folder or manifest, --add, options that conflict with the index's, and corrupt
or truncated index files."""
import json
import os

import pytest

from imgutil import affine, run, write_points
from test_collection import AFFINE, MAPS, base_shapes
from test_protocols import make_manifest


def build(tmp_path, manifest, *opts, name="shapes.idx"):
    out = tmp_path / name
    r = run("index", manifest, "-o", out, *opts)
    assert r.returncode == 0, r.stderr
    assert "9 shapes, 3 classes" in r.stdout or "shapes" in r.stdout
    return out


def same_results(a, b):
    """Every shape's distance agrees (the rows differ only by rounding: exact copies tie, so
    ranks within a tie may swap), and so do the classes rank by rank."""
    assert [r["class"] for r in a] == [r["class"] for r in b]
    da, db = {r["file"]: r["distance"] for r in a}, {r["file"]: r["distance"] for r in b}
    assert da.keys() == db.keys()
    for f in da:
        assert da[f] == pytest.approx(db[f], rel=1e-9, abs=1e-12)


@pytest.mark.parametrize("opts", [AFFINE, ("--invariance", "affine", "--refine", "0"),
                                  ("--refine", "0", "--rerank", "3,7")])
def test_search_index_equals_manifest(tmp_path, opts):
    m = make_manifest(tmp_path)
    idx = build(tmp_path, m, *opts)
    rerank = [o for o in opts if o.startswith("--no-rerank")] + (["--rerank", "3,7"] if "3,7" in opts else [])
    for q in ("star_2.txt", "blob_1.txt", "wave_3.txt"):
        qp = tmp_path / "shapes" / q
        a = json.loads(run("search", qp, idx, "--json", *rerank).stdout)
        b = json.loads(run("search", qp, m, "--json", *opts).stdout)
        same_results(a["results"], b["results"])


def test_matrix_and_eval_from_an_index(tmp_path):
    m = make_manifest(tmp_path)
    idx = build(tmp_path, m, *AFFINE)
    a = run("matrix", idx, "-o", "-", "--no-rerank").stdout
    b = run("matrix", m, "-o", "-", *AFFINE).stdout
    assert a.splitlines()[1:] == b.splitlines()[1:]
    ja = json.loads(run("eval", idx, "--json", "--protocol", "groups").stdout)
    jb = json.loads(run("eval", m, "--json", "--protocol", "groups", *AFFINE).stdout)
    assert ja["groups"] == jb["groups"] and ja["per_class"] == jb["per_class"]


def test_add_appends_without_changing_results(tmp_path):
    m = make_manifest(tmp_path)
    rows = m.read_text().splitlines()
    (tmp_path / "a.tsv").write_text("\n".join(rows[:5]) + "\n")
    (tmp_path / "b.tsv").write_text("\n".join([rows[0]] + rows[5:]) + "\n")
    whole = build(tmp_path, m, "--refine", "0", name="whole.idx")
    part = build(tmp_path, tmp_path / "a.tsv", "--refine", "0", name="part.idx")
    r = run("index", tmp_path / "b.tsv", "-o", part, "--add")
    assert r.returncode == 0 and "9 shapes" in r.stdout, r.stderr
    q = tmp_path / "shapes" / "star_3.txt"
    a = json.loads(run("search", q, part, "--json").stdout)["results"]
    b = json.loads(run("search", q, whole, "--json").stdout)["results"]
    same_results(a, b)
    # the same files again: refused, the index unchanged
    before = part.read_bytes()
    r = run("index", tmp_path / "b.tsv", "-o", part, "--add")
    assert r.returncode == 1 and "already in the index" in r.stderr and part.read_bytes() == before


@pytest.mark.parametrize("cmd,opt,msg", [
    ("search", ("--points", "64"), "built with --points 128"),
    ("eval", ("--invariance", "similarity"), "--invariance"),
    ("matrix", ("--no-reflections",), "reflections"),
    ("search", ("--rerank", "9"), "neighbours a shape"),
    ("index-add", ("--refine", "2"), "--refine"),
])
def test_options_that_conflict_with_the_index(tmp_path, cmd, opt, msg):
    m = make_manifest(tmp_path)
    idx = build(tmp_path, m, *AFFINE[:2], "--refine", "0", "--rerank", "3")
    q = tmp_path / "shapes" / "star_1.txt"
    args = {"search": ("search", q, idx), "eval": ("eval", idx), "matrix": ("matrix", idx, "-o", "-"),
            "index-add": ("index", m, "-o", idx, "--add")}[cmd]
    r = run(*args, *opt)
    assert r.returncode == 2 and msg in r.stderr and r.stdout == "", r.stderr


def test_no_rerank_index(tmp_path):
    m = make_manifest(tmp_path)
    idx = build(tmp_path, m, *AFFINE)
    q = tmp_path / "shapes" / "star_1.txt"
    r = run("search", q, idx)  # re-ranking by default: the index has no neighbour lists
    assert r.returncode == 2 and "--no-rerank" in r.stderr
    assert run("search", q, idx, "--no-rerank").returncode == 0


@pytest.mark.parametrize("damage", ["truncate", "flip", "version", "magic-only", "empty"])
def test_corrupt_index(tmp_path, damage):
    m = make_manifest(tmp_path)
    idx = build(tmp_path, m, "--refine", "0")
    data = bytearray(idx.read_bytes())
    if damage == "truncate":
        data = data[:len(data) // 2]
    elif damage == "flip":
        data[len(data) // 3] ^= 0x40
    elif damage == "version":
        data[8] = 9
    elif damage == "magic-only":
        data = data[:8]
    else:
        data = data[:0]
    bad = tmp_path / "bad.idx"
    bad.write_bytes(bytes(data))
    q = tmp_path / "shapes" / "star_1.txt"
    r = run("search", q, bad)
    assert r.returncode == 1 and r.stdout == "" and r.stderr.count("\n") == 1
    if damage == "truncate":
        assert "truncated" in r.stderr
    if damage == "flip":  # the names and tables are checksummed, every shape is checked by the library
        assert "checksum" in r.stderr or "damaged shape" in r.stderr
    if damage == "version":
        assert "version 9" in r.stderr
    for args in (("eval", bad), ("matrix", bad, "-o", "-"), ("index", m, "-o", bad, "--add")):
        r = run(*args)
        assert r.returncode == 1 and r.stdout == ""


def test_index_output_is_atomic_and_required(tmp_path):
    m = make_manifest(tmp_path)
    assert run("index", m).returncode == 2
    assert run("index", m, "-o", "-").returncode == 2
    r = run("index", tmp_path / "missing.tsv", "-o", tmp_path / "x.idx")
    assert r.returncode == 1 and not (tmp_path / "x.idx").exists()
    assert [p for p in os.listdir(tmp_path) if p.startswith(".")] == []


def test_sheet_from_an_index(tmp_path):
    m = make_manifest(tmp_path)
    idx = build(tmp_path, m, *AFFINE)
    out = tmp_path / "s.svg"
    r = run("search", tmp_path / "shapes" / "wave_2.txt", idx, "--no-rerank", "--top", "3", "--sheet", out)
    assert r.returncode == 0 and out.read_text().count('<g class="hit">') == 3


def test_candidates(tmp_path):
    """--candidates 0 matches every shape, whatever --top; an index built from each shape's
    signature candidates only still finds the query itself first."""
    m = make_manifest(tmp_path)
    idx = build(tmp_path, m, "--refine", "0")
    q = tmp_path / "shapes" / "wave_1.txt"
    a = json.loads(run("search", q, idx, "--json", "--top", "2", "--candidates", "0").stdout)["results"]
    b = json.loads(run("search", q, m, "--json", "--top", "2", "--refine", "0").stdout)["results"]
    same_results(a, b)
    few = build(tmp_path, m, "--refine", "0", "--candidates", "3", "--rerank", "3", name="few.idx")
    r = run("search", q, few, "--json", "--candidates", "4", "--rerank", "3", "--top", "3")
    assert r.returncode == 0, r.stderr
    res = json.loads(r.stdout)["results"]
    assert res[0]["file"].endswith("wave_1.txt") and all(x["class"] == "wave" for x in res[:1])
    assert run("search", q, few, "--candidates", "-1").returncode == 2
