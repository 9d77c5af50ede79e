"""Points as Python users have them: OpenCV contours ((n, 1, 2) int32, x-y) and scikit-image
contours ((row, col) floats, order='rc'); r.matrix goes straight into cv2.warpAffine and
skimage.transform.AffineTransform. The tests with OpenCV / scikit-image skip when those are absent."""
import os

import numpy as np
import pytest

import amscr
from conftest import REPO_ROOT
from helpers import A_TRUE, B_TRUE, affine, blob

EXAMPLES = os.path.join(REPO_ROOT, 'examples')
PAIR = [os.path.join(EXAMPLES, 'pair-%s.png' % w) for w in ('source', 'target')]
needs_pair = pytest.mark.skipif(not all(os.path.exists(p) for p in PAIR),
                                reason='the repository examples/pair-*.png are not here')


def _pair_xy():
    src = blob(300, seed=11)
    return src, affine(src, A_TRUE, B_TRUE)


def _opencv_like(xy):
    """What cv2.findContours gives: (n, 1, 2) int32 of (x, y) pixel coordinates."""
    return np.round(xy * 40 + 200).astype(np.int32).reshape(-1, 1, 2)


def _iou(a, b):
    a, b = np.asarray(a, dtype=bool), np.asarray(b, dtype=bool)
    return (a & b).sum() / (a | b).sum()


# -- without OpenCV / scikit-image ------------------------------------------------------------
def test_matrix_is_homogeneous_3x3():
    src, tgt = _pair_xy()
    r = amscr.register(src, tgt)
    assert r.matrix.shape == (3, 3)
    assert np.array_equal(r.matrix[2], [0.0, 0.0, 1.0])
    assert np.array_equal(r.matrix[:2, :2], r.A) and np.array_equal(r.matrix[:2, 2], r.B)
    homog = np.column_stack([src, np.ones(len(src))]) @ r.matrix.T
    assert np.allclose(homog[:, :2], r.apply(src)) and np.allclose(homog[:, 2], 1.0)
    assert r.apply(np.zeros((0, 2))).shape == (0, 2)  # no points: none mapped
    assert r.apply([]).shape == (0, 2) and amscr.affine_apply(r.matrix, []).shape == (0, 2)  # an empty list too
    assert np.allclose(r.matrix[:2], np.column_stack([A_TRUE, B_TRUE]), atol=1e-3)


def test_opencv_shaped_contours_are_accepted_everywhere():
    src, tgt = _pair_xy()
    cs, ct = _opencv_like(src), _opencv_like(tgt)
    flat_s, flat_t = cs[:, 0, :].astype(float), ct[:, 0, :].astype(float)
    assert np.array_equal(amscr.as_points(cs), flat_s)
    r, r_flat = amscr.register(cs, ct), amscr.register(flat_s, flat_t)
    assert np.array_equal(r.matrix, r_flat.matrix) and r.distance == r_flat.distance
    assert amscr.distance(cs, ct) == amscr.distance(flat_s, flat_t)
    assert np.array_equal(r.apply(cs), r.apply(flat_s))
    assert np.array_equal(amscr.Shape(cs).points, amscr.Shape(flat_s).points)
    db = amscr.Collection(points=64)
    db.extend([cs, ct])
    assert np.array_equal(db.query(cs), db.query(flat_s))
    assert amscr.signed_area(cs) == amscr.signed_area(flat_s)
    assert np.array_equal(amscr.smooth(cs, 2.0), amscr.smooth(flat_s, 2.0))
    assert np.array_equal(amscr.distance_matrix([cs, ct], points=64), db.distance_matrix())


BUILDING_BLOCKS = {
    'orient_ccw': amscr.orient_ccw, 'validate_contour': amscr.validate_contour,
    'resample_euclidean': lambda p: amscr.resample_euclidean(p, 40),
    'resample_affine': lambda p: amscr.resample_affine(p, 40),
    'affine_arclength': lambda p: amscr.affine_arclength(p)[0],
    'normalize_whiten': lambda p: amscr.normalize_whiten(p)[0],
    'affine_apply': lambda p: amscr.affine_apply(np.eye(3), p), 'affine_fit': lambda p: amscr.affine_fit(p, p)[0],
}


