"""Numerical cross-checks of the building blocks against NumPy / SciPy / brute force."""
import itertools
import math
import os
import shutil
import subprocess
import sys

import numpy as np
import pytest

import amscr
from helpers import A_TRUE, B_TRUE, affine, blob

scipy_ndimage = pytest.importorskip('scipy.ndimage')


# ---------------------------------------------------------------- least squares
@pytest.mark.parametrize('m,n,k', [(3, 3, 1), (10, 3, 1), (50, 6, 4), (200, 20, 3)])
def test_lstsq_matches_numpy(m, n, k):
    rng = np.random.default_rng(m * 100 + n)
    a = rng.normal(size=(m, n))
    b = rng.normal(size=(m, k))
    x, res = amscr.lstsq(a, b, return_residuals=True)
    x_ref = np.linalg.lstsq(a, b, rcond=None)[0]
    np.testing.assert_allclose(x, x_ref, rtol=1e-10, atol=1e-12)
    np.testing.assert_allclose(res, np.linalg.norm(a @ x_ref - b, axis=0), rtol=1e-8, atol=1e-12)
    # 1-D right-hand side gives a 1-D solution
    x1 = amscr.lstsq(a, b[:, 0])
    assert x1.shape == (n,)
    np.testing.assert_allclose(x1, x_ref[:, 0], rtol=1e-10, atol=1e-12)


def test_lstsq_accepts_non_contiguous_and_int_input():
    rng = np.random.default_rng(1)
    a = rng.normal(size=(12, 8))[:, ::2]  # a strided view
    b = np.arange(12)  # ints
    np.testing.assert_allclose(amscr.lstsq(a, b), np.linalg.lstsq(a, b, rcond=None)[0], rtol=1e-10)


def test_lstsq_return_residuals_is_a_bool():
    a, b = np.eye(3), np.arange(3.0)
    assert isinstance(amscr.lstsq(a, b, return_residuals=False), np.ndarray)
    assert len(amscr.lstsq(a, b, return_residuals=1)) == 2
    for bad in ('no', None, 2):  # a string was taken as true
        with pytest.raises(amscr.InvalidArgumentError, match='return_residuals'):
            amscr.lstsq(a, b, return_residuals=bad)


def test_lstsq_rank_deficient_raises_numeric_error():
    a = np.ones((5, 2))
    with pytest.raises(amscr.NumericError) as ei:
        amscr.lstsq(a, np.arange(5.0))
    assert ei.value.status == amscr.errors.lib.AMSCR_E_NUMERIC
    assert ei.value.detail  # the C library says why


