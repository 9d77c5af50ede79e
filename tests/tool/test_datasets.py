"""Real silhouettes (skipped visibly when the datasets are absent): `amscr contour` traces every
Kimia silhouette; `amscr eval` reproduces the published retrieval figures on Kimia-99, Kimia-216
and mpeg7-dev."""
import glob
import json
import os

import pytest

from imgutil import datasets_dir, read_points, run, signed_area

DATA = datasets_dir()
FILES = sorted(glob.glob(os.path.join(DATA, "kimia*", "*.png"))) if DATA else []

needs_data = pytest.mark.skipif(not FILES, reason="datasets not found: no Kimia silhouettes (set AMSCR_DATASETS)")
pytestmark = pytest.mark.png


@needs_data
@pytest.mark.parametrize("folder", ["kimia99", "kimia216"])
def test_contour_every_kimia_silhouette(folder):
    files = sorted(glob.glob(os.path.join(DATA, folder, "*.png")))
    if not files:
        pytest.skip(folder + " not present")
    failures = []
    for f in files:
        r = run("contour", f)
        if r.returncode != 0:
            failures.append(r.stderr.strip())
            continue
        pts = read_points(r.stdout)
        if len(pts) < 30 or signed_area(pts) <= 0:
            failures.append("%s: %d points, area %g" % (f, len(pts), signed_area(pts)))
    assert not failures, failures[:10]


# The published retrieval figures (README.md "Headline figures", docs/measurements.md
# "Retrieval"), reproduced through `amscr eval MANIFEST` at its defaults (the retrieval preset)
# and with --paper, on contours traced at sub-pixel accuracy (the tool's default). docs/measurements.md
# publishes the top-k SUMS (Kimia-99 989 of 990, Kimia-216 2356 of 2376 with --ranks 11; the paper's
# method 585 and 1877); the hits per rank below are the measured rows those sums come from, asserted
# exactly. Bull's eye: mpeg7-dev 97.88 % (the paper's method 75.10 %). Measured times (2 shared cores): mpeg7-dev 6-50 s at
# the defaults, 12-25 s with --paper; the Kimia runs 0.3-3.5 s each.
PUBLISHED = {
    ("kimia99", "default"): {"ranks": 10, "topk": [99, 99, 99, 99, 99, 99, 99, 99, 99, 98], "sum": 989},
    ("kimia216", "default"): {"ranks": 11, "sum": 2356,
                              "topk": [215, 215, 215, 215, 215, 214, 213, 213, 214, 213, 214]},
    ("mpeg7-dev", "default"): {"bullseye": 0.9788},
    ("kimia99", "paper"): {"ranks": 10, "topk": [95, 87, 85, 69, 61, 50, 46, 30, 31, 31], "sum": 585},
    ("kimia216", "paper"): {"ranks": 11, "sum": 1877,
                            "topk": [212, 204, 197, 190, 179, 168, 157, 156, 146, 139, 129]},
    ("mpeg7-dev", "paper"): {"bullseye": 0.7510},
}
_EVALS = {}


def published_eval(folder, mode):
    """`amscr eval` of a set's manifest (once per run), or a visible skip without the data."""
    mf = os.path.join(DATA or "", folder, "manifest.tsv")
    if not DATA or not os.path.exists(mf):
        pytest.skip("%s: datasets not found (set AMSCR_DATASETS)" % folder)
    key = (folder, mode)
    if key not in _EVALS:
        want = PUBLISHED[key]
        args = ["eval", mf, "--json"]
        if "ranks" in want:
            args += ["--ranks", str(want["ranks"])]
        if mode == "paper":
            args.append("--paper")
        r = run(*args, timeout=900)
        assert r.returncode == 0, r.stderr
        _EVALS[key] = json.loads(r.stdout)
    return _EVALS[key], PUBLISHED[key]


@pytest.mark.parametrize("folder", ["kimia99", "kimia216", "mpeg7-dev"])
def test_published_retrieval_at_the_defaults(folder):
    """The README's figures at `amscr eval MANIFEST`'s defaults: the same hits per rank as
    published (Kimia), a bull's eye no more than 0.5 point below the published one (mpeg7-dev)."""
    j, want = published_eval(folder, "default")
    if "topk" in want:
        assert j["topk"] == want["topk"] and sum(j["topk"]) == want["sum"], j["topk"]
    else:
        assert j["bullseye"] >= want["bullseye"] - 0.005, "bull's eye %.2f %% < published %.2f %% - 0.5" % (
            100 * j["bullseye"], 100 * want["bullseye"])


@pytest.mark.parametrize("folder", ["kimia99", "kimia216", "mpeg7-dev"])
def test_paper_method_reproduces_its_table(folder):
    """`--paper` (the AMSCR distance alone, affine group, no refinement, no re-ranking) gives
    exactly the recorded table: 585 / 1877, and 75.10 % to the published two decimals."""
    j, want = published_eval(folder, "paper")
    if "topk" in want:
        assert j["topk"] == want["topk"] and sum(j["topk"]) == want["sum"], j["topk"]
    else:
        assert round(100 * j["bullseye"], 2) == round(100 * want["bullseye"], 2), j["bullseye"]


