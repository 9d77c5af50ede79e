"""Bad inputs raise the right exception types, with the C library's message."""
import errno
import os

import numpy as np
import pytest

import amscr
from helpers import blob

GOOD = blob(100)


@pytest.mark.parametrize('bad', [
    np.zeros((10, 3)),  # wrong shape
    np.zeros(10),  # 1-D
    np.zeros((0, 2)),  # empty
    [[0, 0], [1, 2, 3]],  # ragged
    [['a', 'b'], ['c', 'd']],  # not numbers
    np.array([[0, 0], [1, np.nan]] * 8),  # NaN
    np.array([[0, 0], [np.inf, 1]] * 8),  # inf
    np.ones((10, 2), dtype=bool),  # bool
    np.ones((10, 2), dtype=complex),  # complex
])
def test_bad_points_raise_value_error(bad):
    for fn in (lambda p: amscr.register(p, GOOD), lambda p: amscr.register(GOOD, p), amscr.Shape,
               lambda p: amscr.smooth(p, 1.0), lambda p: amscr.Collection().add(p)):
        with pytest.raises(ValueError) as ei:
            fn(bad)
        assert isinstance(ei.value, amscr.InvalidArgumentError)
        assert ei.value.status == amscr.errors.lib.AMSCR_E_INVALID_ARG


def test_messages_are_clear():
    with pytest.raises(ValueError, match=r'shape \(n, 2\).*got shape \(10, 3\)'):
        amscr.Shape(np.zeros((10, 3)))
    with pytest.raises(ValueError, match=r'point 1 is not finite'):
        amscr.smooth([[0, 0], [np.nan, 0]], 1.0)
    with pytest.raises(ValueError, match=r"method: expected one of 'acma'"):
        amscr.register(GOOD, GOOD, method='nope')


def test_degenerate_contours():
    with pytest.raises(amscr.DegenerateError) as ei:
        amscr.register([[0, 0], [1, 0], [1, 1]], GOOD)
    assert isinstance(ei.value, ValueError) and ei.value.detail
    line = np.column_stack([np.arange(30.0), 2 * np.arange(30.0)])
    with pytest.raises(amscr.DegenerateError):
        amscr.Shape(line)
    with pytest.raises(amscr.DegenerateError):
        amscr.validate_contour(line)


def test_c_side_option_errors_carry_the_detail():
    with pytest.raises(amscr.InvalidArgumentError) as ei:
        amscr.Params(points=3)
    e = ei.value
    assert e.status == amscr.errors.lib.AMSCR_E_INVALID_ARG
    assert e.detail and e.detail in str(e) and str(e).startswith('invalid argument')
    with pytest.raises(amscr.InvalidArgumentError):
        amscr.Params(scales=[1.0, -2.0])
    with pytest.raises(amscr.InvalidArgumentError):
        amscr.Params(kmax=0)
    with pytest.raises(ValueError):
        amscr.Params(closed='yes')
    with pytest.raises(TypeError, match='unknown amscr option'):
        amscr.Params(pionts=10)
    with pytest.raises(TypeError):
        amscr.register(GOOD, GOOD, colour='red')


def test_mask_errors():
    with pytest.raises(ValueError):
        amscr.contour_from_mask(np.zeros((3, 3, 3), np.uint8))
    with pytest.raises(amscr.NotFoundError):  # float images are accepted; this one is blank
        amscr.contour_from_mask(np.zeros((8, 8), np.float64))
    with pytest.raises(ValueError):
        amscr.contour_from_mask(np.full((8, 8), 70000, np.int32))
    with pytest.raises(ValueError):
        amscr.contour_from_mask(np.zeros((8, 8), np.complex128))
    with pytest.raises(amscr.NotFoundError):
        amscr.contour_from_mask(np.zeros((8, 8), bool))
    with pytest.raises(amscr.InvalidArgumentError):
        amscr.contour_from_mask(np.zeros((8, 8), np.uint8), threshold=255)


def test_file_errors(tmp_path):
    with pytest.raises(amscr.FileError) as ei:
        amscr.read_points(tmp_path / 'missing.txt')
    assert isinstance(ei.value, OSError)
    p = tmp_path / 'bad.txt'
    p.write_text('1 2\n3 4\nfive 6\n')
    with pytest.raises(amscr.FormatError, match='bad.txt:3'):
        amscr.read_points(p)
    with pytest.raises(amscr.FormatError):
        amscr.parse_points('')
    with pytest.raises(amscr.FileError):
        amscr.write_points(tmp_path / 'no' / 'such' / 'dir.txt', GOOD)


def test_numeric_and_state_errors():
    with pytest.raises(amscr.InvalidArgumentError):
        amscr.kmeans([1.0, 2.0], 3)  # n < k
    with pytest.raises(amscr.StateError):
        amscr.GMM1D(2).means
    import pickle  # a fitted model cannot be set from its parameters: a TypeError saying what to send
    with pytest.raises(TypeError, match='fit it again'):
        pickle.dumps(amscr.GMM1D(2).fit([0.0, 0.1, 0.2, 5.0, 5.1, 5.2]))
    with pytest.raises(amscr.InvalidArgumentError):
        amscr.gaussian_kernel(-1.0)
    with pytest.raises(amscr.InvalidArgumentError):
        amscr.bayes_threshold(0.5, 0, -1, 0.5, 1, 1)
    with pytest.raises(ValueError):
        amscr.lstsq(np.ones((3, 2)), np.ones(4))
    with pytest.raises(ValueError):
        amscr.bullseye(np.zeros((3, 4)), [0, 0, 1])
    with pytest.raises(ValueError):
        amscr.bullseye(np.zeros((3, 3)), [0, 0])


