"""Bad input and bad usage: exit 1 (input/failure) or 2 (usage), exactly one line on stderr
naming the file, nothing on stdout, never a crash, no output file left behind."""
import os
import struct
import zlib

import pytest

from imgutil import (blank, have_png, pgm_bytes, png_bytes, png_header_only, png_short_claim, rect_mask, run,
                     run_peak_memory, smooth_shape, write_points)

GOOD_PNG = png_bytes(rect_mask(fg=255), 0, 8)


def check_fail(r, code, *needles):
    assert r.returncode == code, (r.returncode, r.stderr)
    assert r.returncode >= 0  # not killed by a signal
    lines = r.stderr.splitlines()
    assert len(lines) == 1, r.stderr
    assert lines[0].startswith("amscr: "), lines[0]
    for n in needles:
        assert str(n) in lines[0], (n, lines[0])
    assert r.stdout == ""


def corrupt_idat(data):
    """Replaces the IDAT payload with garbage that has a valid CRC."""
    i = data.index(b"IDAT") - 4
    n = struct.unpack(">I", data[i:i + 4])[0]
    payload = bytes((j * 37 + 11) & 0xFF for j in range(n))
    chunk = struct.pack(">I", n) + b"IDAT" + payload + struct.pack(">I", zlib.crc32(b"IDAT" + payload) & 0xFFFFFFFF)
    return data[:i] + chunk + data[i + 12 + n:]


BAD_FILES = {
    "empty.png": (b"", "empty"),
    "sig-only.png": (b"\x89PNG\r\n\x1a\n", "truncated"),
    "trunc.png": (GOOD_PNG[:len(GOOD_PNG) - 30], "PNG"),
    "trunc-ihdr.png": (GOOD_PNG[:20], "truncated"),
    "bad-crc.png": (GOOD_PNG[:29] + b"\x00\x00\x00\x00" + GOOD_PNG[33:], "corrupt PNG"),
    "bad-idat.png": (corrupt_idat(GOOD_PNG), "corrupt PNG"),
    "bad-depth.png": (png_header_only(10, 10, depth=3, color_type=0), "corrupt PNG"),
    "huge.png": (png_header_only(40000, 40000), "too large"),
    "huge-pixels.png": (png_header_only(20000, 20000), "too large"),
    "wide.png": (png_header_only(32769, 1), "too large"),
    "short-claim.png": (png_short_claim(32768, 8192), "truncated PNG: 32768 x 8192 pixels need at least"),
    "zero.png": (png_header_only(0, 10), "PNG"),
    "trunc.pgm": (pgm_bytes(rect_mask(fg=255))[:200], "truncated"),
    "trunc16.pgm": (pgm_bytes(rect_mask(fg=999), maxval=1000)[:-1], "truncated"),
    "trunc-header.pgm": (b"P5\n40 30\n", "truncated"),
    "bad-header.pgm": (b"P5\nabc 30\n255\n" + bytes(1200), "corrupt PGM"),
    "bad-maxval.pgm": (b"P5\n4 3\n70000\n" + bytes(24), "maxval"),
    "zero-maxval.pgm": (b"P5\n4 3\n0\n" + bytes(12), "maxval"),
    "zero-size.pgm": (b"P5\n0 3\n255\n", "PGM"),
    "over-maxval.pgm": (b"P2\n3 3\n10\n0 0 0\n0 11 0\n0 0 0\n", "exceeds maxval"),
    "trunc.p2.pgm": (b"P2\n3 3\n255\n0 0 0\n0 255\n", "truncated"),
    "garbage.p2.pgm": (b"P2\n3 3\n255\n0 0 0\n0 x 0\n0 0 0\n", "corrupt PGM"),
    "huge.pgm": (b"P5\n100000 10\n255\n", "too large"),
    "huge-pixels.pgm": (b"P5 30000 30000 255\n", "too large"),
    "huger.pgm": (b"P5 4000000000 30 255\n", "image too large: 4000000000 x 30 pixels"),
    "black.png": (png_bytes(blank(20, 20, 0), 0, 8), "no foreground"),
    "white.pgm": (pgm_bytes(blank(20, 20, 255)), "no foreground"),
    "transparent.png": (png_bytes([[(0, 0, 0, 0)] * 8] * 8, 6, 8), "no foreground"),
    "photo.jpg": (b"\xff\xd8\xff\xe0\x00\x10JFIF\x00" + bytes(100), "unsupported image format"),
    "pic.gif": (b"GIF89a" + bytes(100), "unsupported image format"),
    "color.ppm": (b"P6\n2 2\n255\n" + bytes(12), "unsupported image format"),
    "bad-line.txt": (b"1 2\n3 4\n5 six\n", "bad-line.txt:3"),
    "three-numbers.txt": (b"1 2 3\n", "three-numbers.txt:1"),
    "comments-only.txt": (b"# nothing here\n\n", "comments-only.txt"),
    "binary.dat": (bytes(range(1, 256)) * 4, "binary.dat"),
}


