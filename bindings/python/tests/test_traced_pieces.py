"""Traced image pairs whose target a bite cut in two (bench/registration_traced.py, condition
"bite"): with join=True, as `amscr register` traces images, the map is within 2 % of the size;
the largest piece alone gave maps 80-330 % off. Skipped without mpeg7-dev or OpenCV."""
import numpy as np
import pytest

import amscr
from test_polish import heldout_data

# (class, draw): the bite failures of the benchmark before the pieces were joined
CUT_IN_TWO = [('Bone', 1), ('Glas', 1), ('guitar', 0), ('guitar', 1), ('ray', 1), ('spoon', 0), ('spoon', 1)]
# spoon 0: the map is 0.3 % off, but the stub of the bitten handle pulls the final fit (its
# standard error reads 1 %) and the confidence falls to 0.22: the price of reading the fit's
# precision (docs/measurements.md, the families' good maps confident 96.6 -> 95.4 %)
PULLED = {('spoon', 0)}


@pytest.fixture(scope='module')
def bench():
    pytest.importorskip('cv2')
    data = heldout_data()
    import registration_traced
    classes = registration_traced.load_classes(data)
    return registration_traced, classes


@pytest.mark.parametrize('cls,draw', CUT_IN_TWO)
def test_bite_through_a_thin_part(bench, cls, draw):
    B, classes = bench
    i = [c[0] for c in classes].index(cls)
    src = B.load_source(classes[i][1])
    f = B.subpixel_contour(src)
    rng = np.random.default_rng([i, [c[0] for c in B.CONDITIONS].index('bite'), draw, 2024])
    tgt, T = B.make_target(src, f, rng)
    tgt = B.damage('bite', tgt, B.apply(T, f), rng)
    errors = []
    for join in (False, True):
        r = amscr.register(amscr.contour_from_mask(src, join=join), amscr.contour_from_mask(tgt, join=join))
        errors.append(B.errors(np.hstack([np.asarray(r.A), np.asarray(r.B)[:, None]]), T, f)[1])
    assert errors[0] > 2.0, 'the largest piece alone: %.2f %% (no longer a cut case?)' % errors[0]
    assert errors[1] < 2.0, 'joined: %.2f %% of the size' % errors[1]
    if (cls, draw) in PULLED:  # confident but for the standard error
        assert r.standard_error > 0.005 and r.confidence * (1 + (r.standard_error / 0.01) ** 2) >= 0.25
    else:
        assert r.confidence >= 0.25
