"""Sub-pixel contours from Python: bool, uint8, uint16 and float arrays alike; subpixel=False
gives the chain of pixel centres."""
import numpy as np
import pytest

import amscr


def _rect(dtype, fg):
    m = np.zeros((30, 40), dtype)
    m[6:23, 8:32] = fg
    return m


@pytest.mark.parametrize("dtype,fg", [(bool, True), (np.uint8, 255), (np.uint16, 65535), (np.float64, 1.0),
                                      (np.float32, 7.5), (np.int32, 255), (np.float16, 1.0),
                                      (np.uint8, 1), (np.uint16, 1), (np.int64, 1)])
def test_every_dtype_gives_the_same_binary_contour(dtype, fg):
    c = amscr.contour_from_mask(_rect(dtype, fg), threshold='auto' if dtype == np.float32 else None)
    assert c.min(axis=0).tolist() == [7.5, 5.5] and c.max(axis=0).tolist() == [31.5, 22.5]
    assert amscr.signed_area(c) == pytest.approx(24 * 17 - 0.5)


@pytest.mark.parametrize("dtype", [np.uint8, np.int64])
def test_a_zero_one_mask_is_traced_by_default_and_a_dark_one_says_what_to_pass(dtype):
    """0/1 integer masks (mask.astype(np.uint8)) are traced at 0.5 unless a threshold is given,
    either polarity, by both tracers; an image whose values stay under the threshold names its
    brightest value."""
    inverted = 1 - _rect(dtype, 1)
    c = amscr.contour_from_mask(inverted)
    assert c.min(axis=0).tolist() == [7.5, 5.5] and c.max(axis=0).tolist() == [31.5, 22.5]
    assert [x.area for x in amscr.contours_from_mask(_rect(dtype, 1), subpixel=False)] == [24 * 17 - 24 - 17 + 1]
    with pytest.raises(amscr.NotFoundError, match=r"threshold 127 \(the brightest is 1\): pass a threshold below 1"):
        amscr.contour_from_mask(_rect(dtype, 1), threshold=127)
    for f in (amscr.contour_from_mask, amscr.contours_from_mask):
        with pytest.raises(amscr.NotFoundError, match=r"the brightest is 100\): pass a threshold below 100"):
            f(_rect(dtype, 100))
        assert len(f(_rect(dtype, 100), threshold=99)) > 0
    with pytest.raises(amscr.NotFoundError, match="no foreground"):  # black: the library's own message
        amscr.contour_from_mask(np.zeros((8, 8), dtype))


def test_a_bool_mask_is_its_true_pixels_also_on_the_border():
    """True is the foreground of a bool mask even where it covers most of the image border (an
    integer image's automatic polarity would trace the False pixels instead); the points stay in
    the mask's frame."""
    m = np.zeros((80, 120), bool)
    m[:, 10:] = True  # a tight crop: the object touches three sides
    c = amscr.contour_from_mask(m)
    assert amscr.signed_area(c) == pytest.approx(m.sum() - 0.5)
    assert c.min(axis=0).tolist() == [9.5, -0.5] and c.max(axis=0).tolist() == [119.5, 79.5]
    assert amscr.signed_area(amscr.contour_from_mask(m.astype(np.uint8) * 255)) < 1000  # swapped: the strip
    chain = amscr.contour_from_mask(m, subpixel=False)
    assert chain.min(axis=0).tolist() == [10, 0] and chain.max(axis=0).tolist() == [119, 79]
    assert [c.area for c in amscr.contours_from_mask(m)] == [m.sum() - 0.5]
    for t in (0, 127, 'auto'):  # a threshold changes nothing on a bool mask
        np.testing.assert_array_equal(amscr.contour_from_mask(m, threshold=t), c)
    full = amscr.contour_from_mask(np.ones((20, 30), bool))  # every pixel: the frame
    assert amscr.signed_area(full) == pytest.approx(20 * 30 - 0.5)


def test_a_bool_mask_within_the_limits_is_traced():
    """A bool mask at the image limits (32768 wide, or 2^28 pixels) is traced as its uint8 copy:
    it is framed with False only when True covers most of its border (the frame took it past
    the limits, a LimitError naming a size the caller never gave); one that needs the frame
    and has no room for it says so in its own size."""
    m = np.zeros((3, 32768), bool)  # AMSCR_MAX_IMAGE_SIDE
    m[1, 5:40] = True
    np.testing.assert_array_equal(amscr.contour_from_mask(m), amscr.contour_from_mask(m.view(np.uint8)))
    assert [c.area for c in amscr.contours_from_mask(m, min_area=0)] == [34.5]
    with pytest.raises(amscr.LimitError, match=r"^mask: a 32768 x 3 bool mask True over most of its border"):
        amscr.contour_from_mask(~m)


@pytest.mark.parametrize("make", [lambda m: m.astype(np.float32), lambda m: m.astype(np.float64) / 255 * 7.5,
                                  lambda m: m.astype(np.uint16), lambda m: m.astype(np.int32)])
def test_an_8_bit_mask_in_another_dtype_is_traced_as_the_8_bit_one(make):
    """img.astype(np.float32) of a 0/255 mask is traced halfway, as the uint8 mask (not at 0.5, half
    a pixel out); so is a float mask of any largest value, and a uint16 0/255 mask (a 16-bit level
    of 32767 would find nothing)."""
    m = _rect(np.uint8, 255)
    np.testing.assert_allclose(amscr.contour_from_mask(make(m)), amscr.contour_from_mask(m), atol=1e-6)


