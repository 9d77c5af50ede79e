"""Contextual re-ranking of a distance matrix (C ``amscr_rerank_diffusion``)."""
from __future__ import annotations

import numpy as np

from ._lib import lib
from ._util import ArrayLike, as_float_array, as_uint, bad, dbuf
from .errors import _check


def rerank_diffusion(D: ArrayLike, k: int = 5, iterations: int = 20) -> np.ndarray:
    """Contextual re-ranking of a whole (n, n) distance matrix: affinity diffusion on the
    k-nearest-neighbour tensor-product graph (Yang, Prasad, Latecki, CVPR 2012), as
    ``amscr_rerank_diffusion``. Returns a new (n, n) dissimilarity for ranking: values in [0, 1)
    for pairs the diffusion reaches, 1 + D/max(D) for the others. The defaults (k = 5,
    20 iterations) are the ones the Kimia measurements chose (docs/measurements.md).

    Args:
        D: (n, n) distance matrix, finite.
        k: neighbours of the graph, an integer >= 1 (clamped to n).
        iterations: diffusion iterations, an integer in 1..1000.
    Returns:
        (n, n) float array (smaller = more similar).
    Raises:
        InvalidArgumentError: D not square or not finite, bad k or iterations (also a
        TypeError when not an integer).
    """
    d = np.array(as_float_array(D, 'D', ndim=(2,), finite=True), dtype=np.float64, order='C', copy=True)
    n = d.shape[0]
    if d.shape != (n, n):
        raise bad('D: expected a square matrix, got shape %s' % (d.shape,))
    out = np.empty_like(d)
    k, iterations = as_uint(k, 'k'), as_uint(iterations, 'iterations')  # not int(): 2.7 is no k
    kk = min(k, n) if n else k
    _check(lib.amscr_rerank_diffusion(dbuf(d), n, kk, iterations, dbuf(out)))
    return out
