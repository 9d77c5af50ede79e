"""A slow, plain NumPy reference of the shape channel (docs/method.md §10.2), written from its
definition to check the library's amscr_channel_distance (amscr.channel_distance).

It starts from a prepared shape's N samples in input coordinates (Shape.input_points: the
parametrization is the preparation's business, tested elsewhere) and computes, with loops and
no shortcuts:

1. the frame: centroid at the origin, then either scaled to an RMS radius of sqrt(2)
   ('similarity') or multiplied by the symmetric inverse square root of the covariance
   ('affine', whitened; the covariance divides by N);
2. the height functions of every sample i: the signed distances of the other samples
   i+1 .. i+N-1 (in curve order) to the tangent line at i (tangent = P[i+1] - P[i-1], the left
   normal is positive), averaged in 16 bins of equal index width, each bin weighted by
   1 / (1 + locality * t) with t the distance of the bin's centre along the curve as a fraction
   (the shorter way round), quantized to bytes: round(128 + 16 * weighted height), clipped to
   0..255 — so a cell's cost is an integer sum of absolute differences;
3. the mirror image (x -> -x, traversed backwards so it keeps its orientation) gives the second
   sequence;
4. the start: the cyclic shift s maximizing the correlation sum_i <A_i, B_(i+s)> low-passed to
   frequencies |f| <= N/8 (computed here as a direct sum over those frequencies), the first s on
   ties; with reflections, the mirrored sequence replaces B when its best correlation is larger;
5. the order-preserving match: a path through the cells (i, k), k in [-band, band], where cell
   (i, k) pairs a's sample i with b's sample s + i + k (mod N). Row 0 may start at any k; each
   step goes to (i+1, k) (both advance, free), (i+1, k-1) (b's sample matched again: +skip) or
   (i, k+1) (a's sample matched again: +skip); the path ends anywhere in row N-1 and pays
   skip * |k_end - k_start| for the samples it did not close. The distance is that cost
   divided by 16 N. The library does not minimize it jointly over start and end: every cell
   keeps the cheapest way into it and that way's start, and the end penalty is added last
   (match_library_rule, what the library is compared with). match_exact is the true minimum
   over every start (one DP per start), a lower bound of the library's value;
6. the two frames mixed: (1 - share) * similarity + share * affine (the affine frame alone when
   the channel's frame is affine).
"""
import numpy as np

BINS = 16
QUANT = 16.0


def frame(points, kind):
    p = np.asarray(points, dtype=float)
    c = p - p.mean(axis=0)
    if kind == 'affine':
        cov = c.T @ c / len(c)
        vals, vecs = np.linalg.eigh(cov)
        w = vecs @ np.diag(1.0 / np.sqrt(vals)) @ vecs.T
        return c @ w.T
    rms = np.sqrt((c ** 2).sum(axis=1).mean())
    return c * (np.sqrt(2.0) / rms)


def heights(P, locality):
    """(N, 16) uint8 height functions of the closed curve P."""
    n = len(P)
    out = np.zeros((n, BINS), dtype=np.int64)
    for i in range(n):
        t = P[(i + 1) % n] - P[(i - 1) % n]
        norm = np.array([-t[1], t[0]]) / np.hypot(*t)
        sums = [0.0] * BINS
        counts = [0] * BINS
        for j in range(1, n):
            b = (j - 1) * BINS // (n - 1)
            sums[b] += float(np.dot(P[(i + j) % n] - P[i], norm))
            counts[b] += 1
        for b in range(BINS):
            centre = (b + 0.5) / BINS
            along = min(centre, 1.0 - centre)
            h = sums[b] / counts[b] if counts[b] else 0.0
            q = 128.0 + QUANT * h / (1.0 + locality * along)
            out[i, b] = min(255, max(0, int(np.floor(q + 0.5))))
    return out


def mirrored(P):
    return np.column_stack([-P[::-1, 0], P[::-1, 1]])