def png_huge_text_chunk():
    """A 16 x 12 gray image whose tEXt chunk claims 2 GB, in a file of a hundred bytes."""
    ihdr = struct.pack(">IIBBBBB", 16, 12, 8, 0, 0, 0, 0)
    ihdr_chunk = struct.pack(">I", 13) + b"IHDR" + ihdr + struct.pack(">I", zlib.crc32(b"IHDR" + ihdr))
    return b"\x89PNG\r\n\x1a\n" + ihdr_chunk + struct.pack(">I", 2054847098) + b"tEXtComment\0" + b"z" * 40


MEMORY_FILES = {
    "huge-text-chunk.png": (png_huge_text_chunk(), "truncated PNG"),
    "short-claim.png": (png_short_claim(32768, 8192), "truncated PNG"),
}


@pytest.mark.parametrize("name", sorted(MEMORY_FILES))
def test_memory_bounded_by_the_file(tmp_path, name):
    """A small PNG whose chunks or header claim gigabytes is refused without taking them
    (libpng allocates a chunk's claimed size; a claimed image is allocated before its data is read)."""
    if not have_png():
        pytest.skip("tool built without libpng")
    data, needle = MEMORY_FILES[name]
    p = tmp_path / name
    p.write_bytes(data)
    code, err, peak_kib = run_peak_memory("contour", p)
    assert code == 1 and needle in err, (code, err)
    assert peak_kib < 128 * 1024, f"{name}: {len(data)} bytes took {peak_kib / 1024:.0f} MiB"


@pytest.mark.parametrize("name", sorted(BAD_FILES))
def test_bad_file_contour(tmp_path, name):
    data, needle = BAD_FILES[name]
    if data.startswith(b"\x89PNG") and not have_png():
        needle = "without libpng"
    p = tmp_path / name
    p.write_bytes(data)
    out = tmp_path / "out.txt"
    r = run("contour", p, "-o", out)
    check_fail(r, 1, name, needle)
    assert sorted(os.listdir(tmp_path)) == [name]  # no output, no temporary left


@pytest.mark.parametrize("name", ["trunc.png", "huge.pgm", "black.png", "bad-line.txt", "empty.png"])
@pytest.mark.png
def test_bad_file_register_no_pictures(tmp_path, name):
    data, needle = BAD_FILES[name]
    bad = tmp_path / name
    bad.write_bytes(data)
    good = tmp_path / "good.png"
    good.write_bytes(GOOD_PNG)
    for args in ([bad, good], [good, bad]):
        r = run("register", *args, "--overlay", tmp_path / "o.png", "--plot", tmp_path / "p.svg", "--json")
        check_fail(r, 1, name, needle)
    assert sorted(os.listdir(tmp_path)) == sorted([name, "good.png"])


def test_missing_file(tmp_path):
    p = tmp_path / "nope.png"
    check_fail(run("contour", p), 1, "nope.png", "cannot open")
    check_fail(run("register", p, p), 1, "nope.png")


