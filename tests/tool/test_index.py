"""`amscr index` and an index wherever search, matrix and eval take a collection: the same
results as the folder or manifest, --add (equal to a rebuild), options that conflict with the
index's, the tool's index files before 0.4 refused, and corrupt or truncated index files. The
index file is the library's (amscr_index_save): Python and C read it too
(bindings/python/tests/test_index_faces.py)."""
import json
import os
import shutil

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


def test_add_equals_a_rebuild(tmp_path):
    """--add of the remaining files gives the index of all of them: the same top 10, scores
    equal to rounding (every shape a candidate, channel weight 1)."""
    m = make_manifest(tmp_path)
    rows = m.read_text().splitlines()
    # 6 shapes first: their lists already hold the re-ranking's 3 (at most half a collection)
    (tmp_path / "a.tsv").write_text("\n".join(rows[:7]) + "\n")
    (tmp_path / "b.tsv").write_text("\n".join([rows[0]] + rows[7:]) + "\n")
    opts = ("--refine", "0", "--rerank", "3")
    whole = build(tmp_path, m, *opts, name="whole.idx")
    part = build(tmp_path, tmp_path / "a.tsv", *opts, name="part.idx")
    r = run("index", tmp_path / "b.tsv", "-o", part, "--add")
    assert r.returncode == 0 and "9 shapes, 3 classes" in r.stdout, r.stderr
    new = tmp_path / "new.txt"
    write_points(new, affine(((0.8, 0.3, 4.0), (-0.2, 1.2, 1.0)), base_shapes()["star"]))
    for q in (tmp_path / "shapes" / "star_3.txt", new):
        a = json.loads(run("search", q, part, "--json", "--candidates", "0").stdout)["results"]
        b = json.loads(run("search", q, whole, "--json", "--candidates", "0").stdout)["results"]
        assert [x["file"] for x in a] == [x["file"] for x in b]
        same_results(a, b)
    ja = json.loads(run("eval", part, "--json", "--protocol", "groups").stdout)
    jb = json.loads(run("eval", whole, "--json", "--protocol", "groups").stdout)
    assert ja["groups"] == jb["groups"] and ja["per_class"] == jb["per_class"]
    # the same files again: refused, the index unchanged
    before = part.read_bytes()
    r = run("index", tmp_path / "b.tsv", "-o", part, "--add")
    assert r.returncode == 1 and "already in the index" in r.stderr and part.read_bytes() == before


def test_add_to_an_index_smaller_than_its_lists_rebuilds_it(tmp_path):
    """An index of fewer than twice its re-ranking K holds shorter lists (at most half the
    collection): --add builds it again on the old and new shapes, as collections.md says, with
    the names, classes and groups of both: the index of all the files."""
    m = make_manifest(tmp_path)
    rows = m.read_text().splitlines()
    (tmp_path / "a.tsv").write_text("\n".join(rows[:3]) + "\n")
    (tmp_path / "b.tsv").write_text("\n".join([rows[0]] + rows[3:]) + "\n")
    whole = build(tmp_path, m, "--refine", "0", name="whole.idx")
    part = build(tmp_path, tmp_path / "a.tsv", "--refine", "0", name="part.idx")
    r = run("index", tmp_path / "b.tsv", "-o", part, "--add")
    assert r.returncode == 0 and r.stderr == "", r.stderr
    assert "9 shapes, 3 classes" in r.stdout and "object in the wrong state" not in r.stdout + r.stderr
    assert part.read_bytes() == whole.read_bytes()
    for q in ("star_3.txt", "blob_1.txt"):
        a = json.loads(run("search", tmp_path / "shapes" / q, part, "--json").stdout)["results"]
        b = json.loads(run("search", tmp_path / "shapes" / q, m, "--json", "--refine", "0").stdout)["results"]
        same_results(a, b)
    ja = json.loads(run("eval", part, "--json", "--protocol", "groups").stdout)
    jb = json.loads(run("eval", m, "--json", "--protocol", "groups", "--refine", "0").stdout)
    assert ja["groups"] == jb["groups"] and ja["per_class"] == jb["per_class"]


