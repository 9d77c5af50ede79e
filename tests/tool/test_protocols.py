"""`amscr eval --protocol split|groups` and the per-class scores of --json."""
import json

import pytest

from imgutil import affine, run, write_points
from test_collection import AFFINE, MAPS, base_shapes


def make_manifest(tmp_path, with_group=True):
    """3 classes x 3 affine copies; the group of a shape is its distortion (one map = one group)."""
    d = tmp_path / "shapes"
    d.mkdir(exist_ok=True)
    rows = ["file\tclass\tgroup" if with_group else "file\tclass"]
    for name, pts in base_shapes().items():
        for k, m in enumerate(MAPS, 1):
            rel = "shapes/%s_%d.txt" % (name, k)
            write_points(tmp_path / rel, affine(m, pts))
            rows.append("%s\t%s\tmap%d" % (rel, name, k) if with_group else "%s\t%s" % (rel, name))
    mf = tmp_path / ("grouped.tsv" if with_group else "plain.tsv")
    mf.write_text("\n".join(rows) + "\n")
    return mf


def eval_json(*args):
    r = run("eval", *args, "--json", *AFFINE)
    assert r.returncode == 0, r.stderr
    return json.loads(r.stdout)


def test_split_mean_spread_and_per_class(tmp_path):
    mf = make_manifest(tmp_path)
    j = eval_json(mf, "--protocol", "split", "--train", "2", "--splits", "4", "--seed", "7")
    sp = j["split"]
    assert sp["train"] == 2 and sp["splits"] == 4 and sp["seed"] == 7 and len(sp["accuracies"]) == 4
    # affine copies under the affine group: every tested shape finds its class
    assert sp["accuracies"] == [1, 1, 1, 1] and sp["accuracy_mean"] == 1 and sp["accuracy_std"] == 0
    assert [c["class"] for c in j["per_class"]] == ["blob", "wave", "star"]
    assert all(c["split_accuracy"] == 1 and c["n"] == 3 for c in j["per_class"])
    assert "bullseye" not in j and "nn_accuracy" not in j


def test_split_is_reproducible_and_text(tmp_path):
    mf = make_manifest(tmp_path)
    a = eval_json(mf, "--protocol", "split", "--train", "1", "--splits", "3")
    b = eval_json(mf, "--protocol", "split", "--train", "1", "--splits", "3")
    assert a["split"] == b["split"]
    r = run("eval", mf, "--protocol", "split", "--train", "1", *AFFINE)
    assert r.returncode == 0 and "split" in r.stdout and "10 splits" in r.stdout


@pytest.mark.parametrize("args,msg", [
    (("--protocol", "split", "--train", "3"), "class 'blob' (3 shapes)"),
    (("--protocol", "split", "--train", "99"), "use --train 2 or less"),
    (("--protocol", "split"), "needs --train"),
    (("--protocol", "nn", "--train", "1"), "only with --protocol split"),
    (("--protocol", "split", "--train", "1", "--splits", "0"), "--splits"),
    (("--protocol", "split", "--train", "-1"), "--train"),
])
def test_split_bad_input(tmp_path, args, msg):
    r = run("eval", make_manifest(tmp_path), *args, *AFFINE)
    assert r.returncode == 2 and msg in r.stderr and r.stdout == ""


def test_split_with_a_class_of_one_shape(tmp_path):
    """A class of one shape leaves no --train to suggest: the error says so, not 'use --train 0
    or less' (a value --train refuses)."""
    mf = make_manifest(tmp_path, with_group=False)
    write_points(tmp_path / "shapes" / "lone.txt", affine(MAPS[1], base_shapes()["star"]))
    mf.write_text(mf.read_text() + "shapes/lone.txt\tlone\n")
    r = run("eval", mf, "--protocol", "split", "--train", "1", *AFFINE)
    assert r.returncode == 2 and r.stdout == "", r.stderr
    assert "class 'lone' has 1 shape" in r.stderr and "--train 0" not in r.stderr, r.stderr


def test_groups_leave_one_out(tmp_path):
    j = eval_json(make_manifest(tmp_path), "--protocol", "groups")
    g = j["groups"]
    assert g["n"] == 3 and g["accuracy"] == 1
    assert [x["group"] for x in g["per_group"]] == ["map1", "map2", "map3"]
    assert all(c["groups_accuracy"] == 1 for c in j["per_class"])


def test_groups_needs_the_group_column(tmp_path):
    r = run("eval", make_manifest(tmp_path, with_group=False), "--protocol", "groups", *AFFINE)
    assert r.returncode == 1 and "'group' column" in r.stderr and r.stdout == ""


def test_groups_needs_two_groups(tmp_path):
    mf = make_manifest(tmp_path)
    text = mf.read_text().replace("map2", "map1").replace("map3", "map1")
    mf.write_text(text)
    r = run("eval", mf, "--protocol", "groups", *AFFINE)
    assert r.returncode == 1 and "at least 2 groups" in r.stderr


def test_per_class_scores_add_up(tmp_path):
    """Per-class leave-one-out scores weigh back to the library's whole-collection scores."""
    mf = make_manifest(tmp_path)
    j = json.loads(run("eval", mf, "--json", "--no-rerank", "--refine", "0").stdout)
    pc = j["per_class"]
    assert len(pc) == 3
    nn = sum(c["nn_accuracy"] * c["n"] for c in pc) / j["n"]
    be = sum(c["bullseye"] * c["n"] ** 2 for c in pc) / sum(c["n"] ** 2 for c in pc)
    assert nn == pytest.approx(j["nn_accuracy"], abs=1e-12)
    assert be == pytest.approx(j["bullseye"], abs=1e-12)