def test_a_long_path_keeps_its_reason(tmp_path):
    """An error line holds a long path whole and its reason after it (lines were cut at 1 KiB)."""
    p = tmp_path.joinpath(*["d" * 200] * 6) / "nope.png"
    r = run("contour", p)
    assert r.returncode == 1 and r.stderr.endswith("cannot open: No such file or directory\n"), r.stderr[-80:]
    assert str(p) in r.stderr


def test_directory_as_shape(tmp_path):
    check_fail(run("contour", tmp_path), 1, str(tmp_path), "directory")


def test_degenerate_point_list(tmp_path):
    src = tmp_path / "line.txt"
    src.write_text("0 0\n1 1\n2 2\n3 3\n4 4\n5 5\n6 6\n7 7\n8 8\n9 9\n")
    tgt = tmp_path / "shape.txt"
    write_points(tgt, smooth_shape(100))
    check_fail(run("register", src, tgt), 1, "line.txt")


def test_overlay_into_missing_folder(tmp_path):
    a = tmp_path / "a.txt"
    write_points(a, smooth_shape(100))
    r = run("register", a, a, "--overlay", tmp_path / "no" / "such" / "dir" / "o.svg")
    check_fail(r, 1, "o.svg")


USAGE = [
    [],
    ["frobnicate"],
    ["contour"],
    ["contour", "a.png", "b.png"],
    ["contour", "a.png", "--bogus"],
    ["contour", "a.png", "--threshold", "300"],
    ["contour", "a.png", "--threshold", "x"],
    ["contour", "a.png", "-o"],
    ["register", "a.png"],
    ["register", "a.png", "b.png", "--points", "abc"],
    ["register", "a.png", "b.png", "--points", "5"],
    ["register", "a.png", "b.png", "--points", "-3"],
    ["register", "a.png", "b.png", "--method", "foo"],
    ["register", "a.png", "b.png", "--scales", "1,a"],
    ["register", "a.png", "b.png", "--scales", ""],
    ["register", "a.png", "b.png", "--refine", "51"],
    ["register", "a.png", "b.png", "--threads", "x"],
    ["register", "a.png", "b.png", "--overlay", "o.gif"],
    ["register", "a.png", "b.png", "--plot", "p.png"],
    ["register", "a.png", "b.png", "--json=1"],
    ["contour", "a.png", "--help=foo"],
    ["register", "a.png", "b.png", "--top", "3"],
    ["search", "q.png"],
    ["search", "q.png", "dir", "--top", "0"],
    ["matrix", "dir"],
    ["matrix", "dir", "-o", "m.csv"],
    ["eval", "dir", "--protocol", "median"],
    ["eval", "dir", "--ranks", "0"],
]


@pytest.mark.parametrize("args", USAGE, ids=[" ".join(a) or "<none>" for a in USAGE])
def test_usage_errors(tmp_path, args):
    r = run(*args, cwd=tmp_path)
    assert r.returncode == 2, (r.returncode, r.stderr)
    assert "unknown option '--help'" not in r.stderr, r.stderr
    if args:
        lines = r.stderr.splitlines()
        assert len(lines) == 1 and lines[0].startswith("amscr: "), r.stderr
    assert r.stdout == ""
    assert os.listdir(tmp_path) == []


def test_bad_scales_value_rejected_by_library(tmp_path):
    a = tmp_path / "a.txt"
    write_points(a, smooth_shape(100))
    r = run("register", a, a, "--scales", "1,2,1e9")  # sigma > N
    assert r.returncode == 2, r.stderr
    assert len(r.stderr.splitlines()) == 1 and "--scales" in r.stderr


def test_help_and_version():
    r = run("--help")
    assert r.returncode == 0 and "register" in r.stdout and r.stderr == ""
    for cmd in ["contour", "register", "search", "matrix", "eval"]:
        r = run(cmd, "--help")
        assert r.returncode == 0 and ("amscr " + cmd) in r.stdout, cmd
    r = run("help", "frob")  # an unknown command's help is a usage error, not the main help
    assert r.returncode == 2 and r.stdout == "" and "unknown command 'frob'" in r.stderr
    r = run("--version")
    assert r.returncode == 0
    assert r.stdout.strip().count(".") == 2 and r.stdout.strip().replace(".", "").isdigit()


