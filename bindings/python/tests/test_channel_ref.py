"""The shape channel (docs/method.md §10.2) against an independent NumPy reference
(ref_channel.py, written from the definition), and each channel setting shown to move the
distance the way its definition says."""
import numpy as np
import pytest

import amscr
import ref_channel
from helpers import affine, blob


def limbed(seed, n=300, bend=0.0):
    """A body with three thin limbs; `bend` swings the first limb (articulation)."""
    rng = np.random.default_rng(seed)
    t = np.linspace(0.0, 2.0 * np.pi, n, endpoint=False)
    r = 1 + 0.2 * np.cos(3 * t + rng.uniform(0, 2 * np.pi)) + 0.08 * np.sin(5 * t)
    for k in range(3):
        at = rng.uniform(0, 2 * np.pi) + (bend if k == 0 else 0.0)
        r = r + rng.uniform(0.8, 1.5) * np.exp(rng.uniform(60, 120) * (np.cos(t - at) - 1))
    return np.column_stack([r * np.cos(t), r * np.sin(t)])


SHEAR = np.array([[1.4, 0.6], [-0.1, 0.7]])  # not a similarity: aspect and shear change


def shapes():
    """Prepared shapes (retrieval preset, N = 128): two different blobs, a limbed body, the same
    body with a limb swung, affine / similarity / mirror images of the body from the same start
    point (the same samples up to the map), and a rotated copy from another start point."""
    p = amscr.Params.retrieval()
    body = limbed(3)
    rot = np.array([[np.cos(0.7), -np.sin(0.7)], [np.sin(0.7), np.cos(0.7)]]) * 2.5
    pts = {
        'blob1': blob(400, seed=1), 'blob2': blob(350, seed=2), 'body': body, 'bent': limbed(3, bend=0.5),
        'sheared': affine(body, SHEAR, [4, -1]),
        'rotated': affine(body, rot, [-3, 2]),
        'mirrored': np.roll(body[::-1], 1, axis=0) * [-1, 1],  # starts at body[0], goes the other way
        'rolled': affine(np.roll(body, 60, axis=0), rot, [-3, 2]),
    }
    return {k: amscr.Shape(v, p) for k, v in pts.items()}


@pytest.fixture(scope='module')
def S():
    return shapes()


def lib(S, a, b, **opts):
    return amscr.channel_distance(S[a], S[b], params=amscr.Params.retrieval(**opts))


def ref(S, a, b, exact=False, **opts):
    names = {'channel_band': 'band', 'channel_affine_band': 'affine_band', 'channel_skip': 'skip', 'channel_locality': 'locality',
             'channel_affine_share': 'affine_share', 'channel_invariance': 'invariance',
             'reflections': 'reflections', 'channel_affine_view': 'affine_view'}
    return ref_channel.channel_distance(S[a].input_points, S[b].input_points,
                                        exact=exact, **{names[k]: v for k, v in opts.items()})


CASES = [
    ('blob1', 'blob2', {}),
    ('body', 'bent', {}),
    ('body', 'sheared', {}),
    ('blob1', 'body', {'channel_affine_share': 0.0}),
    ('body', 'bent', {'channel_band': 0.03, 'channel_skip': 2.5}),
    ('blob2', 'bent', {'channel_locality': 0.0, 'channel_invariance': 'affine'}),
    ('body', 'rolled', {'channel_affine_share': 0.5, 'channel_band': 0.08}),
    ('body', 'bent', {'channel_affine_share': 0.5, 'channel_affine_band': 0.2}),
    ('blob1', 'mirrored', {'reflections': False}),
    ('body', 'sheared', {'channel_affine_view': 0.0}),
    ('body', 'sheared', {'channel_affine_view': 1.0}),
    ('body', 'bent', {'channel_affine_view': 1.0}),
]


def test_affine_view_takes_the_sheared_pair_by_the_affine_frame(S):
    """The sheared copy is nearer in the whitened frame by more than the preset's factor: the
    rule ranks it there (below the mix); the bent copy keeps the mix."""
    assert lib(S, 'body', 'sheared') < lib(S, 'body', 'sheared', channel_affine_view=0.0)
    assert lib(S, 'body', 'bent') == lib(S, 'body', 'bent', channel_affine_view=0.0)


@pytest.mark.parametrize('a,b,opts', CASES)
def test_library_matches_the_reference(S, a, b, opts):
    """Measured: every case agrees to the last bit or within 1e-15 (distances are multiples of
    1 / (16 N) mixed by the shares)."""
    d_lib, d_ref = lib(S, a, b, **opts), ref(S, a, b, **opts)
    assert d_lib == pytest.approx(d_ref, abs=1e-9, rel=0), (a, b, opts, d_lib, d_ref)


