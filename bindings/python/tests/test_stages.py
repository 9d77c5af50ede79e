"""Registration.stages (which stages of the pipeline ran, in order), Params.stages (the optional
stages' switches) and Registration.alternatives (the distinct maps that fit about as well)."""
import copy
import pickle

import numpy as np
import pytest

import amscr

PIPELINE = ['despike', 'search', 'method', 'recovery', 'final_solve', 'symmetric', 'polish', 'order',
            'even_spacing', 'alternatives', 'correspondences', 'pixel_grid']
A = np.array([[1.3, 0.4], [-0.2, 0.9]])
B = np.array([3.0, 1.0])


def outline(vertices, n):
    v = np.asarray(vertices, float)
    per = n // len(v)
    t = np.arange(per)[:, None] / per
    return np.vstack([v[i] + t * (v[(i + 1) % len(v)] - v[i]) for i in range(len(v))])


SQUARE = [[0, 0], [1, 0], [1, 1], [0, 1]]
CROSS = [[1, 0], [2, 0], [2, 1], [3, 1], [3, 2], [2, 2], [2, 3], [1, 3], [1, 2], [0, 2], [0, 1], [1, 1]]
TRIANGLE = [[0, 0], [1, 0], [0.5, np.sqrt(3) / 2]]
ELL = [[0, 0], [3, 0], [3, 1], [1, 1], [1, 2.5], [0, 2.5]]
# a regular 5-pointed star: points at radius 1, notches at 0.4
STAR5 = [[(1.0 if i % 2 == 0 else 0.4) * np.cos(np.pi / 2 + np.pi * i / 5),
          (1.0 if i % 2 == 0 else 0.4) * np.sin(np.pi / 2 + np.pi * i / 5)] for i in range(10)]


def pair(vertices, n=480):
    src = outline(vertices, n)
    return src, src @ A.T + B


def test_stages_dict_in_pipeline_order():
    r = amscr.register(*pair(ELL))
    assert list(r.stages) == PIPELINE
    assert all(isinstance(v, bool) for v in r.stages.values())
    assert r.stages['search'] and r.stages['polish'] and r.stages['correspondences']
    assert not r.stages['symmetric'] and not r.stages['recovery']
    assert amscr.register(*pair(ELL), symmetric=True).stages['symmetric']


def test_params_stages_switch():
    p = amscr.Params.registration()
    assert set(p.stages) == set(amscr.params.SWITCHABLE_STAGES)
    p.stages = {'polish': False}
    assert p.stages['polish'] is False and p.stages['recovery'] is True  # the others unchanged
    assert p.polish  # the polish option is its own switch
    q = pickle.loads(pickle.dumps(p))
    assert q == p and q.stages == p.stages
    assert p != amscr.Params.registration()
    r = amscr.register(*pair(ELL), params=p)
    assert not r.stages['polish']
    on = amscr.register(*pair(ELL), stages={'polish': True})
    assert on.stages['polish'] and not np.array_equal(on.A, r.A)


@pytest.mark.parametrize('bad', [{'search': False}, {'nonsense': True}])
def test_params_stages_refused(bad):
    with pytest.raises(amscr.InvalidArgumentError):
        amscr.Params(stages=bad)


def test_params_stages_type():
    with pytest.raises(TypeError):
        amscr.Params(stages=['polish'])


def check_alternatives(r, vertices, count):
    """Exactly `count` distinct maps (each symmetry of the polygon once), about equal costs."""
    alts = r.alternatives
    assert len(alts) == count
    assert np.array_equal(alts[0].A, r.A) and np.array_equal(alts[0].B, r.B)
    assert r.confidence <= 0.25 and r.ambiguity >= 0.75
    v = np.asarray(vertices, float)
    tv = v @ A.T + B
    for alt in alts:
        assert isinstance(alt, amscr.Alternative) and alt.A.shape == (2, 2) and alt.B.shape == (2,)
        w = v @ alt.A.T + alt.B
        gap = np.min(np.linalg.norm(w[:, None] - tv[None], axis=2), axis=1).max()
        assert gap < 0.02  # every vertex onto a target vertex: a symmetry
        assert (alts[0].cost + 1e-9) / (alt.cost + 1e-9) >= 0.75
    images = [v @ a.A.T + a.B for a in alts]
    for i in range(len(images)):
        for j in range(i):
            assert np.abs(images[i] - images[j]).max() > 0.1  # distinct


@pytest.mark.parametrize('name,vertices,count', [('square', SQUARE, 4), ('cross', CROSS, 4), ('triangle', TRIANGLE, 3),
                                                  ('star', STAR5, 5)])
def test_symmetric_shapes_list_alternatives(name, vertices, count):
    check_alternatives(amscr.register(*pair(vertices, n=480 if name != 'star' else 500)), vertices, count)


@pytest.mark.parametrize('name,vertices,count', [('square', SQUARE, 8), ('triangle', TRIANGLE, 6)])
def test_symmetric_shapes_list_mirror_maps_with_reflections(name, vertices, count):
    check_alternatives(amscr.register(*pair(vertices), reflections=True), vertices, count)


def test_asymmetric_shape_lists_the_chosen_map_only():
    r = amscr.register(*pair(ELL))
    assert len(r.alternatives) == 1
    assert np.array_equal(r.alternatives[0].A, r.A)
    assert np.isfinite(r.alternatives[0].cost) and r.confidence > 0.9


def test_no_ranking_without_refinement():
    r = amscr.register(*pair(SQUARE), refine=0)
    assert len(r.alternatives) == 1 and np.isnan(r.alternatives[0].cost)


def test_registration_stages_and_alternatives_cannot_be_changed():
    """A Registration is read-only: stages a read-only mapping, alternatives a tuple, before and
    after pickling and copying."""
    r = amscr.register(*pair(ELL))
    for r2 in (r, pickle.loads(pickle.dumps(r)), copy.deepcopy(r)):
        with pytest.raises(TypeError):
            r2.stages['polish'] = False
        assert isinstance(r2.alternatives, tuple)
        assert r2.stages == r.stages and list(r2.stages) == PIPELINE and dict(r2.stages) == dict(r.stages)
        assert len(r2.alternatives) == len(r.alternatives) == 1
        np.testing.assert_array_equal(r2.alternatives[0].A, r.A)
        assert repr(r2) == repr(r)