def test_index_of_one_shape_counts_in_the_singular(tmp_path):
    m = make_manifest(tmp_path)
    (tmp_path / "one.tsv").write_text("\n".join(m.read_text().splitlines()[:2]) + "\n")
    r = run("index", tmp_path / "one.tsv", "-o", tmp_path / "one.idx")
    assert r.returncode == 0 and ": 1 shape, 1 class, " in r.stdout, r.stdout + r.stderr


@pytest.mark.parametrize("index_groups", [True, False])
def test_add_with_and_without_a_group_column(tmp_path, index_groups):
    """A group column on one side only: the message says which side has one."""
    grouped, plain = make_manifest(tmp_path), make_manifest(tmp_path, with_group=False)
    rows = (grouped if index_groups else plain).read_text().splitlines()
    (tmp_path / "a.tsv").write_text("\n".join(rows[:7]) + "\n")
    other = (plain if index_groups else grouped).read_text().splitlines()
    (tmp_path / "b.tsv").write_text("\n".join([other[0]] + other[7:]) + "\n")
    idx = build(tmp_path, tmp_path / "a.tsv", "--refine", "0")
    before = idx.read_bytes()
    r = run("index", tmp_path / "b.tsv", "-o", idx, "--add")
    want = ("the index has groups and the new shapes' manifest has no group column" if index_groups else
            "the index has no groups and the new shapes' manifest has a group column")
    assert r.returncode == 1 and want in r.stderr and r.stderr.count("\n") == 1, r.stderr
    assert idx.read_bytes() == before


PYTHON = os.path.join(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))), ".venv", "bin",
                      "python")

PY_INDEX = """
import sys, amscr
out, step, files = sys.argv[1], int(sys.argv[2]), sys.argv[3:]
db = amscr.Collection(amscr.Params.retrieval())
for k, f in enumerate(files):
    db.add(amscr.read_points(f), label=step * (1 + k // 3))
db.save(out + ".coll")
amscr.Index(db).save(out)
"""


