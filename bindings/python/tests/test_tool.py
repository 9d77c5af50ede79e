"""The distance matrix from Python equals the `amscr matrix` tool's (build/tools/amscr)."""
import os
import struct
import subprocess
import zlib

import numpy as np
import pytest

import amscr
from conftest import BUILD_DIR, REPO_ROOT
from helpers import affine, blob

TOOL = os.environ.get('AMSCR_TOOL') or os.path.join(BUILD_DIR, 'tools', 'amscr')
DATASETS = os.environ.get('AMSCR_DATASETS') or os.path.join(REPO_ROOT, '..', 'shared', 'datasets')

pytestmark = pytest.mark.skipif(not os.access(TOOL, os.X_OK),
                                reason='the amscr tool is not built (%s); build it with meson compile -C build' % TOOL)


def _tool(*args):
    r = subprocess.run([TOOL, *args], capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, 'amscr %s failed: %s' % (' '.join(args), r.stderr)
    return r


def test_matrix_of_point_files_equals_tool(tmp_path):
    rng = np.random.default_rng(3)
    folder = tmp_path / 'shapes'
    folder.mkdir()
    for c in range(3):
        base = blob(250, seed=40 + c)
        for i in range(3):
            pts = affine(base, np.eye(2) + 0.3 * rng.normal(size=(2, 2)), rng.normal(size=2))
            amscr.write_points(folder / ('class%d-%d.txt' % (c, i + 1)), pts)
    out = tmp_path / 'D.npy'
    # the tool's retrieval defaults are the retrieval preset; the paper's plain matrix first
    _tool('matrix', str(folder), '-o', str(out), '--points', '64', '--threads', '2', '--paper')
    D_tool = np.load(out)
    names = sorted(os.listdir(folder), key=os.fsencode)  # the tool sorts by byte order
    db = amscr.Collection(points=64, reflections=True)  # reflections: on by default in `amscr matrix`
    for n in names:
        db.add(amscr.read_points(folder / n), label=n.split('-')[0])
    D = db.distance_matrix()
    assert D_tool.shape == D.shape == (9, 9)
    np.testing.assert_array_equal(D, D_tool)
    # the tool's text output agrees too (to its printed precision)
    tsv = _tool('matrix', str(folder), '-o', '-', '--points', '64', '--invariance', 'affine', '--no-rerank', '--refine',
                '0', '--channel-weight', '0').stdout
    rows = [list(map(float, line.split('\t'))) for line in tsv.splitlines() if line and not line.startswith('#')]
    np.testing.assert_allclose(np.array(rows), D, rtol=1e-9, atol=1e-12)
    # and the tool's defaults are the retrieval preset (Collection.retrieval_matrix)
    out2 = tmp_path / 'D2.npy'
    _tool('matrix', str(folder), '-o', str(out2), '--points', '64')
    dbs = amscr.Collection(amscr.Params.retrieval(points=64))
    for n in names:
        dbs.add(amscr.read_points(folder / n), label=n.split('-')[0])
    np.testing.assert_array_equal(dbs.retrieval_matrix(), np.load(out2))


def _read_png_gray8(path):
    """Minimal PNG reader for 8-bit grayscale, non-interlaced images (the datasets' format)."""
    with open(path, 'rb') as f:
        data = f.read()
    if data[:8] != b'\x89PNG\r\n\x1a\n':
        return None
    pos, idat, hdr = 8, [], None
    while pos < len(data):
        n, = struct.unpack('>I', data[pos:pos + 4])
        typ, body = data[pos + 4:pos + 8], data[pos + 8:pos + 8 + n]
        pos += 12 + n
        if typ == b'IHDR':
            hdr = struct.unpack('>IIBBBBB', body)
        elif typ == b'IDAT':
            idat.append(body)
    w, h, depth, ctype, _, _, interlace = hdr
    if depth != 8 or ctype != 0 or interlace != 0:
        return None
    raw = zlib.decompress(b''.join(idat))
    img = np.zeros((h, w), dtype=np.int32)
    prev = np.zeros(w, dtype=np.int32)
    stride = w + 1
    for y in range(h):
        ftype = raw[y * stride]
        line = np.frombuffer(raw, dtype=np.uint8, count=w, offset=y * stride + 1).astype(np.int32)
        cur = np.zeros(w, dtype=np.int32)
        for x in range(w):
            a = cur[x - 1] if x else 0
            b = prev[x]
            c = prev[x - 1] if x else 0
            if ftype == 0:
                p = 0
            elif ftype == 1:
                p = a
            elif ftype == 2:
                p = b
            elif ftype == 3:
                p = (a + b) // 2
            else:
                pa, pb, pc = abs(b - c), abs(a - c), abs(a + b - 2 * c)
                p = a if pa <= pb and pa <= pc else (b if pb <= pc else c)
            cur[x] = (line[x] + p) & 0xFF
        img[y] = cur
        prev = cur
    return img.astype(np.uint8)


def test_matrix_of_images_equals_tool(tmp_path):
    folder = os.path.join(DATASETS, 'kimia99')
    if not os.path.isdir(folder):
        pytest.skip('datasets not found (%s)' % folder)
    files = sorted(f for f in os.listdir(folder) if f.endswith('.png'))
    pick = [f for f in files if f.split('-')[0] in ('fish', 'rabbit', 'hand')][:12]
    imgs = [_read_png_gray8(os.path.join(folder, f)) for f in pick]
    if len(pick) < 6 or any(i is None for i in imgs):
        pytest.skip('images are not 8-bit grayscale PNGs this test can decode')
    manifest = tmp_path / 'manifest.tsv'
    manifest.write_text('file\tclass\n' + ''.join('%s\t%s\n' % (os.path.join(os.path.abspath(folder), f),
                                                                 f.split('-')[0]) for f in pick))
    out = tmp_path / 'D.npy'
    _tool('matrix', str(manifest), '-o', str(out), '--points', '64', '--paper')
    D_tool = np.load(out)
    db = amscr.Collection(points=64, reflections=True)
    for f, img in zip(pick, imgs):
        db.add(amscr.contour_from_mask(img), label=f.split('-')[0])  # threshold 127 as the tool
    np.testing.assert_array_equal(db.distance_matrix(), D_tool)
