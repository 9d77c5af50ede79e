"""Maps that rest on a few parts of the boundary (bench/registration_traced.py --families,
procedural shapes): a target traced at 30-40 px across or with 2 % segmentation noise whose thin
parts pull the map 4-144 % of the size off while the inliers and the overlap still read high.
The standard error of the map (the block jackknife of its final fit) is large there, and the
confidence must say so. Before the standard error entered it, these pairs read 0.29-0.52. A clean
pair and a finely traced one of the same shapes stay confident. Skipped without OpenCV or
scikit-image."""
import math

import numpy as np
import pytest

import amscr

pytest.importorskip('cv2')
pytest.importorskip('skimage')
from family_pairs import pair  # noqa: E402  (beside this file)

# (procedural shape, condition, draw): wrong + confident pairs of the families sweep in 0.17.0
IMPRECISE = [(8, 'lowres30', 1), (8, 'lowres30', 5), (8, 'lowres40', 0), (8, 'lowres40', 1), (11, 'lowres40', 3),
             (11, 'lowres40', 5), (23, 'lowres30', 6), (28, 'lowres40', 6), (33, 'noise2', 7)]


@pytest.mark.parametrize('i,key,draw', IMPRECISE)
def test_an_imprecise_map_is_not_confident(family_bench, i, key, draw):
    r, err, thr = pair(family_bench, i, key, draw)
    assert err < thr or r.confidence < 0.25, 'map %.1f %% off, confidence %.2f' % (err, r.confidence)
    if err >= thr:
        assert r.standard_error > 0.005, 'standard error %.4f' % r.standard_error


@pytest.mark.parametrize('i,key,draw', [(8, 'clean', 1), (11, 'lowres80', 3), (23, 'noise1', 6)])
def test_a_precise_map_stays_confident(family_bench, i, key, draw):
    r, err, thr = pair(family_bench, i, key, draw)
    assert err < thr and r.confidence >= 0.25, 'map %.2f %% off, confidence %.2f' % (err, r.confidence)
    assert r.standard_error < 0.005, 'standard error %.4f' % r.standard_error


def test_the_confidence_combines_the_standard_error():
    """The confidence is the documented product, the standard error one of its factors."""
    t = np.linspace(0, 2 * np.pi, 300, endpoint=False)
    src = np.column_stack([np.cos(t) * (1 + 0.3 * np.cos(3 * t)), np.sin(t) * (1 + 0.2 * np.sin(2 * t))])
    rng = np.random.default_rng(5)
    tgt = src @ np.array([[1.3, 0.4], [-0.2, 0.9]]).T + rng.normal(0, 0.01, src.shape)
    r = amscr.register(src, tgt)
    assert 0.0 < r.standard_error < 0.01
    amb = max(r.ambiguity, 0.0 if math.isnan(r.symmetry_ambiguity) else r.symmetry_ambiguity)
    fb = 0.0 if math.isnan(r.backward_error) else r.backward_error
    share = min(r.inlier_fraction, r.overlap)
    want = (1 - amb) * share / (1 + (fb / 0.01) ** 2) / (1 + (r.standard_error / 0.01) ** 2)
    assert r.confidence == pytest.approx(want, abs=1e-12)
    assert math.isnan(amscr.register(src, tgt, invariance='similarity').standard_error)