def test_error_detail_is_per_thread():
    """A failure in one thread does not change the message another thread reports."""
    import threading
    errs = {}

    def fail(name, fn):
        try:
            for _ in range(200):
                try:
                    fn()
                except amscr.AmscrError as e:
                    errs.setdefault(name, set()).add(e.detail)
        except Exception as e:  # pragma: no cover
            errs[name] = e

    t1 = threading.Thread(target=fail, args=('a', lambda: amscr.Params(points=3)))
    t2 = threading.Thread(target=fail, args=('b', lambda: amscr.gaussian_kernel(-1.0)))
    t1.start(), t2.start()
    t1.join(), t2.join()
    assert len(errs['a']) == 1 and len(errs['b']) == 1 and errs['a'] != errs['b']


def test_file_errors_are_the_builtin_os_errors(tmp_path):
    """A missing file is a FileNotFoundError (and a FileError) with its errno; a folder an
    IsADirectoryError; every face's reader alike."""
    missing = str(tmp_path / 'missing.txt')
    for read in (amscr.read_points, amscr.Collection.load, amscr.Index.load):
        with pytest.raises(FileNotFoundError) as e:
            read(missing)
        assert isinstance(e.value, amscr.FileError) and e.value.errno == errno.ENOENT
        assert e.value.strerror == os.strerror(errno.ENOENT) and missing in str(e.value)
    with pytest.raises(IsADirectoryError):
        amscr.read_points(str(tmp_path))


def test_a_path_holding_a_nul_character_is_refused(tmp_path):
    """The library takes a C string, which a NUL character would cut short (x\\0.txt written as x):
    every face refuses it, as open() does; a path of another type is a TypeError naming `path`."""
    db = amscr.Collection(amscr.Params.retrieval(points=64))
    db.extend([GOOD, GOOD * [2, 1], GOOD[::-1] * [1, 3]])
    index = amscr.Index(db)
    amscr.write_points(tmp_path / 'x', GOOD)
    for path in (str(tmp_path / 'x\0.txt'), os.fsencode(tmp_path / 'x\0.txt'), tmp_path / 'x\0.txt'):
        for call in (lambda p: amscr.write_points(p, GOOD), db.save, index.save, amscr.read_points,
                     amscr.Collection.load, amscr.Index.load):
            with pytest.raises(amscr.InvalidArgumentError, match=r'^path: embedded null byte$'):
                call(path)
    assert os.listdir(tmp_path) == ['x']
    assert np.array_equal(amscr.read_points(os.fsencode(tmp_path / 'x')), amscr.read_points(tmp_path / 'x'))
    for read in (amscr.read_points, amscr.Collection.load, amscr.Index.load):
        with pytest.raises(TypeError, match=r'^path: expected a str, bytes or os\.PathLike path, got None$'):
            read(None)


@pytest.mark.parametrize('text', [5, 10 ** 6, None, 1.5, ['1 2']])
def test_parse_points_refuses_what_is_no_text(text):
    """parse_points takes str or bytes: an int is not bytes(n) (n NUL bytes, a FormatError or a
    huge allocation), None or a list is the same TypeError, not cffi's."""
    with pytest.raises(TypeError, match='text: expected the text of a point list'):
        amscr.parse_points(text)


def test_parse_points_takes_text_not_a_path(tmp_path):
    """A path given to parse_points (bytes(path) would be parsed as the text) says to use read_points."""
    p = tmp_path / 'c.txt'
    amscr.write_points(p, GOOD)
    with pytest.raises(TypeError, match=r'^text: expected the text of a point list \(str or bytes\), got a '
                                        r'pathlib\.\w+: read a file with amscr\.read_points\(path\)$'):
        amscr.parse_points(p)
    text = p.read_text()
    np.testing.assert_array_equal(amscr.parse_points(text), amscr.read_points(p))
    np.testing.assert_array_equal(amscr.parse_points(text.encode()), amscr.read_points(p))


def test_option_errors_name_the_python_option():
    with pytest.raises(amscr.InvalidArgumentError, match=r'^invalid argument: points: 3 is not in 16\.\.65536$'):
        amscr.Params(points=3)
    with pytest.raises(amscr.InvalidArgumentError,
                       match=r'^invalid argument: channel_weight: 1\.5 is not in \[0, 1\]$'):
        amscr.Params(channel_weight=1.5)


def test_messages_name_the_python_call_and_option():
    """Errors the library reports under its C names say the Python ones."""
    with pytest.raises(amscr.InvalidArgumentError, match=r'^invalid argument: scales: 0 scales \(1\.\.64 allowed\)$'):
        amscr.Params(scales=[])
    with pytest.raises(amscr.InvalidArgumentError, match=r"^invalid argument: stages: 'search' is not a switchable"):
        amscr.Params(stages={'search': True})
    with pytest.raises(amscr.InvalidArgumentError, match=r'^invalid argument: topk: k = 10 > 3 candidates$'):
        amscr.topk(np.arange(3.0), 10)
    with pytest.raises(amscr.FormatError, match=r'not an amscr index \(bad magic\)$'):
        amscr.Index.from_bytes(b'')
    db = amscr.Collection(amscr.Params.retrieval(points=64))
    db.extend([GOOD, GOOD * [2, 1], GOOD[::-1] * [1, 3]])
    index = amscr.Index(db)
    with pytest.raises(amscr.InvalidArgumentError, match=r'^invalid argument: Index\.add: the shape was prepared '
                                                         r'with another value of points than the index'):
        index.add(amscr.Shape(GOOD, amscr.Params.retrieval(points=128)))
    with pytest.raises(amscr.InvalidArgumentError, match='another value of presmooth than'):
        index.add(amscr.Shape(GOOD, amscr.Params.retrieval(points=64, presmooth=0.02)))
