"""The held-out registration table of docs/measurements.md ("Held-out MPEG-7 contours, against
OpenCV's ECC"), amscr column, reproduced case by case with the bench's own generator
(bench/registration_heldout.py: one contour of each of the 35 mpeg7-dev classes, 2 seeded draws
per condition, success = map error below 2 % of the size). Skipped by name without mpeg7-dev.

Not reproduced here: the ECC column (OpenCV's ECC from 8 starts takes ~20 min), the 280-pair
noise table and the uneven-sampling / convention / stray-point benches (minutes each: beyond
the suite's time budget; their commands are in docs/measurements.md). Measured: ~25-40 s."""
import numpy as np
import pytest

import amscr

from test_polish import heldout_data

# Published successes of 70 pairs: clean, 1 % noise, 5 / 10 / 20 % missing all 100 %; 2 % noise
# 97.1 %; fragments of 70 % / 50 % of the boundary 100 % / 97.1 % (98.6 / 95.7 % before a
# placement that collapsed the fragment's area lost). Since 0.5 the order and
# even-spacing steps of the polish are opt-in (they changed no traced-image pair): 2 % noise
# 100 -> 97.1 % by default; with them switched on, as before (POINT_LIST_STAGES below).
PUBLISHED = {'clean': 70, 'noise1': 70, 'noise2': 68, 'miss5': 70, 'miss10': 70, 'miss20': 70,
             'frag70': 70, 'frag50': 68}
POINT_LIST_STAGES = {'order': True, 'even_spacing': True}
POINT_LIST_PUBLISHED = {'noise1': 70, 'noise2': 70}


@pytest.fixture(scope='module')
def heldout():
    data = heldout_data()
    import registration_heldout
    return registration_heldout, registration_heldout.load_shapes(data, 35)


@pytest.mark.parametrize('key', list(PUBLISHED))
def test_heldout_condition_as_published(heldout, key):
    bench, shapes = heldout
    ci = [c[0] for c in bench.CONDITIONS].index(key)
    amount = bench.CONDITIONS[ci][2]
    ok, failed = 0, []
    for si, (cls, f) in enumerate(shapes):
        for d in range(2):
            rng = np.random.default_rng([14, ci, si, d])
            src, tgt, T, size, partial = bench.make_case(f, key, amount, rng)
            M, r = bench.amscr_register(src, tgt, partial)
            err = bench.map_error(M, T, src, size) if M is not None else np.inf
            if err < 0.02:
                ok += 1
            else:
                failed.append((cls, d, round(100 * err, 2), None if r is None else round(r.confidence, 3)))
    assert len(shapes) == 35
    assert ok >= PUBLISHED[key], '%s: %d of 70 within 2 %% (published %d); failures %s' % (
        key, ok, PUBLISHED[key], failed)


@pytest.mark.parametrize('key', list(POINT_LIST_PUBLISHED))
def test_heldout_noise_with_the_point_list_stages(heldout, key):
    """The noisy conditions with the polish's order and even-spacing steps switched on (the
    table's "point-list stages on" column): 2 % noise 100 %, as published for 0.3.2-0.4."""
    bench, shapes = heldout
    ci = [c[0] for c in bench.CONDITIONS].index(key)
    amount = bench.CONDITIONS[ci][2]
    ok, failed = 0, []
    for si, (cls, f) in enumerate(shapes):
        for d in range(2):
            rng = np.random.default_rng([14, ci, si, d])
            src, tgt, T, size, _ = bench.make_case(f, key, amount, rng)
            r = amscr.register(src, tgt, stages=POINT_LIST_STAGES)
            err = bench.map_error(np.hstack([r.A, r.B[:, None]]), T, src, size)
            ok += err < 0.02
            if err >= 0.02:
                failed.append((cls, d, round(100 * err, 2)))
    assert ok >= POINT_LIST_PUBLISHED[key], '%s: %d of 70 (published %d); failures %s' % (
        key, ok, POINT_LIST_PUBLISHED[key], failed)