def test_affine_fit_matches_numpy():
    rng = np.random.default_rng(3)
    src = rng.normal(size=(40, 2))
    dst = affine(src, A_TRUE, B_TRUE) + 0.01 * rng.normal(size=src.shape)
    M, rms = amscr.affine_fit(src, dst)
    X = np.column_stack([src, np.ones(len(src))])
    sol = np.linalg.lstsq(X, dst, rcond=None)[0]
    np.testing.assert_allclose(M[:2, :2], sol[:2].T, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(M[:2, 2], sol[2], rtol=1e-9, atol=1e-12)
    np.testing.assert_array_equal(M[2], [0, 0, 1])
    res = X @ sol - dst
    assert rms == pytest.approx(np.sqrt((res ** 2).sum(axis=1).mean()), rel=1e-9)


def test_affine_apply_and_invert():
    M = np.eye(3)
    M[:2, :2], M[:2, 2] = A_TRUE, B_TRUE
    pts = blob(50)
    np.testing.assert_allclose(amscr.affine_apply(M, pts), affine(pts, A_TRUE, B_TRUE), rtol=1e-14, atol=1e-14)
    np.testing.assert_allclose(amscr.affine_apply(M[:2], pts), affine(pts, A_TRUE, B_TRUE), rtol=1e-14)
    np.testing.assert_allclose(amscr.affine_invert(M), np.linalg.inv(M), rtol=1e-12, atol=1e-14)
    for none in (np.zeros((0, 2)), np.zeros((0, 1, 2), np.int32)):  # no points: none mapped
        assert amscr.affine_apply(M, none).shape == (0, 2)
    with pytest.raises(amscr.InvalidArgumentError, match="not finite"):
        amscr.affine_apply(M, [[0.0, np.nan]])
    with pytest.raises(amscr.DegenerateError):
        amscr.affine_invert([[1, 2, 0], [2, 4, 0], [0, 0, 1]])


# ---------------------------------------------------------------- smoothing
@pytest.mark.parametrize('sigma', [0.25, 0.5, 1.0, 2.0, 2.5, 3.0])
def test_gaussian_kernel(sigma):
    taps = amscr.gaussian_kernel(sigma)
    r = math.ceil(4 * sigma)
    assert taps.shape == (2 * r + 1,)
    x = np.arange(-r, r + 1)
    ref = np.exp(-0.5 * (x / sigma) ** 2)
    np.testing.assert_allclose(taps, ref / ref.sum(), rtol=1e-13, atol=1e-16)
    assert taps.sum() == pytest.approx(1.0, abs=1e-15)


# sigma with 4*sigma an integer: then scipy's radius int(4 sigma + 0.5) equals our ceil(4 sigma).
@pytest.mark.parametrize('sigma', [0.5, 1.0, 2.0, 2.5, 3.0, 6.0])
@pytest.mark.parametrize('n', [7, 64, 101])
def test_smooth_closed_matches_scipy_wrap(sigma, n):
    pts = np.random.default_rng(n).normal(size=(n, 2))
    got = amscr.smooth(pts, sigma, closed=True)
    ref = scipy_ndimage.gaussian_filter1d(pts, sigma, axis=0, mode='wrap', truncate=4.0)
    np.testing.assert_allclose(got, ref, rtol=1e-12, atol=1e-13)


@pytest.mark.parametrize('sigma', [1.0, 3.0, 10.0])
@pytest.mark.parametrize('n', [5, 16])
def test_smooth_closed_kernel_longer_than_curve(sigma, n):
    """Exactly periodic even when the kernel wraps the curve many times (explicit circular sum)."""
    pts = np.random.default_rng(7).normal(size=(n, 2))
    taps = amscr.gaussian_kernel(sigma)
    r = (len(taps) - 1) // 2
    ref = np.zeros_like(pts)
    for j, w in zip(range(-r, r + 1), taps):
        ref += w * np.roll(pts, -j, axis=0)
    np.testing.assert_allclose(amscr.smooth(pts, sigma, closed=True), ref, rtol=1e-12, atol=1e-13)


@pytest.mark.parametrize('sigma', [0.5, 1.0, 2.0])
def test_smooth_open_matches_scipy_reflect(sigma):
    pts = np.random.default_rng(2).normal(size=(40, 2))
    got = amscr.smooth(pts, sigma, closed=False)
    ref = scipy_ndimage.gaussian_filter1d(pts, sigma, axis=0, mode='reflect', truncate=4.0)
    np.testing.assert_allclose(got, ref, rtol=1e-12, atol=1e-13)


def test_smooth_sigma_zero_copies():
    pts = blob(30)
    np.testing.assert_array_equal(amscr.smooth(pts, 0.0), pts)


# ---------------------------------------------------------------- resampling and normalization
def test_resample_euclidean_square():
    sq = np.array([[0, 0], [2, 0], [2, 2], [0, 2]], dtype=float)
    out = amscr.resample_euclidean(sq, 16, closed=True)
    assert out.shape == (16, 2)
    np.testing.assert_allclose(out[0], [0, 0])
    steps = np.linalg.norm(np.diff(np.vstack([out, out[:1]]), axis=0), axis=1)
    np.testing.assert_allclose(steps, 0.5, rtol=1e-12)
    op = amscr.resample_euclidean(sq, 7, closed=False)
    np.testing.assert_allclose(op[0], sq[0])
    np.testing.assert_allclose(op[-1], sq[-1])


def test_normalize_whiten():
    pts = affine(blob(300), A_TRUE, B_TRUE)
    out, fwd, inv = amscr.normalize_whiten(pts)
    np.testing.assert_allclose(out.mean(axis=0), 0, atol=1e-12)
    np.testing.assert_allclose(np.cov(out.T, bias=True), np.eye(2), atol=1e-12)
    np.testing.assert_allclose(amscr.affine_apply(fwd, pts), out, atol=1e-12)
    np.testing.assert_allclose(fwd @ inv, np.eye(3), atol=1e-12)


def test_affine_arclength_is_affine_covariant():
    """Affine arc length scales by det(A)^(1/3) under an affine map (exact for the formula)."""
    pts = blob(256)
    cum, total = amscr.affine_arclength(pts, closed=True)
    cum2, total2 = amscr.affine_arclength(affine(pts, A_TRUE, B_TRUE), closed=True)
    s = abs(np.linalg.det(A_TRUE)) ** (1.0 / 3.0)
    assert cum[0] == 0 and np.all(np.diff(cum) >= 0) and total > cum[-1]
    np.testing.assert_allclose(cum2, s * cum, rtol=1e-9, atol=1e-12)
    assert total2 == pytest.approx(s * total, rel=1e-9)


def test_resample_affine_shapes():
    out = amscr.resample_affine(blob(300), 64)
    assert out.shape == (64, 2) and np.isfinite(out).all()
    with pytest.raises(amscr.DegenerateError):
        amscr.resample_affine(np.column_stack([np.arange(20.0), np.zeros(20)]), 16, closed=False)


# ---------------------------------------------------------------- K-means, elbow, GMM, Bayes
def _brute_force_sse(x, k):
    best = math.inf
    for assign in itertools.product(range(k), repeat=len(x)):
        a = np.array(assign)
        if len(set(assign)) != k:
            continue
        sse = sum(((x[a == c] - x[a == c].mean()) ** 2).sum() for c in range(k))
        best = min(best, sse)
    return best


@pytest.mark.parametrize('seed', [0, 1, 2])
@pytest.mark.parametrize('k', [1, 2, 3])
def test_kmeans_1d_is_the_exact_optimum(seed, k):
    x = np.random.default_rng(seed).normal(size=8) * [1, 1, 1, 5, 5, 9, 9, 9]
    res = amscr.kmeans(x, k)
    assert res.inertia == pytest.approx(_brute_force_sse(x, k), rel=1e-12, abs=1e-12)
    assert res.centers.shape == (k,) and np.all(np.diff(res.centers) >= 0)
    # labels = nearest centre; inertia recomputed from them
    np.testing.assert_array_equal(res.labels, np.argmin(np.abs(x[:, None] - res.centers[None]), axis=1))
    assert res.inertia == pytest.approx(((x - res.centers[res.labels]) ** 2).sum(), rel=1e-12, abs=1e-12)


def test_kmeans_2d_is_deterministic_and_consistent():
    rng = np.random.default_rng(5)
    data = np.vstack([rng.normal(size=(30, 2)) + c for c in ([0, 0], [8, 0], [0, 8])])
    a = amscr.kmeans(data, 3, seed=42)
    b = amscr.kmeans(data, 3, seed=42)
    np.testing.assert_array_equal(a.centers, b.centers)
    assert a.centers.shape == (3, 2)
    sse = ((data - a.centers[a.labels]) ** 2).sum()
    assert a.inertia == pytest.approx(sse, rel=1e-10)
    assert sorted(np.bincount(a.labels)) == [30, 30, 30]


@pytest.mark.parametrize('seed', [-1, 2 ** 64, 2 ** 70])
def test_kmeans_and_elbow_refuse_a_seed_outside_uint64(seed):
    """The seed is the library's uint64_t: outside it, the documented InvalidArgumentError (as
    nn_random_split's), not cffi's OverflowError; 2**64 - 1 is taken."""
    x = np.arange(10.0)
    for call in (lambda s: amscr.kmeans(x, 2, seed=s), lambda s: amscr.elbow(x, seed=s)):
        with pytest.raises(amscr.InvalidArgumentError, match='seed'):
            call(seed)
        call(2 ** 64 - 1)


def test_elbow_sse_matches_kmeans():
    rng = np.random.default_rng(0)
    x = np.concatenate([rng.normal(0, 0.1, 10), rng.normal(5, 0.1, 10), rng.normal(20, 0.1, 10)])
    k_best, sse = amscr.elbow(x, k_max=5)
    assert sse.shape == (5,)
    for k in range(1, 6):
        assert sse[k - 1] == pytest.approx(amscr.kmeans(x, k).inertia, rel=1e-12)
    assert k_best in (2, 3)
    k_flat, _ = amscr.elbow(np.ones(10), k_max=4)
    assert k_flat == 1


def test_gmm1d_recovers_two_components():
    rng = np.random.default_rng(1)
    x = np.concatenate([rng.normal(0.0, 1.0, 600), rng.normal(10.0, 2.0, 400)])
    g = amscr.gmm1d(x, 2)
    np.testing.assert_allclose(g.weights, [0.6, 0.4], atol=0.05)
    np.testing.assert_allclose(g.means, [0.0, 10.0], atol=0.3)
    np.testing.assert_allclose(g.variances, [1.0, 4.0], rtol=0.25)
    assert g.weights.sum() == pytest.approx(1.0)
    assert g.converged and g.iterations >= 1 and np.isfinite(g.loglik)
    post = g.posterior(0.0)
    assert post.shape == (2,) and post.sum() == pytest.approx(1.0) and post[0] > 0.99
    s = g.bayes_threshold(0, 1)
    w, m, v = g.weights, g.means, g.variances
    pdf = lambda i: w[i] * np.exp(-(s - m[i]) ** 2 / (2 * v[i])) / np.sqrt(2 * np.pi * v[i])  # noqa: E731
    assert m[0] < s < m[1] and pdf(0) == pytest.approx(pdf(1), rel=1e-8)


def test_bayes_threshold_closed_form():
    # equal variances: s = (mu1 + mu2)/2 + var * ln(w1/w2) / (mu2 - mu1)
    w1, w2, m1, m2, var = 0.7, 0.3, 1.0, 4.0, 0.8
    s = amscr.bayes_threshold(w1, m1, var, w2, m2, var)
    assert s == pytest.approx((m1 + m2) / 2 + var * math.log(w1 / w2) / (m2 - m1), rel=1e-12)
    # unequal variances: the two weighted densities are equal there
    s = amscr.bayes_threshold(0.5, 0.0, 1.0, 0.5, 3.0, 4.0)
    f = lambda w, m, v: w * math.exp(-(s - m) ** 2 / (2 * v)) / math.sqrt(2 * math.pi * v)  # noqa: E731
    assert 0 < s < 3 and f(0.5, 0.0, 1.0) == pytest.approx(f(0.5, 3.0, 4.0), rel=1e-10)


def test_bayes_threshold_no_crossing_gives_midpoint_or_raises():
    # a tiny, wide component never rises above the big one between the means
    args = (0.999, 0.0, 1.0, 0.001, 1.0, 100.0)
    assert amscr.bayes_threshold(*args) == pytest.approx(0.5)
    with pytest.raises(amscr.NotFoundError):
        amscr.bayes_threshold(*args, strict=True)


# ---------------------------------------------------------------- retrieval scores vs numpy references
def _order(row, exclude=None):
    idx = [j for j in np.lexsort((np.arange(len(row)), row)) if j != exclude]
    return idx


def _ref_bullseye(D, labels):
    n = len(labels)
    total = 0
    denom = 0
    for i in range(n):
        nc = int((labels == labels[i]).sum())
        win = _order(D[i])[:2 * nc]
        total += int((labels[win] == labels[i]).sum())
        denom += nc
    return total / denom


def _ref_topk(D, labels, ranks):
    out = np.zeros(ranks, dtype=int)
    for i in range(len(labels)):
        order = _order(D[i], exclude=i)
        for r in range(ranks):
            out[r] += labels[order[r]] == labels[i]
    return out


def _random_case(seed, n=24, classes=4, ties=False):
    rng = np.random.default_rng(seed)
    D = rng.random((n, n))
    if ties:
        D = np.round(D, 1)
    np.fill_diagonal(D, 0)
    labels = rng.integers(0, classes, n)
    return D, labels


@pytest.mark.parametrize('seed', range(4))
def test_scores_match_reference(seed):
    D, labels = _random_case(seed, ties=seed % 2 == 1)
    assert amscr.bullseye(D, labels) == pytest.approx(_ref_bullseye(D, labels), rel=1e-14)
    np.testing.assert_array_equal(amscr.topk_table(D, labels, ranks=10), _ref_topk(D, labels, 10))
    ref_nn = np.mean([labels[_order(D[i], exclude=i)[0]] == labels[i] for i in range(len(labels))])
    assert amscr.nn_accuracy(D, labels) == pytest.approx(ref_nn, rel=1e-14)


def test_scores_accept_string_labels():
    D, labels = _random_case(9)
    names = np.array(['class-%d' % v for v in labels])
    assert amscr.bullseye(D, names) == amscr.bullseye(D, labels)
    np.testing.assert_array_equal(amscr.topk_table(D, list(names)), amscr.topk_table(D, labels))


def test_nn_split_matches_reference():
    rng = np.random.default_rng(4)
    D = rng.random((10, 15))
    te, tr = rng.integers(0, 3, 10), rng.integers(0, 3, 15)
    ref = np.mean([tr[np.argmin(D[i])] == te[i] for i in range(10)])
    assert amscr.nn_split(D, te, tr) == pytest.approx(ref)
    assert amscr.nn_split(D, ['c%d' % v for v in te], ['c%d' % v for v in tr]) == pytest.approx(ref)


def test_topk():
    d = np.array([3.0, 1.0, 2.0, 1.0, 0.5])
    np.testing.assert_array_equal(amscr.topk(d, 3), [4, 1, 3])
    np.testing.assert_array_equal(amscr.topk(d, 3, exclude=4), [1, 3, 2])


# ---------------------------------------------------------------- contours
def _disc_mask(h=40, w=50, cy=20, cx=22, r=12):
    yy, xx = np.mgrid[:h, :w]
    return (yy - cy) ** 2 + (xx - cx) ** 2 <= r * r


def test_contour_from_mask_bool_uint8_and_strides():
    m = _disc_mask()
    c = amscr.contour_from_mask(m, subpixel=False)
    assert c.ndim == 2 and c.shape[1] == 2 and len(c) > 40
    assert amscr.signed_area(c) > 0
    # every contour point is a foreground pixel with a background 4-neighbour
    for x, y in c.astype(int):
        assert m[y, x]
    np.testing.assert_array_equal(amscr.contour_from_mask(m.astype(np.uint8) * 255, subpixel=False), c)
    np.testing.assert_array_equal(amscr.contour_from_mask(m.astype(np.uint8), threshold=0, subpixel=False), c)
    gray = m.astype(np.uint8) * 150 + 40  # 40 outside, 190 inside
    np.testing.assert_array_equal(amscr.contour_from_mask(gray, threshold='auto', subpixel=False), c)
    np.testing.assert_array_equal(amscr.contour_from_mask(gray.astype(np.int64), subpixel=False), c)
    # a non-contiguous view (every other row and column of an upsampled mask) equals its copy
    big = np.repeat(np.repeat(m, 2, axis=0), 2, axis=1)
    view = big[::2, ::2]
    assert not view.flags.c_contiguous
    np.testing.assert_array_equal(amscr.contour_from_mask(view, subpixel=False), c)
    # Fortran order / transposed
    ct = amscr.contour_from_mask(np.asfortranarray(m.T), subpixel=False)
    assert len(ct) == len(c) and amscr.signed_area(ct) > 0


def test_contour_from_mask_inverted_polarity_and_border():
    m = _disc_mask()  # an image's polarity is automatic (a bool mask's True is the foreground)
    img = m.astype(np.uint8) * 255
    np.testing.assert_array_equal(amscr.contour_from_mask(255 - img), amscr.contour_from_mask(m))
    touching = np.zeros((20, 20), bool)
    touching[0:10, 0:12] = True
    c = amscr.contour_from_mask(touching, subpixel=False)
    assert c[:, 0].min() == 0 and c[:, 1].min() == 0
    c = amscr.contour_from_mask(touching)  # the iso-line closes at the image's edge
    assert c[:, 0].min() == -0.5 and c[:, 1].min() == -0.5


def test_points_text_roundtrip(tmp_path):
    pts = blob(37) * 1e3
    p = tmp_path / 'shape.txt'
    amscr.write_points(p, pts)
    np.testing.assert_array_equal(amscr.read_points(p), pts)
    np.testing.assert_array_equal(amscr.read_points(str(p)), pts)
    np.testing.assert_array_equal(amscr.parse_points('# c\n1 2\n3,4\n\n5\t6\n'), [[1, 2], [3, 4], [5, 6]])
    # a byte order mark (Excel's and Notepad's exports) is skipped, as str and as a file
    np.testing.assert_array_equal(amscr.parse_points('\ufeff1 2\r\n3 4\r\n'), [[1, 2], [3, 4]])
    (tmp_path / 'bom.csv').write_bytes(b'\xef\xbb\xbf5,6\r\n7,8\r\n')
    np.testing.assert_array_equal(amscr.read_points(tmp_path / 'bom.csv'), [[5, 6], [7, 8]])


@pytest.fixture
def comma_locale(tmp_path):
    """A folder for LOCPATH holding de_DE.UTF-8, whose decimal point is ','."""
    built = os.environ.get('AMSCR_TEST_LOCPATH')  # tests/meson.build compiles it
    if built:
        return built
    localedef = shutil.which('localedef')
    if not localedef or not os.path.isfile('/usr/share/i18n/locales/de_DE'):
        pytest.skip('no locale with a decimal comma can be built (Debian: apt-get install locales)')
    subprocess.run([localedef, '-i', 'de_DE', '-f', 'UTF-8', str(tmp_path / 'de_DE.UTF-8')], check=True)
    return str(tmp_path)


def test_points_text_in_a_comma_locale(tmp_path, comma_locale):
    # A program that set a German locale (locale.setlocale(locale.LC_ALL, '') in a German session)
    # still reads and writes point lists with '.', and keeps its locale.
    script = """
import locale, sys
import numpy as np
import amscr
locale.setlocale(locale.LC_ALL, 'de_DE.UTF-8')
assert locale.localeconv()['decimal_point'] == ','
path = sys.argv[1]
pts = amscr.parse_points('0 0\\n10.5 0\\n10.5, 10.25\\n-0.125 1e-3\\n')
np.testing.assert_array_equal(pts, [[0, 0], [10.5, 0], [10.5, 10.25], [-0.125, 1e-3]])
amscr.write_points(path, pts)
np.testing.assert_array_equal(amscr.read_points(path), pts)
assert locale.localeconv()['decimal_point'] == ','
print(locale.format_string('%.1f', 0.5))
"""
    path = tmp_path / 'pts.txt'
    env = dict(os.environ, LOCPATH=comma_locale)
    out = subprocess.run([sys.executable, '-c', script, str(path)], env=env, capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    assert out.stdout == '0,5\n'
    assert path.read_text() == '0 0\n10.5 0\n10.5 10.25\n-0.125 0.001\n'


def test_signed_area_and_orient():
    sq = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], float)
    assert amscr.signed_area(sq) == pytest.approx(1.0)
    assert amscr.signed_area(sq[::-1]) == pytest.approx(-1.0)
    np.testing.assert_array_equal(amscr.orient_ccw(sq), sq)
    assert amscr.signed_area(amscr.orient_ccw(sq[::-1])) == pytest.approx(1.0)