@pytest.mark.parametrize('name', sorted(BUILDING_BLOCKS))
def test_building_blocks_take_opencv_contours(name, tmp_path):
    c = _opencv_like(blob(120, seed=5))
    fn = BUILDING_BLOCKS[name]
    a, b = fn(c), fn(c[:, 0, :].astype(float))
    assert (a is None and b is None) or np.array_equal(a, b)
    amscr.write_points(tmp_path / 'c.txt', c)
    assert np.array_equal(amscr.read_points(tmp_path / 'c.txt'), c[:, 0, :])


def test_a_list_of_opencv_contours_is_refused_with_a_hint():
    c = _opencv_like(blob(50))
    with pytest.raises(amscr.InvalidArgumentError, match='OpenCV contours'):
        amscr.register((c,), c)
    with pytest.raises(amscr.InvalidArgumentError, match=r'got 2 arrays of different lengths \(a list of OpenCV '
                                                         r'contours\? pass one of them'):
        amscr.register([c, c[:30]], c)  # findContours' contours have different lengths
    with pytest.raises(amscr.InvalidArgumentError, match=r'\(n, 2\)'):
        amscr.register(np.zeros((5, 2, 2)), c)


def test_rc_order_is_the_swapped_xy():
    src, tgt = _pair_xy()
    src_rc, tgt_rc = src[:, ::-1].copy(), tgt[:, ::-1].copy()
    r, r_rc = amscr.register(src, tgt), amscr.register(src_rc, tgt_rc, order='rc')
    assert np.array_equal(r.matrix, r_rc.matrix) and r.distance == r_rc.distance
    assert np.array_equal(r_rc.apply(src_rc, order='rc'), r.apply(src)[:, ::-1])
    assert amscr.distance(src_rc, tgt_rc, order='rc') == amscr.distance(src, tgt)
    assert np.array_equal(amscr.as_points(src_rc, order='rc'), src)
    assert np.array_equal(amscr.Shape(src_rc, order='rc').points, amscr.Shape(src).points)
    db, db_rc = amscr.Collection(points=64), amscr.Collection(points=64)
    db.extend([src, tgt])
    db_rc.extend([src_rc, tgt_rc], order='rc')
    assert np.array_equal(db.distance_matrix(), db_rc.distance_matrix())
    assert np.array_equal(db.query(tgt), db_rc.query(tgt_rc, order='rc'))
    assert np.array_equal(amscr.distance_matrix([src_rc, tgt_rc], points=64, order='rc'), db.distance_matrix())


@pytest.mark.parametrize('order', ['yx', 'RC', None, 1])
def test_a_bad_order_is_refused(order):
    src, tgt = _pair_xy()
    with pytest.raises(amscr.InvalidArgumentError, match='order'):
        amscr.register(src, tgt, order=order)
    with pytest.raises(amscr.InvalidArgumentError, match='order'):
        amscr.as_points(src, order=order)


def _small_mask(seed):
    """A binary image of blob(seed) about 30 px across."""
    yy, xx = np.mgrid[0:40, 0:40]
    b = blob(400, seed=seed)
    ang = np.arctan2(yy - 20.0, xx - 20.0)
    r = np.interp(ang, np.arctan2(b[:, 1], b[:, 0]), np.hypot(b[:, 0], b[:, 1]), period=2 * np.pi)
    return (np.hypot(yy - 20.0, xx - 20.0) <= 13.0 * r).astype(np.uint8) * 255


def _compressed(chain):
    """The chain as OpenCV's CHAIN_APPROX_SIMPLE gives it: the points inside a straight run
    (the steps before and after equal) dropped; (n, 1, 2) int32."""
    c = np.asarray(chain, dtype=np.int32)
    d = np.diff(c, axis=0, append=c[:1])
    keep = np.any(d != np.roll(d, 1, axis=0), axis=1)
    keep[0] = True
    return c[keep].reshape(-1, 1, 2)