def best_shift(A, B):
    """(shift, correlation) maximizing the low-passed cyclic correlation of A against B."""
    n = len(A)
    fmax = min(n // 8, n // 2)
    FA = np.fft.fft(A - 128.0, axis=0)
    FB = np.fft.fft(B - 128.0, axis=0)
    freqs = [f for f in range(n) if min(f, n - f) <= fmax]
    best, best_c = 0, -np.inf
    for s in range(n):
        c = 0.0
        for f in freqs:
            c += (np.conj(FA[f]) * FB[f] * np.exp(2j * np.pi * f * s / n)).sum().real
        if c > best_c:
            best, best_c = s, c
    return best, best_c


def match_exact(A, B, s, band, skip):
    """The cheapest path of step 5 (integer cost units), minimized exactly over every start."""
    n = len(A)
    ks = range(-band, band + 1)
    cost = {(i, k): int(np.abs(A[i] - B[(s + i + k) % n]).sum()) for i in range(n) for k in ks}
    best = None
    for k0 in ks:
        INF = float('inf')
        D = {(0, k): INF for k in ks}
        D[(0, k0)] = cost[(0, k0)]
        for k in ks:  # row 0: a's first sample matched again towards larger k
            if k > k0:
                D[(0, k)] = D[(0, k - 1)] + skip + cost[(0, k)]
        for i in range(1, n):
            for k in ks:
                cands = [D[(i - 1, k)]]
                if k + 1 <= band:
                    cands.append(D[(i - 1, k + 1)] + skip)
                if k - 1 >= -band:
                    cands.append(D[(i, k - 1)] + skip)
                D[(i, k)] = cost[(i, k)] + min(cands)
        for k in ks:
            total = D[(n - 1, k)] + skip * abs(k - k0)
            best = total if best is None else min(best, total)
    return best


def match_library_rule(A, B, s, band, skip):
    """Step 5 as the library decides it: one pass, every cell keeps the cheapest way in (ties:
    the straight step first, then b's sample again, then a's sample again) and the start offset
    of that way; the end penalty is added last, with the start each end cell carries. Its value
    is a real path's cost, so it is never below match_exact."""
    n = len(A)
    ks = list(range(-band, band + 1))
    cost = {(i, k): int(np.abs(A[i] - B[(s + i + k) % n]).sum()) for i in range(n) for k in ks}
    D, start = {}, {}
    for k in ks:
        D[(0, k)], start[(0, k)] = cost[(0, k)], k  # a start costs nothing: never beaten in row 0
    for i in range(1, n):
        for k in ks:
            ways = [(D[(i - 1, k)], start[(i - 1, k)])]
            if k + 1 <= band:
                ways.append((D[(i - 1, k + 1)] + skip, start[(i - 1, k + 1)]))
            if k - 1 >= -band:
                ways.append((D[(i, k - 1)] + skip, start[(i, k - 1)]))
            way = min(ways, key=lambda w: w[0])  # min keeps the first of equal ones
            D[(i, k)], start[(i, k)] = cost[(i, k)] + way[0], way[1]
    return min(D[(n - 1, k)] + skip * abs(k - start[(n - 1, k)]) for k in ks)


def channel_in_frame(pa, pb, kind, band, skip, locality, reflections, exact):
    n = len(pa)
    Pa, Pb = frame(pa, kind), frame(pb, kind)
    A = heights(Pa, locality)
    B0, B1 = heights(Pb, locality), heights(mirrored(Pb), locality)
    s, c = best_shift(A, B0)
    B = B0
    if reflections:
        s1, c1 = best_shift(A, B1)
        if c1 > c:
            s, B = s1, B1
    w = max(1, int(np.floor(band * n + 0.5)))
    w = min(w, n // 2)
    match = match_exact if exact else match_library_rule
    return match(A, B, s, w, int(round(skip * QUANT))) / (n * QUANT)


def channel_distance(pa, pb, *, invariance='similarity', affine_share=0.2, band=0.15, affine_band=0.08, skip=1.0,
                     locality=4.0, reflections=True, affine_view=2.0, exact=False):
    """The channel distance of two shapes given their prepared samples (N x 2 each); exact=True
    minimizes step 5 over every start instead of following the library's rule. The whitened
    frame mixed in with affine_share uses affine_band; a frame alone uses band. With both frames
    and affine_view f > 0 the distance is min(mix, f * the whitened frame's)."""
    opts = dict(skip=skip, locality=locality, reflections=reflections, exact=exact)
    if invariance == 'affine' or affine_share >= 1.0:
        return channel_in_frame(pa, pb, 'affine', band=band, **opts)
    d = channel_in_frame(pa, pb, invariance, band=band, **opts)
    if affine_share <= 0.0:
        return d
    da = channel_in_frame(pa, pb, 'affine', band=affine_band, **opts)
    mix = (1.0 - affine_share) * d + affine_share * da
    return min(mix, affine_view * da) if affine_view > 0 else mix
