"""Real silhouettes (skipped when ../shared/datasets is absent): `amscr contour` traces every
Kimia silhouette; `amscr eval` runs on the Kimia-99 manifest."""
import glob
import json
import os

import pytest

from imgutil import datasets_dir, read_points, run, signed_area

DATA = datasets_dir()
FILES = sorted(glob.glob(os.path.join(DATA, "kimia*", "*.png"))) if DATA else []

needs_data = pytest.mark.skipif(not FILES, reason="../shared/datasets (Kimia silhouettes) not present")
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


@needs_data
def test_eval_kimia99_manifest():
    mf = os.path.join(DATA, "kimia99", "manifest.tsv")
    if not os.path.exists(mf):
        pytest.skip("kimia99 manifest not present")
    r = run("eval", mf, "--json", "--threads", "0", timeout=600)
    assert r.returncode == 0, r.stderr
    j = json.loads(r.stdout)
    assert j["n"] == 99 and j["classes"] == 9
    assert len(j["topk"]) == 10 and all(0 <= c <= 99 for c in j["topk"])
    assert 0 <= j["bullseye"] <= 1 and 0 <= j["nn_accuracy"] <= 1