def test_kimia99_eval_json_fields():
    """The JSON of `amscr eval` (the default run above, not a second one)."""
    j, _ = published_eval("kimia99", "default")
    assert j["n"] == 99 and j["classes"] == 9
    assert len(j["topk"]) == 10 and all(0 <= c <= 99 for c in j["topk"])
    assert 0 <= j["bullseye"] <= 1 and 0 <= j["nn_accuracy"] <= 1


# The README's ablation table ("What each part of the retrieval default adds"), the rows the tool
# can give: mpeg7-dev's bull's eye with the parts added one by one (the inner graph at 0.11's
# share 0.05 until the last row; `--affine-view 0`: without the affine views' rule), and the
# default, 0.11's default and --fast on its two class folds (folds.tsv), each fold its own
# collection. Asserted to 0.1 point (one query of mpeg7-dev's 700 moves the bull's eye by a few
# hundredths).
NO_VIEW = ["--affine-view", "0"]
SHARE_011 = ["--inner-share", "0.05"]
ABLATION = [
    ("mpeg7-dev", ["--no-rerank"] + NO_VIEW, 88.84),
    ("mpeg7-dev", ["--inner-share", "0"] + NO_VIEW, 95.63),
    ("mpeg7-dev", ["--inner-closing", "0"] + SHARE_011 + NO_VIEW, 96.41),
    ("mpeg7-dev", SHARE_011 + NO_VIEW, 97.09),
    ("mpeg7-dev", SHARE_011, 97.39),
    ("mpeg7-dev", [], 97.88),
    ("mpeg7-dev", ["--fast"], 97.75),
    ("A", SHARE_011, 97.22),
    ("A", [], 97.83),
    ("A", ["--fast"], 97.71),
    ("B", [], 100.00),
]


def fold_manifest(fold, tmp_path):
    """mpeg7-dev's rows of one fold of its folds.tsv, as a manifest of absolute paths."""
    d = os.path.join(DATA or "", "mpeg7-dev")
    if not DATA or not os.path.exists(os.path.join(d, "folds.tsv")):
        pytest.skip("mpeg7-dev: datasets not found (set AMSCR_DATASETS)")
    with open(os.path.join(d, "folds.tsv")) as f:
        folds = dict(line.rstrip("\n").split("\t") for line in list(f)[1:])
    with open(os.path.join(d, "manifest.tsv")) as f:
        rows = [line.rstrip("\n").split("\t") for line in list(f)[1:]]
    path = tmp_path / ("fold%s.tsv" % fold)
    path.write_text("file\tclass\n" + "".join("%s\t%s\n" % (os.path.join(d, p), c)
                                             for p, c in rows if folds[c] == fold))
    assert len(path.read_text().splitlines()) > 300
    return str(path)


@pytest.mark.parametrize("where,flags,published", ABLATION)
def test_ablation_rows(where, flags, published, tmp_path):
    if where == "mpeg7-dev":
        mf = os.path.join(DATA or "", where, "manifest.tsv")
        if not DATA or not os.path.exists(mf):
            pytest.skip("mpeg7-dev: datasets not found (set AMSCR_DATASETS)")
    else:
        mf = fold_manifest(where, tmp_path)
    r = run("eval", mf, "--json", *flags, timeout=900)
    assert r.returncode == 0, r.stderr
    got = 100 * json.loads(r.stdout)["bullseye"]
    assert abs(got - published) <= 0.1, "%s %s: bull's eye %.2f %%, published %.2f %%" % (where, flags, got, published)


# eth80-dev (objects of ETH-80 seen in 41 views; docs/measurements.md "Retrieval"): leave one object
# out (out of the collection's fusion and re-ranking graph too), 1-NN, through `amscr eval MANIFEST
# --protocol groups` at the defaults, on every fourth view of each object (views 1, 5, ..., 41: 440
# shapes, a few seconds; the whole set's figure is the ablation table's). No setting of the default was chosen on it. Asserted not to fall more than
# half a point (two of its 440 queries) below the published figure.
ETH80_EVERY_FOURTH_VIEW = 73.86


def test_eth80_dev_one_object_out(tmp_path):
    d = os.path.join(DATA or "", "eth80-dev")
    if not DATA or not os.path.exists(os.path.join(d, "manifest.tsv")):
        pytest.skip("eth80-dev: datasets not found (set AMSCR_DATASETS)")
    with open(os.path.join(d, "manifest.tsv")) as f:
        head = f.readline().rstrip("\n").split("\t")
        rows = [dict(zip(head, line.rstrip("\n").split("\t"))) for line in f if line.strip()]
    assert len(rows) == 1640 and "group" in head
    path = tmp_path / "eth80-dev-every-fourth-view.tsv"
    kept = [r for i, r in enumerate(rows) if (i % 41) % 4 == 0]
    path.write_text("file\tclass\tgroup\n" +
                    "".join("%s\t%s\t%s\n" % (os.path.join(d, r["file"]), r["class"], r["group"]) for r in kept))
    r = run("eval", str(path), "--protocol", "groups", "--json", timeout=900)
    assert r.returncode == 0, r.stderr
    j = json.loads(r.stdout)
    assert j["n"] == 440 and j["groups"]["n"] == 40
    got = 100 * j["groups"]["accuracy"]
    assert got >= ETH80_EVERY_FOURTH_VIEW - 0.5, "eth80-dev (every fourth view): %.2f %%, published %.2f %%" % (
        got, ETH80_EVERY_FOURTH_VIEW)