def test_library_rule_is_a_path_never_below_the_exact_minimum(S):
    """The library's one-pass rule (each cell keeps its cheapest way in and that way's start)
    costs a real path, so it is never below the exact minimum over start and end; measured on
    blob1 / body, similarity frame: 3.92041015625 against the exact 3.91796875 (5 units of
    1 / (16 N)), the other cases of CASES equal."""
    opts = {'channel_affine_share': 0.0}
    d_lib, d_exact = lib(S, 'blob1', 'body', **opts), ref(S, 'blob1', 'body', exact=True, **opts)
    assert d_exact <= d_lib <= d_exact + 10.0 / (16 * S['body'].num_samples), (d_exact, d_lib)


def test_identity_is_zero(S):
    assert lib(S, 'body', 'body') == 0.0
    assert ref(S, 'body', 'body') == 0.0


def test_wider_band_never_costs_more(S):
    """A wider band admits every path of a narrower one: the distance cannot grow, and on an
    articulated pair it falls."""
    ds = [lib(S, 'body', 'bent', channel_band=b) for b in (0.01, 0.04, 0.08, 0.2)]
    assert all(x >= y for x, y in zip(ds, ds[1:])), ds
    assert ds[0] > ds[-1], ds


def test_larger_skip_never_costs_less(S):
    """Every path's cost grows with the skip cost: the distance cannot fall, and the articulated
    pair (which needs skips) pays more."""
    ds = [lib(S, 'body', 'bent', channel_skip=s) for s in (0.0, 0.5, 1.0, 4.0)]
    assert all(x <= y for x, y in zip(ds, ds[1:])), ds
    assert ds[0] < ds[-1], ds


def test_locality_discounts_far_parts(S):
    """A larger locality shrinks the weight of far bins (1 / (1 + locality t)): heights move
    towards 0 and two different shapes come closer."""
    ds = [lib(S, 'blob1', 'body', channel_locality=x, channel_affine_share=0.0) for x in (0.0, 4.0, 16.0)]
    assert ds[0] > ds[1] > ds[2], ds


def test_affine_share_mixes_the_two_frames(S):
    """Without the affine-view rule the distance is (1 - share) * similarity frame + share *
    affine frame: on a sheared copy the affine frame sees (almost) nothing, so a larger share
    lowers the distance."""
    sim = lib(S, 'body', 'sheared', channel_affine_share=0.0)
    aff = lib(S, 'body', 'sheared', channel_invariance='affine')
    for share in (0.2, 0.5):
        mixed = lib(S, 'body', 'sheared', channel_affine_share=share, channel_affine_view=0.0)
        assert mixed == pytest.approx((1 - share) * sim + share * aff, rel=1e-12, abs=1e-15)
    assert aff < 0.1 * sim, (aff, sim)
    assert lib(S, 'body', 'sheared', channel_affine_share=0.5, channel_affine_view=0.0) < \
        lib(S, 'body', 'sheared', channel_affine_share=0.2, channel_affine_view=0.0)


def test_invariance_frames(S):
    """The affine frame is invariant to affine maps, the similarity frame only to similarities.
    Measured: the sheared copy in the affine frame and the rotated copy in both give exactly 0
    (same start point: the samples are the same up to the map), the sheared copy in the
    similarity frame 2.26 (4638 units of 1 / (16 N))."""
    unit = 1.0 / (16 * S['body'].num_samples)
    assert lib(S, 'body', 'sheared', channel_invariance='affine') == 0.0
    assert lib(S, 'body', 'rotated', channel_affine_share=0.0) == 0.0
    assert lib(S, 'body', 'rotated', channel_invariance='affine') == 0.0
    assert lib(S, 'body', 'sheared', channel_affine_share=0.0) > 400 * unit


def test_another_start_point_is_nearly_free(S):
    """A new start point samples the curve at other places: measured 0.086 for the rotated body
    started 60 input points later, against 2.08 between blob1 and blob2 (4 %)."""
    assert lib(S, 'body', 'rolled') < 0.1 * lib(S, 'blob1', 'blob2')


def test_reflections_setting(S):
    """With reflections the mirror image (same start point) is the same shape; without, it is
    as far as another shape. Measured: 0 and 2.39."""
    assert lib(S, 'body', 'mirrored') == 0.0
    assert lib(S, 'body', 'mirrored', reflections=False) > 1.0
