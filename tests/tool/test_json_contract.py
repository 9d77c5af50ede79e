"""The --json contract: every object is strict JSON (no NaN/Infinity tokens), valid UTF-8 whatever
the file names, with exactly the documented keys (docs/cli.md, docs/collections.md)."""
import json
import os
import subprocess

import pytest

from imgutil import affine, rasterize, smooth_shape, tool_path, write_points

REGISTER_KEYS = {"source", "target", "A", "B", "distance", "method", "scales", "residuals", "kept", "shift",
                 "reflected", "k", "threshold", "sse", "mixture", "samples", "closed", "source_points",
                 "target_points", "confidence", "ambiguity", "inlier_fraction", "overlap", "backward_error",
                 "symmetry_ambiguity", "standard_error", "partial", "part", "correspondences", "stages",
                 "alternatives"}
SEARCH_KEYS = {"query", "collection", "n", "results", "seconds"}
SEARCH_RESULT_KEYS = {"rank", "index", "file", "class", "distance"}
EVAL_KEYS = {"collection", "n", "classes", "protocol", "bullseye", "topk", "nn_accuracy", "per_class", "method",
             "reflections", "seconds", "seconds_prepare", "seconds_matrix"}
CONTOUR_KEYS = {"image", "count", "contours"}


def strict(raw):
    """The one JSON object of raw (bytes): UTF-8, one line, no NaN/Infinity."""
    def bad(c):
        raise AssertionError("non-JSON constant %s" % c)
    text = raw.decode("utf-8")  # RFC 8259: UTF-8
    assert text.endswith("\n") and text.count("\n") == 1
    return json.loads(text, parse_constant=bad)


def tool(*args):
    r = subprocess.run([tool_path()] + [os.fsencode(a) if isinstance(a, (str, bytes, os.PathLike)) else str(a)
                                        for a in args], capture_output=True)
    assert r.returncode == 0, r.stderr
    return r.stdout


@pytest.fixture
def coll(tmp_path):
    """Three shapes of two classes, one with a name that is not UTF-8."""
    d = tmp_path / "c"
    d.mkdir()
    base = smooth_shape(300)
    write_points(d / "a-1.txt", base)
    write_points(d / "a-2.txt", affine(((0.9, 0.2, 3.0), (-0.1, 1.1, 2.0)), base))
    write_points(os.path.join(os.fsencode(d), b"b\xe9 \"x\"\t-1.txt"), smooth_shape(300, seed=2))
    return d


def test_register_keys(coll):
    for extra in ([], ["--partial"]):
        j = strict(tool("register", coll / "a-1.txt", coll / "a-2.txt", "--json", *extra))
        assert set(j) == REGISTER_KEYS
        assert set(j["mixture"]) == {"weights", "means", "variances"}
        assert set(j["correspondences"]) == {"param", "points"}
        assert all(set(a) == {"A", "B", "cost"} for a in j["alternatives"])
        assert len(j["A"]) == 2 and all(len(r) == 2 for r in j["A"]) and len(j["B"]) == 2


def test_search_and_eval_keys_and_utf8(coll):
    j = strict(tool("search", coll / "a-1.txt", coll, "--json"))
    assert set(j) == SEARCH_KEYS and all(set(r) == SEARCH_RESULT_KEYS for r in j["results"])
    # a name that is not UTF-8 comes back as Python's surrogateescape: the file itself
    assert all(os.path.exists(os.path.join(os.fsencode(coll), os.fsencode(r["file"]))) for r in j["results"])
    e = strict(tool("eval", coll, "--json", "--protocol", "All"))
    assert set(e) == EVAL_KEYS and e["protocol"] == "all"


def test_contour_keys_and_utf8(tmp_path):
    img = os.path.join(os.fsencode(tmp_path), b"\xff.pgm")
    from imgutil import pgm_bytes
    with open(img, "wb") as f:
        f.write(pgm_bytes(rasterize(smooth_shape(200), 200, 200)))
    j = strict(tool("contour", img, "--all", "--json"))
    assert set(j) == CONTOUR_KEYS and os.fsencode(j["image"]) == img


def test_index_to_stdout_is_the_index_alone(coll, tmp_path):
    want = tmp_path / "want.idx"
    tool("index", coll, "-o", want)
    with open(tmp_path / "got.idx", "wb") as f:
        r = subprocess.run([tool_path(), "index", str(coll), "-o", "/dev/stdout"], stdout=f, stderr=subprocess.PIPE)
    assert r.returncode == 0, r.stderr
    assert (tmp_path / "got.idx").read_bytes() == want.read_bytes()


def test_matrix_names_and_matrix_through_one_file_refused(tmp_path):
    """-o - --names /dev/stdout with stdout a file: one file through two descriptors, refused
    (the names were overwritten by the matrix); to a terminal-like device both still go."""
    coll = tmp_path / "c"
    coll.mkdir()
    write_points(coll / "a-1.txt", smooth_shape(300))
    write_points(coll / "b-1.txt", smooth_shape(300, seed=2))
    out = tmp_path / "both.tsv"
    with open(out, "wb") as f:
        r = subprocess.run([tool_path(), "matrix", str(coll), "-o", "-", "--names", "/dev/stdout"],
                           stdout=f, stderr=subprocess.PIPE)
    assert r.returncode == 1 and b"name the same file" in r.stderr, r.stderr
    r = subprocess.run([tool_path(), "matrix", str(coll), "-o", "-", "--names", "/dev/null"],
                       stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    assert r.returncode == 0, r.stderr