def _mutants(seed, data, count):
    import random
    rng = random.Random(seed)
    for _ in range(count):
        b = bytearray(data)
        kind = rng.randrange(3)
        if kind == 0:  # flip bytes
            for _ in range(rng.randint(1, 8)):
                b[rng.randrange(len(b))] = rng.randrange(256)
        elif kind == 1:  # truncate
            del b[rng.randrange(1, len(b)):]
        else:  # duplicate a slice
            i = rng.randrange(len(b))
            b[i:i] = b[i:i + rng.randint(1, 64)]
        yield bytes(b)


def _fuzz_sources():
    img = rect_mask(fg=255)
    pal = [(0, 0, 0), (255, 255, 255)]
    return {
        "gray.png": png_bytes(img, 0, 8),
        "adam7-rgba16.png": png_bytes([[(v * 257, 0, 0, 65535) for v in row] for row in img], 6, 16, interlace=True),
        "pal2.png": png_bytes(rect_mask(fg=1), 3, 2, palette=pal, trns=b"\x00"),
        "p5-16.pgm": pgm_bytes(rect_mask(fg=999), maxval=1000, comments=True),
        "p2.pgm": pgm_bytes(rect_mask(fg=7), maxval=7, ascii=True, comments=True),
    }


@pytest.mark.parametrize("name", sorted(_fuzz_sources()))
def test_mutated_files_never_crash(tmp_path, name):
    data = _fuzz_sources()[name]
    for k, mutant in enumerate(_mutants(zlib.crc32(name.encode()), data, 40)):
        p = tmp_path / ("m%d-%s" % (k, name))
        p.write_bytes(mutant)
        r = run("contour", p)
        assert r.returncode in (0, 1), (p, r.returncode, r.stderr)
        if r.returncode == 1:
            lines = r.stderr.splitlines()
            assert len(lines) == 1 and lines[0].startswith("amscr: ") and p.name in lines[0], r.stderr
        p.unlink()


@pytest.mark.parametrize("value", ["1000000,1000", "0", "5,0", "5,1001", "x"])
def test_rerank_range_is_stated(tmp_path, value):
    """--rerank's error states both ranges, K's upper limit included."""
    d = tmp_path / "set"
    d.mkdir()
    for k in range(3):
        write_points(d / ("s-%d.txt" % k), smooth_shape(seed=k))
    check_fail(run("eval", d, "--rerank", value), 2, "--rerank", "1 <= K <= 1000", "1 <= ITER <= 1000", value)


@pytest.mark.parametrize("args,needle", [
    (["eval", "dir", "--protocol", "split", "--train", "1", "--seed", " -1"], "--seed"),  # was 2^64 - 1
    (["search", "q.png", "dir", "--top", "+5"], "--top"),
    (["search", "q.png", "dir", "--top", " 5"], "--top"),
    (["search", "q.png", "dir", "--rerank", " 8"], "--rerank"),
    (["search", "q.png", "dir", "--rerank", "8, 9"], "--rerank"),
])
def test_integers_are_digits_only(tmp_path, args, needle):
    """An integer option takes digits alone: strtoull's leading blanks and sign are refused (a
    seed ' -1' was taken as 2^64 - 1)."""
    check_fail(run(*args, cwd=tmp_path), 2, needle, "got '%s'" % args[-1])
    assert os.listdir(tmp_path) == []


@pytest.mark.parametrize("args,needle", [
    (["contour", "a.png", "-o", ""], "-o"),
    (["contour", "a.png", "--output="], "--output"),
    (["index", "dir", "-o", ""], "-o"),
    (["matrix", "dir", "-o", "m.npy", "--names", ""], "--names"),
    (["contour", ""], "empty file name"),
    (["register", "a.png", ""], "empty file name"),
])
def test_empty_file_names_are_usage_errors(tmp_path, args, needle):
    """An empty file name is a usage error that says so, for every FILE argument (it was exit 1
    with a line naming no file, or 'input/output error')."""
    check_fail(run(*args, cwd=tmp_path), 2, needle)
    assert os.listdir(tmp_path) == []
