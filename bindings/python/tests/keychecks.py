"""Key checks run in a subprocess per loading mode (see test_modes.py); prints one JSON object."""
import json
import sys

import numpy as np

import amscr
from helpers import A_TRUE, B_TRUE, affine, blob


def run():
    out = {'api_mode': amscr.API_MODE, 'version': amscr.library_version()}
    src = blob(400, seed=1)
    tgt = affine(src, A_TRUE, B_TRUE)
    r = amscr.register(src, tgt)
    out['register'] = [r.matrix.tolist(), r.distance, r.residuals.tolist(), r.kept.tolist(), r.shift]
    out['smooth'] = amscr.smooth(src[:50], 2.0).tolist()
    rng = np.random.default_rng(0)
    a, b = rng.normal(size=(30, 4)), rng.normal(size=30)
    out['lstsq'] = amscr.lstsq(a, b).tolist()
    out['lstsq_ok'] = bool(np.allclose(amscr.lstsq(a, b), np.linalg.lstsq(a, b, rcond=None)[0], rtol=1e-10))
    out['kmeans'] = amscr.kmeans([1.0, 2.0, 2.5, 9.0, 10.0], 2).inertia
    db = amscr.Collection(points=64, threads=2)
    db.extend([blob(200, seed=s) for s in range(5)], labels=['a', 'a', 'b', 'b', 'c'])
    out['matrix'] = db.distance_matrix().tolist()
    mask = np.zeros((30, 30), bool)
    mask[5:20, 8:25] = True
    out['mask'] = amscr.contour_from_mask(mask).tolist()
    try:
        amscr.Params(points=3)
    except amscr.InvalidArgumentError as e:
        out['error'] = [type(e).__name__, e.status, str(e)]
    try:
        db.distance_matrix(progress=lambda d, t: True)
    except amscr.CancelledError as e:
        out['cancel'] = type(e).__name__
    return out


if __name__ == '__main__':
    json.dump(run(), sys.stdout)