@pytest.mark.parametrize("dtype", ['>u2', '>i4', '>f8'])
def test_a_big_endian_image_is_traced_as_the_native_one(dtype):
    """A big-endian image ('>u2', as FITS or a raw big-endian file gives it) is its native dtype:
    a uint16 one takes the 16-bit thresholds."""
    def trace(m, t):
        try:
            return amscr.contour_from_mask(m, threshold=t)
        except amscr.AmscrError as e:
            return type(e), str(e)

    for fg, thresholds in ((200, (None, 100, 300, 'auto')), (1000, (None, 500, 'auto'))):
        m = _rect(np.dtype(dtype).newbyteorder('='), fg)
        for t in thresholds:
            want, got = trace(m, t), trace(m.astype(dtype), t)
            assert type(got) is type(want)
            if isinstance(want, tuple):
                assert got == want
            else:
                np.testing.assert_array_equal(got, want)


def test_subpixel_false_is_the_pixel_chain():
    m = _rect(np.uint8, 255)
    chain = amscr.contour_from_mask(m, subpixel=False)
    assert chain.min(axis=0).tolist() == [8, 6] and chain.max(axis=0).tolist() == [31, 22]
    assert np.all(chain == np.round(chain))


def test_float_and_uint16_edges_are_interpolated():
    m = np.zeros((30, 40))
    m[5:25, 5:20] = 1.0
    m[5:25, 20] = 0.75  # the iso-line at 0.5 lies between columns 20 and 21
    c = amscr.contour_from_mask(m)
    right = c[(c[:, 1] > 8) & (c[:, 1] < 20), 0].max()
    assert right == pytest.approx(20 + (0.75 - 0.5) / 0.75, abs=1e-4)
    c16 = amscr.contour_from_mask((m * 65535).round().astype(np.uint16))
    assert c16[(c16[:, 1] > 8) & (c16[:, 1] < 20), 0].max() == pytest.approx(right, abs=1e-4)


def test_contours_from_mask_float_hierarchy():
    m = np.zeros((40, 50), np.float32)
    m[4:36, 4:36] = 1
    m[10:30, 10:30] = 0
    cs = amscr.contours_from_mask(m, min_area=0)
    assert [(c.parent, c.is_hole, c.area) for c in cs] == [(None, False, 1023.5), (0, True, 399.5)]
    chain = amscr.contours_from_mask(m, min_area=0, subpixel=False)
    assert [c.area for c in chain] == [961.0, 361.0]


def test_bad_float_and_threshold():
    with pytest.raises(amscr.InvalidArgumentError):
        amscr.contour_from_mask(np.full((8, 8), np.nan))
    with pytest.raises(amscr.InvalidArgumentError):
        amscr.contour_from_mask(np.zeros((8, 8)) + np.eye(8), threshold=5.0)
    with pytest.raises(amscr.InvalidArgumentError):
        amscr.contour_from_mask(np.zeros((8, 8), np.uint16), threshold=65535)


@pytest.mark.parametrize('lo,hi,what', [(0.1, 0.4, 'no foreground'), (0.6, 0.9, 'foreground everywhere'),
                                        (150.0, 200.0, 'foreground everywhere'), (1.0, 1.0, 'foreground everywhere'),
                                        (0.0, 0.0, 'no foreground')])
def test_float_image_the_default_level_misses_is_not_found(lo, hi, what):
    """A float image all of whose values lie on one side of the default level (a dim 0..1 image,
    a constant one) has no foreground, or foreground everywhere: NotFoundError, as for an
    integer image, not an InvalidArgumentError about a threshold nobody passed."""
    m = np.full((30, 40), lo)
    m[6:23, 8:32] = hi
    for trace in (amscr.contour_from_mask, amscr.contours_from_mask):
        with pytest.raises(amscr.NotFoundError, match=what):
            trace(m)
    if lo < hi:  # the image's own split traces the rectangle
        assert amscr.contour_from_mask(m, threshold='auto').max(axis=0).tolist() == [31.5, 22.5]


def test_join_registers_a_shape_cut_in_two():
    """join=True: a bar cut in two by an occluder is one outline holding both pieces; registered
    against the whole bar (shifted) it gives the map back, where the largest piece alone
    cannot (it lacks a third of the boundary)."""
    whole = np.zeros((60, 100), np.uint8)
    whole[20:32, 10:80] = 255
    whole[14:38, 70:80] = 255  # a T, so the map is determined
    cut = np.roll(whole, (3, 5), axis=(0, 1)).copy()
    cut[:, 38:44] = 0  # the occluder severs the bar
    alone, joined = amscr.contour_from_mask(cut), amscr.contour_from_mask(cut, join=True)
    assert amscr.signed_area(joined) == pytest.approx(
        amscr.signed_area(alone) + amscr.signed_area(amscr.contour_from_mask(cut[:, :40])))
    assert joined[:, 0].min() == pytest.approx(14.5) and alone[:, 0].min() > 40
    src = amscr.contour_from_mask(whole)
    r = amscr.register(src, joined)
    assert np.allclose(r.A, np.eye(2), atol=0.02) and np.allclose(r.B, [5, 3], atol=0.3)
    # pixel chain: the flag has no effect
    assert np.array_equal(amscr.contour_from_mask(cut, subpixel=False, join=True),
                          amscr.contour_from_mask(cut, subpixel=False))