def test_a_compressed_opencv_chain_is_read_as_the_chain():
    """An OpenCV contour compressed by CHAIN_APPROX_SIMPLE registers, closed, exactly as the
    pixel chain it stands for (so a small image's chain is traced again: the pixel_grid stage);
    open, or where it is applied to points, it is taken as given."""
    src = amscr.contour_from_mask(_small_mask(1), join=True) * 6.0
    for seed in (2, 3):
        chain = amscr.contour_from_mask(_small_mask(seed), subpixel=False)
        full = chain.astype(np.int32).reshape(-1, 1, 2)
        simple = _compressed(chain)
        assert len(simple) < 0.75 * len(full)
        assert np.array_equal(amscr._util.expand_chain(simple[:, 0, :]), full[:, 0, :])
        r, r_full, r_given = (amscr.register(src, t) for t in (simple, full, simple[:, 0, :].astype(float)))
        assert np.array_equal(r.matrix, r_full.matrix) and r.stages['pixel_grid']
        assert not np.array_equal(r.matrix, r_given.matrix)
        assert r.apply(simple).shape == (len(simple), 2)
        assert np.array_equal(amscr.Shape(simple, closed=False).points,
                              amscr.Shape(simple[:, 0, :].astype(float), closed=False).points)
    # a step off the 8 grid directions: not a compressed chain, taken as given
    poly = np.array([[0, 0], [5, 1], [3, 4]], dtype=np.int32)
    assert amscr._util.expand_chain(poly) is poly
    # a chain longer than a contour may be: a clear error before it is made (it allocated 30 GiB)
    square = np.array([[0, 0], [10**9, 0], [10**9, 10**9], [0, 10**9]], dtype=np.int32).reshape(-1, 1, 2)
    with pytest.raises(amscr.InvalidArgumentError, match='pixel chain of 4000000000 points.*as floats'):
        amscr.Shape(square)
    with pytest.raises(amscr.DegenerateError, match='4 distinct points'):  # as floats: the 4 corners
        amscr.Shape(square.astype(float))


# -- with OpenCV ------------------------------------------------------------------------------
@needs_pair
@pytest.mark.parametrize('approx', ['CHAIN_APPROX_NONE', 'CHAIN_APPROX_SIMPLE'])
def test_opencv_contours_register_and_warp_the_mask(approx):
    cv2 = pytest.importorskip('cv2')
    src_img, tgt_img = (cv2.imread(p, cv2.IMREAD_GRAYSCALE) for p in PAIR)
    contours = []
    for img in (src_img, tgt_img):
        found = cv2.findContours((img > 127).astype(np.uint8), cv2.RETR_EXTERNAL, getattr(cv2, approx))[-2]
        contours.append(max(found, key=cv2.contourArea))
    assert contours[0].ndim == 3 and contours[0].shape[1:] == (1, 2)
    r = amscr.register(*contours)  # as cv2 gives them
    h, w = tgt_img.shape
    warped = cv2.warpAffine(src_img, r.matrix[:2], (w, h), flags=cv2.INTER_NEAREST)
    assert _iou(warped > 127, tgt_img > 127) > 0.95
    # the map of examples/README.md
    assert np.allclose(r.A, [[0.75, 0.35], [-0.2, 0.65]], atol=0.03)