def python_index(tmp_path, step):
    """An index saved by Python whose labels are 1, 2, 3 or 10, 20, 30 (not the tool's 0..k-1),
    and its collection file. Skipped when the project's Python or its amscr is missing."""
    if not os.access(PYTHON, os.X_OK):
        pytest.skip("no project Python at %s to write an index with amscr.Index" % PYTHON)
    import subprocess
    if subprocess.run([PYTHON, "-c", "import amscr; amscr.Index"], capture_output=True).returncode:
        pytest.skip("%s cannot import amscr (with amscr.Index)" % PYTHON)
    make_manifest(tmp_path)
    files = [str(tmp_path / "shapes" / ("%s_%d.txt" % (c, k))) for c in ("blob", "wave", "star") for k in (1, 2, 3)]
    out = tmp_path / ("py%d.idx" % step)
    r = subprocess.run([PYTHON, "-c", PY_INDEX, str(out), str(step)] + files, capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    return out


@pytest.mark.parametrize("step", [1, 10])
def test_eval_of_an_index_with_other_labels(tmp_path, step):
    """eval takes any index: the classes are its distinct labels (3 here), named by their number
    when the index does not name them, whatever the labels' values; an --add of a named class
    keeps them and adds one."""
    idx = python_index(tmp_path, step)
    names = ["1", "2", "3"] if step == 1 else ["10", "20", "30"]
    for proto in ("all", "topk", "nn"):
        r = run("eval", idx, "--json", "--protocol", proto)
        assert r.returncode == 0, r.stderr
        j = json.loads(r.stdout)
        assert j["n"] == 9 and j["classes"] == 3, j
        assert [c["class"] for c in j["per_class"]] == names and all(c["n"] == 3 for c in j["per_class"])
    r = run("eval", idx, "--protocol", "topk")
    assert "(9 shapes, 3 classes)" in r.stdout, r.stdout
    res = json.loads(run("search", tmp_path / "shapes" / "wave_2.txt", idx, "--json", "--top", "3").stdout)
    assert [x["class"] for x in res["results"]] == [names[1]] * 3
    r = run("index", make_add_manifest(tmp_path), "-o", idx, "--add")
    assert r.returncode == 0 and "10 shapes, 4 classes" in r.stdout, r.stdout + r.stderr
    j = json.loads(run("eval", idx, "--json", "--protocol", "nn").stdout)
    assert [c["class"] for c in j["per_class"]] == names + ["new"]


def make_add_manifest(tmp_path):
    """A manifest of one new shape of a new class."""
    write_points(tmp_path / "new.txt", affine(((0.8, 0.3, 4.0), (-0.2, 1.2, 1.0)), base_shapes()["star"][::2]))
    mf = tmp_path / "new.tsv"
    mf.write_text("file\tclass\nnew.txt\tnew\n")
    return mf


def test_a_collection_file_where_an_index_is_expected(tmp_path):
    """A collection file without an index (Python's Collection.save): the message says how to
    build an index from the tool or Python, not from C."""
    idx = python_index(tmp_path, 1)
    coll = str(idx) + ".coll"
    r = run("eval", coll)
    assert r.returncode == 1 and r.stderr.count("\n") == 1, r.stderr
    assert "amscr index" in r.stderr and "amscr.Index" in r.stderr and "build one with" not in r.stderr, r.stderr
    # following the advice: `amscr index` of the file says the way that works for it
    r = run("index", coll, "-o", tmp_path / "x.idx")
    assert r.returncode == 1 and "amscr.Index(amscr.Collection.load(FILE)).save(OUT)" in r.stderr, r.stderr
    # a file cut inside its magic is an amscr file cut short, not a manifest without a header
    cut = tmp_path / "cut.idx"
    cut.write_bytes(open(coll, "rb").read()[:7])
    q = tmp_path / "shapes" / "star_1.txt"
    for args in (("eval", cut), ("search", q, cut), ("index", cut, "-o", tmp_path / "y.idx")):
        r = run(*args)
        assert r.returncode == 1 and "header" not in r.stderr and "cut.idx" in r.stderr, (args, r.stderr)


def test_old_tool_index_is_refused(tmp_path):
    """An index file of the tool before 0.4 (magic AMSCRIDX): a clear error saying to rebuild."""
    m = make_manifest(tmp_path)
    old = tmp_path / "old.idx"
    old.write_bytes(b"AMSCRIDX" + bytes([2, 0, 0, 0, 0, 0, 0, 0]) + bytes(64))
    q = tmp_path / "shapes" / "star_1.txt"
    for args in (("search", q, old), ("eval", old), ("matrix", old, "-o", "-"), ("index", m, "-o", old, "--add")):
        r = run(*args)
        assert r.returncode == 1 and r.stdout == "" and r.stderr.count("\n") == 1, (args, r.stderr)
        assert "AMSCRIDX" in r.stderr and "rebuild it with `amscr index`" in r.stderr, r.stderr


@pytest.mark.parametrize("cmd,opt,msg", [
    ("search", ("--points", "64"), "built with --points 128"),
    ("eval", ("--invariance", "similarity"), "--invariance"),
    ("matrix", ("--no-reflections",), "reflections"),
    ("index-add", ("--refine", "2"), "--refine"),
    ("index-add", ("--rerank", "5"), "--rerank"),
    ("index-add", ("--channel-weight", "0.5"), "--channel-weight"),
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
    """An index remembers its re-ranking settings: built without re-ranking (--paper), it
    searches without it by default; another --rerank ranks by the collection's matrix with it,
    as the manifest does."""
    m = make_manifest(tmp_path)
    idx = build(tmp_path, m, *AFFINE)
    q = tmp_path / "shapes" / "star_1.txt"
    r = run("search", q, idx, "--json")
    assert r.returncode == 0, r.stderr
    plain = run("search", q, idx, "--json", "--no-rerank")
    assert json.loads(r.stdout)["results"] == json.loads(plain.stdout)["results"]
    a = json.loads(run("search", q, idx, "--json", "--rerank", "3").stdout)["results"]
    b = json.loads(run("search", q, m, "--json", *AFFINE, "--rerank", "3").stdout)["results"]
    same_results(a, b)


@pytest.mark.parametrize("damage", ["truncate", "flip", "version", "magic-only", "short-header", "empty"])
def test_corrupt_index(tmp_path, damage):
    m = make_manifest(tmp_path)
    idx = build(tmp_path, m, "--refine", "0")
    data = bytearray(idx.read_bytes())
    if damage == "truncate":
        data = data[:len(data) // 2]
    elif damage == "flip":
        data[len(data) // 3] ^= 0x40
    elif damage == "version":
        data[8] = 17  # a version newer than the newest
    elif damage == "magic-only":
        data = data[:8]
    elif damage == "short-header":  # magic and version, then the file ends inside the lengths (a fuzzer find)
        data = data[:14]
    else:
        data = data[:0]
    bad = tmp_path / "bad.idx"
    bad.write_bytes(bytes(data))
    q = tmp_path / "shapes" / "star_1.txt"
    r = run("search", q, bad)
    assert r.returncode == 1 and r.stdout == "" and r.stderr.count("\n") == 1
    if damage == "truncate":
        assert "truncated" in r.stderr
    if damage == "short-header":  # the library reads a file shorter than its envelope as not its own
        assert "truncated" in r.stderr or "bad magic" in r.stderr
    if damage == "flip":  # the names and tables are checksummed, every shape is checked by the library
        assert "checksum" in r.stderr or "damaged shape" in r.stderr
    if damage == "version":
        assert "version 17" in r.stderr
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


@pytest.mark.parametrize("opts", [(), ("--channel-weight", "0.5"), ("--affine-share", "0", "--rerank", "4,5")])
def test_retrieval_defaults_from_an_index(tmp_path, opts):
    """The retrieval preset (shape channel, fusion, re-ranking) holds for an index: matrix and
    eval of the index equal the manifest's with the same options, and a search against it
    (every shape a candidate) gives the manifest's scores in [0, 1], the query itself 0, for a
    member query and for a new shape (weight 1: exactly; fused weights use the medians of the
    index's build, so a new shape's scores keep their order but not their digits)."""
    m = make_manifest(tmp_path)
    idx = build(tmp_path, m, *opts)
    a = run("matrix", idx, "-o", "-").stdout
    b = run("matrix", m, "-o", "-", *opts).stdout
    assert a.splitlines()[1:] == b.splitlines()[1:] and len(a.splitlines()) == 10
    ja = json.loads(run("eval", idx, "--json", "--protocol", "groups").stdout)
    jb = json.loads(run("eval", m, "--json", "--protocol", "groups", *opts).stdout)
    assert ja["groups"] == jb["groups"] and ja["per_class"] == jb["per_class"]
    member = tmp_path / "shapes" / "blob_2.txt"
    new = tmp_path / "new.txt"
    write_points(new, affine(((0.8, 0.3, 4.0), (-0.2, 1.2, 1.0)), base_shapes()["wave"]))
    for q in (member, new):
        a = json.loads(run("search", q, idx, "--json", "--candidates", "0").stdout)["results"]
        b = json.loads(run("search", q, m, "--json", *opts).stdout)["results"]
        assert all(0.0 <= r["distance"] <= 1.0 for r in a)
        if q == member:
            assert a[0]["file"].endswith("blob_2.txt") and a[0]["distance"] == 0.0
        if q == member or "--channel-weight" not in opts:
            same_results(a, b)
        else:
            assert [r["class"] for r in a] == [r["class"] for r in b]


def test_channel_options_that_conflict_with_the_index(tmp_path):
    m = make_manifest(tmp_path)
    idx = build(tmp_path, m)
    q = tmp_path / "shapes" / "star_1.txt"
    for opt, msg in ((("--channel-weight", "0.5"), "built with --channel-weight 1"),
                     (("--affine-share", "0"), "--affine-share"), (("--fast",), "--affine-share"),
                     (("--paper",), "--channel-weight")):
        r = run("search", q, idx, *opt)
        assert r.returncode == 2 and msg in r.stderr and r.stdout == "", r.stderr
    # re-ranking is a query-time setting (another one than the index's ranks by the matrix)
    assert run("search", q, idx, "--rerank", "4,3").returncode == 0
    assert run("search", q, idx, "--no-rerank").returncode == 0


def test_inner_share_and_the_index(tmp_path):
    """The default re-ranks on two graphs (the inner distance's at share 0.1) and an index
    built with it holds both: its search is the manifest's; `index --inner-share 0` holds one
    graph and searches as the manifest with --inner-share 0; an --inner-share other than the
    index's ranks by the collection's matrix, as the manifest does; --add with another share is
    refused."""
    m = make_manifest(tmp_path)
    idx = build(tmp_path, m)
    one_idx = build(tmp_path, m, "--inner-share", "0", name="one.idx")
    q = tmp_path / "shapes" / "wave_2.txt"
    two = json.loads(run("search", q, m, "--json").stdout)["results"]
    one = json.loads(run("search", q, m, "--json", "--inner-share", "0").stdout)["results"]
    assert [r["distance"] for r in two] != [r["distance"] for r in one]
    same_results(json.loads(run("search", q, idx, "--json").stdout)["results"], two)
    same_results(json.loads(run("search", q, one_idx, "--json").stdout)["results"], one)
    same_results(json.loads(run("search", q, idx, "--json", "--inner-share", "0").stdout)["results"], one)
    same_results(json.loads(run("search", q, one_idx, "--json", "--inner-share", "0.1").stdout)["results"], two)
    r = run("index", m, "-o", one_idx, "--add", "--inner-share", "0.05")
    assert r.returncode != 0 and "inner_share" in r.stderr
    assert run("search", q, m, "--inner-share", "1").returncode == 2


def test_inner_closing_and_the_index(tmp_path):
    """The default takes the inner distance inside each silhouette closed at 0.08 sqrt(area), and
    an index built with it keeps each shape's closed outline: its search is the manifest's;
    `index --inner-closing 0` searches as the manifest with --inner-closing 0, and so does the
    default index searched with --inner-closing 0; a closing the index was not built with
    (its outlines come from the contours, which it does not keep) and --add with another
    closing are refused; a closing outside 0..1 is a usage error."""
    m = make_manifest(tmp_path)
    idx = build(tmp_path, m)
    open_idx = build(tmp_path, m, "--inner-closing", "0", name="open.idx")
    q = tmp_path / "shapes" / "wave_2.txt"
    closed = json.loads(run("search", q, m, "--json").stdout)["results"]
    plain = json.loads(run("search", q, m, "--json", "--inner-closing", "0").stdout)["results"]
    assert [r["distance"] for r in closed] != [r["distance"] for r in plain]
    same_results(json.loads(run("search", q, idx, "--json").stdout)["results"], closed)
    same_results(json.loads(run("search", q, open_idx, "--json").stdout)["results"], plain)
    same_results(json.loads(run("search", q, idx, "--json", "--inner-closing", "0").stdout)["results"], plain)
    r = run("search", q, open_idx, "--inner-closing", "0.08")
    assert r.returncode == 1 and r.stdout == "" and "rebuild the index" in r.stderr
    r = run("index", m, "-o", open_idx, "--add", "--inner-closing", "0.1")
    assert r.returncode != 0 and "inner_closing" in r.stderr
    assert run("search", q, m, "--inner-closing", "2").returncode == 2


def test_affine_view_and_the_index(tmp_path):
    """The default ranks a pair the affine frame finds twice as near as the frames' mix by the
    affine frame (the manifest's shapes are affine copies of three shapes): its distances differ
    from `--affine-view 0`'s (the mix for every pair). An index keeps its build's factor: built
    with 0 it searches as the manifest with 0; searched with another factor (a usage error
    naming the option) or --add with one, it is refused; a factor outside [1, 100] other than 0
    is a usage error."""
    m = make_manifest(tmp_path)
    q = tmp_path / "shapes" / "wave_2.txt"
    view = json.loads(run("search", q, m, "--json").stdout)["results"]
    mix = json.loads(run("search", q, m, "--json", "--affine-view", "0").stdout)["results"]
    dv, dm = {r["file"]: r["distance"] for r in view}, {r["file"]: r["distance"] for r in mix}
    assert dv != dm
    idx = build(tmp_path, m)
    mix_idx = build(tmp_path, m, "--affine-view", "0", name="mix.idx")
    same_results(json.loads(run("search", q, idx, "--json").stdout)["results"], view)
    same_results(json.loads(run("search", q, mix_idx, "--json").stdout)["results"], mix)
    r = run("search", q, idx, "--affine-view", "0")
    assert r.returncode == 2 and r.stdout == "" and "rebuild it" in r.stderr and "--affine-view 2" in r.stderr
    r = run("index", m, "-o", mix_idx, "--add", "--affine-view", "3")
    assert r.returncode != 0 and "affine" in r.stderr
    for bad in ("0.5", "101", "x", "-1"):
        assert run("search", q, m, "--affine-view", bad).returncode == 2


def killed_run(*args):
    """Runs the tool under strace, which kills it (SIGKILL) as its first write begins: a save cut
    off mid-write, no clean-up code run."""
    import subprocess

    from imgutil import tool_path
    return subprocess.run(["strace", "-qq", "-f", "-o", "/dev/null", "-e", "trace=write",
                           "-e", "inject=write:signal=SIGKILL:when=1", tool_path()] + [str(a) for a in args],
                          capture_output=True)


@pytest.mark.skipif(shutil.which("strace") is None, reason="strace is not installed (scripts/setup.sh installs it)")
@pytest.mark.parametrize("what", ["index", "matrix"])
def test_a_killed_save_leaves_the_old_file_and_nothing_else(tmp_path, what):
    """An index (the library's writer) or a matrix (the tool's) whose save is killed mid-write
    leaves the file it would replace as it was and no temporary file beside it, where the
    system has unnamed files (O_TMPFILE; Linux, most file systems)."""
    m = make_manifest(tmp_path)
    out = tmp_path / "out"
    out.mkdir()
    name = "x.idx" if what == "index" else "x.tsv"
    args = ("index", m, "-o", out / name) if what == "index" else ("matrix", m, "-o", out / name, "--no-rerank")
    assert run(*args).returncode == 0
    good = (out / name).read_bytes()
    assert len(good) > 1024
    r = killed_run(*args)
    assert r.returncode in (-signal_number("SIGKILL"), 128 + signal_number("SIGKILL")), (r.returncode, r.stderr)
    assert (out / name).read_bytes() == good
    if unnamed_files(out):
        assert sorted(os.listdir(out)) == [name]


@pytest.mark.skipif(shutil.which("strace") is None, reason="strace is not installed (scripts/setup.sh installs it)")
def test_a_refused_rename_fails_once(tmp_path):
    """An index whose replacing rename is refused (EPERM, injected: a sticky folder, an immutable
    file) is an error naming the reason, the old file kept and nothing beside it, after one
    attempt: the library wrote the whole file a second time under a temporary name before."""
    import subprocess

    from imgutil import tool_path
    m = make_manifest(tmp_path)
    out = tmp_path / "out"
    out.mkdir()
    args = ["index", str(m), "-o", str(out / "x.idx")]
    assert run(*args).returncode == 0
    good = (out / "x.idx").read_bytes()
    trace = tmp_path / "trace.txt"
    r = subprocess.run(["strace", "-qq", "-f", "-o", str(trace), "-e", "trace=rename,renameat,renameat2",
                        "-e", "inject=rename,renameat,renameat2:error=EPERM", tool_path()] + args,
                       capture_output=True, text=True)
    assert r.returncode == 1 and "x.idx: cannot write: Operation not permitted" in r.stderr, r.stderr
    assert (out / "x.idx").read_bytes() == good
    assert sorted(os.listdir(out)) == ["x.idx"]
    renames = [line for line in trace.read_text().splitlines() if "x.idx" in line]
    assert len(renames) == 1, renames


def signal_number(name):
    import signal
    return int(getattr(signal, name))


def unnamed_files(d):
    flag = getattr(os, "O_TMPFILE", None)
    if flag is None:
        return False
    try:
        os.close(os.open(str(d), flag | os.O_WRONLY, 0o600))
        return True
    except OSError:
        return False
