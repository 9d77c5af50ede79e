"""Params: every option of the table reads back what was set, through the C getter and setter."""
import pickle

import numpy as np
import pytest

import amscr

# one value per option that differs from both presets (amscr_params_new, amscr_params_new_registration)
CHANGED = {
    'points': 96, 'scales': [0.5, 2.0, 5.0], 'method': 'binary-em', 'closed': False, 'reflections': True,
    'parametrization': 'affine', 'presmooth': 0.02, 'arclength_passes': 2, 'oversampling': 4, 'kmax': 7,
    'symmetric': True, 'refine': 3, 'threads': 2, 'invariance': 'penalized', 'penalty': 0.25,
    'partial': True, 'channel_weight': 0.5, 'channel_invariance': 'affine', 'channel_affine_share': 0.5,
    'channel_band': 0.2, 'channel_affine_band': 0.1, 'channel_skip': 0.5, 'channel_locality': 8.0, 'rerank_k': 3, 'rerank_iterations': 4,
    'rerank_inner_share': 0.125, 'inner_closing': 0.25, 'channel_affine_view': 3.5, 'polish': True,
    'stages': {'despike': True, 'recovery': False, 'polish': False, 'order': True, 'even_spacing': True,
               'pixel_grid': False},
}
# the presets disagree on these flags: each preset gets the other value
FLIPPED = {'polish'}
# one value per option that the setter refuses (by Python-side validation or the C range check)
REFUSED = {
    'points': 8, 'scales': [[1.0]], 'method': 'nearest', 'closed': 2, 'reflections': 'yes',
    'parametrization': 'polar', 'presmooth': 0.5, 'arclength_passes': 0, 'oversampling': 65, 'kmax': 17,
    'symmetric': None, 'refine': 51, 'threads': -1, 'invariance': 'projective', 'penalty': -1.0,
    'partial': 2, 'channel_weight': 1.5, 'channel_invariance': 'penalized', 'channel_affine_share': -0.1,
    'channel_band': 0.0, 'channel_affine_band': 0.6, 'channel_skip': -1.0, 'channel_locality': -1.0, 'rerank_k': 1001, 'rerank_iterations': 0,
    'rerank_inner_share': 1.0, 'inner_closing': 1.5, 'channel_affine_view': 0.5, 'polish': 2, 'stages': {'search': False},
}


def test_the_table_covers_every_option():
    assert set(CHANGED) == set(amscr.Params.OPTIONS) == set(REFUSED)
    assert amscr.Params.OPTIONS[:3] == ('points', 'scales', 'method')


@pytest.mark.parametrize('name', amscr.Params.OPTIONS)
def test_each_option_round_trips_alone(name):
    for preset in (amscr.Params(), amscr.Params.registration()):
        before = preset.to_dict()
        value = (not before[name]) if name in FLIPPED else CHANGED[name]
        setattr(preset, name, value)
        after = preset.to_dict()
        np.testing.assert_array_equal(after[name], value)
        assert not np.array_equal(before[name], after[name])
        assert {k: v for k, v in after.items() if k not in (name, 'scales')} == \
               {k: v for k, v in before.items() if k not in (name, 'scales')}
        if name != 'scales':
            np.testing.assert_array_equal(after['scales'], before['scales'])


@pytest.mark.parametrize('name', amscr.Params.OPTIONS)
def test_each_option_refuses_a_bad_value(name):
    p = amscr.Params()
    before = p.to_dict()
    with pytest.raises((amscr.InvalidArgumentError, TypeError)):
        setattr(p, name, REFUSED[name])
    np.testing.assert_array_equal(p.to_dict()[name], before[name])


def test_types_of_the_values():
    d = amscr.Params(**CHANGED).to_dict()
    kinds = {'points': int, 'method': str, 'closed': bool, 'reflections': bool, 'parametrization': str,
             'presmooth': float, 'arclength_passes': int, 'oversampling': int, 'kmax': int,
             'symmetric': bool, 'refine': int, 'threads': int, 'invariance': str, 'penalty': float}
    for k, t in kinds.items():
        assert type(d[k]) is t, k
    assert d['scales'].dtype == np.float64 and d['scales'].ndim == 1


def test_all_options_at_once_and_back():
    p = amscr.Params(**CHANGED)
    for k, v in CHANGED.items():
        np.testing.assert_array_equal(getattr(p, k), v)
    assert amscr.Params(**p.to_dict()) == p
    assert pickle.loads(pickle.dumps(p)) == p
    assert eval(repr(p), {'Params': amscr.Params}) == p


def test_aliases_and_unknown_names():
    p = amscr.Params(num_samples=64, num_threads=3)
    assert p.points == 64 and p.threads == 3
    with pytest.raises(TypeError, match='unknown amscr option'):
        amscr.Params(sample_count=64)


def test_docstrings_come_from_the_table():
    doc = amscr.Params.__doc__
    for name in amscr.Params.OPTIONS:
        option = vars(amscr.Params)[name]
        assert doc.count('``%s``' % name) == 1
        assert option.__doc__ and option.__doc__ in doc


def test_a_pickle_of_amscr_0_1_loads():
    # pickle.dumps(amscr.Params(points=96, method='acma', scales=[0.5, 2]), protocol=0) by amscr 0.1
    old = (b'camscr\n_params_from_dict\np0\n((dp1\nVpoints\np2\nI96\nsVscales\np3\n(lp4\nF0.5\naF2.0\nasV'
           b'method\np5\nVacma\np6\nsVclosed\np7\nI01\nsVreflections\np8\nI00\nsVparametrization\np9\nV'
           b'whitened\np10\nsVpresmooth\np11\nF0.01\nsVarclength_passes\np12\nI3\nsVoversampling\np13\nI8\n'
           b'sVkmax\np14\nI5\nsVsymmetric\np15\nI00\nsVrefine\np16\nI0\nsVthreads\np17\nI0\nsVinvariance\n'
           b'p18\nVaffine\np19\nsVpenalty\np20\nF0.5\nstp21\nRp22\n.')
    assert pickle.loads(old) == amscr.Params(points=96, method='acma', scales=[0.5, 2])


FLOATS = [k for k in amscr.Params.OPTIONS if isinstance(CHANGED[k], float)]


@pytest.mark.parametrize('name', FLOATS)
def test_float_options_refuse_str_and_bool(name):
    """As the integer options: a str or a bool is refused (TypeError, also an InvalidArgumentError),
    not converted; a NumPy number is taken."""
    for bad in (str(CHANGED[name]), True, np.bool_(False), b'0.1'):
        with pytest.raises(TypeError, match=r'^%s: expected a number, got ' % name):
            amscr.Params(**{name: bad})
        with pytest.raises(amscr.InvalidArgumentError):
            amscr.Params(**{name: bad})
    assert getattr(amscr.Params(**{name: np.float32(CHANGED[name])}), name) == np.float32(CHANGED[name])
    with pytest.raises(TypeError, match=r'^points: expected an integer, got 96\.0$'):
        amscr.Params(points=96.0)