# -- with scikit-image ------------------------------------------------------------------------
@needs_pair
def test_skimage_contours_register_and_warp_the_mask():
    pytest.importorskip('skimage')
    from skimage import io, measure, transform
    src_mask, tgt_mask = (io.imread(p) > 127 for p in PAIR)
    src_rc, tgt_rc = (max(measure.find_contours(m.astype(float), 0.5), key=len) for m in (src_mask, tgt_mask))
    r = amscr.register(src_rc, tgt_rc, order='rc')  # (row, col) -> x = col, y = row
    tform = transform.AffineTransform(matrix=r.matrix)
    warped = transform.warp(src_mask.astype(float), tform.inverse, output_shape=tgt_mask.shape, order=0)
    assert _iou(warped > 0.5, tgt_mask) > 0.95
    src_xy = src_rc[:, ::-1]  # skimage's transforms take (x, y) = (col, row), as amscr's maps
    assert np.allclose(tform(src_xy), r.apply(src_xy))
    assert np.allclose(r.apply(src_rc, order='rc'), r.apply(src_xy)[:, ::-1])
    # (row, col) taken as (x, y) gives a map in the transposed frame: wrong for skimage's (x, y)
    wrong = transform.AffineTransform(matrix=amscr.register(src_rc, tgt_rc).matrix)
    warped_wrong = transform.warp(src_mask.astype(float), wrong.inverse, output_shape=tgt_mask.shape, order=0)
    assert _iou(warped_wrong > 0.5, tgt_mask) < 0.8


def test_contours_from_mask_gives_the_hierarchy():
    # two squares, the left one with a square hole holding a small square component
    m = np.zeros((60, 100), np.uint8)
    m[5:55, 5:55] = 255
    m[15:45, 15:45] = 0
    m[25:35, 25:35] = 255
    m[10:40, 65:95] = 255
    cs = amscr.contours_from_mask(m, min_area=0)
    assert [(c.is_hole, c.parent) for c in cs] == [(False, None), (False, None), (True, 0), (False, 2)] or \
        [(c.is_hole, c.parent) for c in cs] == [(False, None), (True, 0), (False, None), (False, 1)]
    outer = [c for c in cs if not c.is_hole]
    holes = [c for c in cs if c.is_hole]
    assert len(outer) == 3 and len(holes) == 1
    for c in outer:
        assert amscr.signed_area(c.points) > 0 and c.area > 0
    assert amscr.signed_area(holes[0].points) < 0
    # the largest outer contour is what contour_from_mask gives
    big = max(outer, key=lambda c: c.area)
    np.testing.assert_array_equal(big.points, amscr.contour_from_mask(m))
    # min_area drops the small inner component only
    assert len(amscr.contours_from_mask(m, min_area=200)) == 3


def test_contours_from_mask_bad_input():
    with pytest.raises(amscr.NotFoundError):
        amscr.contours_from_mask(np.zeros((10, 10), np.uint8))
    with pytest.raises(amscr.InvalidArgumentError):
        amscr.contours_from_mask(np.zeros((10, 10), np.uint8), min_area=-1)
    with pytest.raises(amscr.InvalidArgumentError):
        amscr.contours_from_mask(np.zeros(10, np.uint8))


def test_an_image_contour_is_taken_wherever_points_are(tmp_path):
    """An ImageContour of contours_from_mask stands for its points."""
    c = amscr.contours_from_mask(_small_mask(1))[0]
    tgt = affine(c.points, A_TRUE, B_TRUE)
    r = amscr.register(c.points, tgt)
    for fn in list(BUILDING_BLOCKS.values()) + [
            amscr.as_points, amscr.signed_area, lambda p: amscr.smooth(p, 2.0), lambda p: amscr.Shape(p).points,
            lambda p: amscr.register(p, tgt).matrix, lambda p: amscr.distance(tgt, p), r.apply,
            lambda p: amscr.distance_matrix([p, tgt], points=64)]:
        a, b = fn(c), fn(c.points)
        assert (a is None and b is None) or np.array_equal(a, b)
    db = amscr.Collection(points=64)
    db.add(c)
    db.extend([c, tgt])
    assert np.array_equal(db.query(c), db.query(c.points)) and db.query(c)[:2].tolist() == [0.0, 0.0]
    amscr.write_points(tmp_path / 'c.txt', c)
    assert np.array_equal(amscr.read_points(tmp_path / 'c.txt'), c.points)