def test_rerank_diffusion_blocks():
    """Three separated classes: after re-ranking every same-class pair ranks before every other,
    and the result equals the C function's (deterministic)."""
    import amscr
    idx = np.arange(12)
    same = (idx[:, None] // 4) == (idx[None, :] // 4)
    D = np.where(same, 0.1 + 0.01 * np.abs(idx[:, None] - idx[None, :]),
                 5.0 + 0.1 * np.abs(idx[:, None] - idx[None, :]))
    np.fill_diagonal(D, 0.0)
    R = amscr.rerank_diffusion(D, k=2, iterations=10)
    assert R.shape == D.shape
    assert np.all(R[same] < 1.0) and np.all(R[~same] >= 1.0)
    np.testing.assert_array_equal(R, amscr.rerank_diffusion(D, k=2, iterations=10))
    with pytest.raises(ValueError):
        amscr.rerank_diffusion(D, k=0)
    with pytest.raises(ValueError):
        amscr.rerank_diffusion(D[:, :5])


@pytest.mark.parametrize('kw', [dict(k=2.7), dict(k='3'), dict(k=None), dict(k=-1), dict(k=2 ** 40),
                                dict(iterations=10.5), dict(iterations=-1), dict(iterations=2 ** 40)])
def test_rerank_diffusion_refuses_what_is_not_a_count(kw):
    """k and iterations are counts: a float is not truncated, a str not parsed, and a negative or
    too large one is the documented InvalidArgumentError (not cffi's OverflowError)."""
    D = np.abs(np.subtract.outer(np.arange(6.0), np.arange(6.0)))
    with pytest.raises(amscr.InvalidArgumentError):
        amscr.rerank_diffusion(D, **kw)