# -- NumPy masked arrays and object arrays -----------------------------------------------------
def test_masked_values_are_refused_wherever_points_or_masks_are_taken():
    """A numpy.ma array's masked values would be used as they are (an outlier hidden by the mask
    registered): refused, with what to pass instead; nothing masked: its data."""
    src, tgt = _pair_xy()
    m = np.ma.masked_array(src.copy())
    m[0] = np.ma.masked
    r = amscr.register(src, tgt)
    db = amscr.Collection(amscr.Params.retrieval(points=64))
    db.extend([src, tgt])
    index = amscr.Index(db)
    for take in (lambda p: amscr.register(p, tgt), lambda p: amscr.register(src, p), amscr.Shape, db.add,
                 lambda p: db.extend([src, p]), db.query, index.query, index.find_member, r.apply,
                 amscr.as_points, amscr.signed_area):
        with pytest.raises(ValueError, match=r'masked values are not accepted.*points\[~points\.mask\.any'):
            take(m)
    mask = np.zeros((20, 20), np.uint8)
    mask[5:15, 4:16] = 255
    for trace in (amscr.contour_from_mask, amscr.contours_from_mask):
        with pytest.raises(ValueError, match=r'mask: masked values are not accepted.*mask\.filled\(0\)'):
            trace(np.ma.masked_array(mask, mask=mask == 0))
    np.testing.assert_array_equal(amscr.register(np.ma.masked_array(src), tgt).matrix, r.matrix)
    np.testing.assert_array_equal(amscr.contour_from_mask(np.ma.masked_array(mask)), amscr.contour_from_mask(mask))


def test_object_arrays_are_refused_with_how_to_convert_them():
    """A pandas nullable Float64 frame is an object array to NumPy: the message says to convert it."""
    src, _ = _pair_xy()
    with pytest.raises(ValueError, match=r'dtype object: convert it first, e\.g\. df\.to_numpy\(float\)'):
        amscr.Shape(src.astype(object))


class _LinearRing:
    """What a shapely LineString or LinearRing is to NumPy: one object, its points behind .coords."""
    coords = property(lambda self: [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 0.0)])


class _Polygon:
    """What a shapely Polygon is to NumPy: one object, its points behind .exterior.coords."""
    exterior = property(lambda self: _LinearRing())


def test_objects_that_are_no_arrays_are_named():
    """None, a dict, a shapely geometry are named (not taken for a pandas frame); a geometry's
    message says how to take its points, where points and where a mask are expected."""
    src, _ = _pair_xy()
    geometries = [_Polygon(), _LinearRing()]
    try:
        import shapely.geometry as sg
        if not hasattr(sg.LineString, '__array_interface__'):  # shapely 2: no geometry is an array
            geometries += [sg.Polygon(src), sg.LineString(src), sg.LinearRing(src)]
    except ImportError:
        pass
    for g in geometries:
        with pytest.raises(ValueError, match=r'^src: expected an array of real numbers, got a \w+\.\w+: pass its '
                                             r'points, np\.asarray\(poly\.exterior\.coords\) of a Polygon, '
                                             r'np\.asarray\(line\.coords\) of a LineString'):
            amscr.register(g, src)
        with pytest.raises(ValueError, match=r'^mask: expected a 2-D bool, integer or float array, got a \w+\.\w+: '
                                             r'it is a contour already, pass its points where amscr takes points, '
                                             r'np\.asarray\(poly\.exterior\.coords\)'):
            amscr.contour_from_mask(g)
    for x, what in ((None, 'None'), ({'x': 1}, 'a dict')):
        with pytest.raises(amscr.InvalidArgumentError,
                           match=r'^points: expected an array of real numbers, got %s$' % what):
            amscr.as_points(x)
        with pytest.raises(amscr.InvalidArgumentError, match=r'^mask: expected a 2-D bool, integer or float array, '
                                                             r'got %s$' % what):
            amscr.contours_from_mask(x)
