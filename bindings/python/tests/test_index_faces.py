"""One index file, three faces: an index made by `amscr index` or by `Index.save` gives the same
top 10 (same shapes, scores equal to 1e-9) through `amscr search --json` (the tool at
$AMSCR_TOOL, else this environment's `amscr`), `Index.query` and the C program
tests/index_top.c ($AMSCR_INDEX_TOP, else build/tests/index_top), every shape a candidate, for
affine-warped queries: on examples/collection always, on Kimia-216 and a fifth of mpeg7-dev when
the datasets are present (skipped visibly otherwise)."""
import json
import os
import shutil
import subprocess
import sys

import numpy as np
import pytest

import amscr

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.normpath(os.path.join(HERE, '..', '..', '..'))
DATASETS = os.environ.get('AMSCR_DATASETS') or os.path.join(REPO, '..', 'shared', 'datasets')
TOP = 10


def tool():
    t = os.environ.get('AMSCR_TOOL') or shutil.which('amscr', path=os.path.dirname(sys.executable))
    if not t or not os.path.exists(t):
        pytest.skip('the amscr tool was not found (set AMSCR_TOOL)')
    return t


def index_top():
    c = os.environ.get('AMSCR_INDEX_TOP') or os.path.join(REPO, 'build', 'tests', 'index_top')
    if not os.path.exists(c):
        pytest.skip('the C face tests/index_top was not built (meson compile -C build; or set AMSCR_INDEX_TOP)')
    return c


def run(*args):
    r = subprocess.run([str(a) for a in args], capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, r.stderr
    return r.stdout


def warp(points, rng):
    """A random affine map: a rotation, axis scales x0.6-1.6, shear +-0.4, a rotation, a shift."""
    def rot(a):
        return np.array([[np.cos(a), -np.sin(a)], [np.sin(a), np.cos(a)]])
    s = np.diag(np.exp(rng.uniform(np.log(0.6), np.log(1.6), 2)))
    h = np.array([[1.0, rng.uniform(-0.4, 0.4)], [0.0, 1.0]])
    A = rot(rng.uniform(0, 2 * np.pi)) @ s @ h @ rot(rng.uniform(0, 2 * np.pi))
    return np.asarray(points, dtype=float) @ A.T + rng.uniform(-5, 5, 2)


def faces(idx_path, qfile, q):
    """(indices, scores, files) of the top 10 through the tool, Python and C."""
    t = json.loads(run(tool(), 'search', qfile, idx_path, '--json', '--candidates', '0', '--top', TOP))['results']
    c = json.loads(run(index_top(), idx_path, qfile, 0, TOP))['results']
    index = amscr.Index.load(idx_path)
    pi, ps = index.query(q, top=TOP, candidates=0)
    names = index.names
    py = [{'index': int(i), 'distance': float(s), 'file': names[i]} for i, s in zip(pi, ps)]
    return {'tool': t, 'python': py, 'c': c}


def same(a, b, what):
    assert [r['index'] for r in a] == [r['index'] for r in b], what
    np.testing.assert_allclose([r['distance'] for r in a], [r['distance'] for r in b], rtol=0, atol=1e-9,
                               err_msg=what)


def check_collection(tmp_path, collection, queries=3, seed=0):
    """`amscr index` of `collection` (a folder or a manifest) and Index(its collection).save: the
    same top 10 through every face for `queries` affine-warped members."""
    by_tool = tmp_path / 'tool.idx'
    run(tool(), 'index', collection, '-o', by_tool)
    made = amscr.Index.load(by_tool)
    coll = made.collection
    by_python = tmp_path / 'python.idx'
    amscr.Index(coll).save(by_python)
    rng = np.random.default_rng(seed)
    n = len(coll)
    for k, t in enumerate(rng.choice(n, queries, replace=False)):
        q = warp(coll.shape(int(t)).input_points, rng)
        qfile = tmp_path / ('q%d.txt' % k)
        np.savetxt(qfile, q, fmt='%.17g')
        q = np.loadtxt(qfile)  # the points every face reads
        ref = None
        for path in (by_tool, by_python):
            got = faces(path, qfile, q)
            ref = ref or got['tool']
            for face, res in got.items():
                same(ref, res, '%s, query %d (shape %d): %s' % (path.name, k, t, face))
            if path == by_tool:  # the tool's index names its files in every face
                assert [r['file'] for r in got['tool']] == [r['file'] for r in got['python']] \
                    == [r['file'] for r in got['c']]
                assert all(r['file'] == made.names[r['index']] for r in got['tool'])


def test_examples_collection(tmp_path):
    check_collection(tmp_path, os.path.join(REPO, 'examples', 'collection'))


def dataset_manifest(tmp_path, name, step):
    folder = os.path.join(DATASETS, name)
    manifest = os.path.join(folder, 'manifest.tsv')
    if not os.path.exists(manifest):
        pytest.skip('%s not found (%s): the cross-face test runs on examples/collection only' % (name, folder))
    rows = [line.rstrip('\n').split('\t') for line in open(manifest) if line.strip()]
    sub = tmp_path / ('%s.tsv' % name)
    sub.write_text('file\tclass\n' + ''.join('%s\t%s\n' % (os.path.join(folder, f), c) for f, c in rows[1:][::step]))
    return sub


@pytest.mark.parametrize('name,step', [('kimia216', 1), ('mpeg7-dev', 5)])
def test_datasets(tmp_path, name, step):
    check_collection(tmp_path, dataset_manifest(tmp_path, name, step), queries=3, seed=216)


def member_faces(tmp_path, collection, files):
    """A member's file as the query (the member rule): `amscr search FILE` (the image itself and
    its traced points), `amscr search` on the folder or manifest, Index.query / Index.scores,
    Collection.query on the index's collection and the C face (amscr_index_search) give the
    member first at 0 and the same scores: its row of the collection's retrieval matrix."""
    idx_path = tmp_path / 'members.idx'
    run(tool(), 'index', collection, '-o', idx_path)
    index = amscr.Index.load(idx_path)
    coll = index.collection
    names = index.names
    n = len(index)
    assert coll.params.ranking == 'retrieval'
    for f in files:
        pts_file = tmp_path / (os.path.basename(f) + '.txt')
        run(tool(), 'contour', f, '-o', pts_file)
        q = np.loadtxt(pts_file)
        member = index.find_member(q)
        assert member is not None and names[member] == os.path.basename(f), f
        row = index.scores(q, candidates=0)
        assert row[member] == 0.0
        # the query calls score it as a new shape; the search applies the member rule
        new = np.zeros(n)
        from amscr._lib import lib, ffi
        assert lib.amscr_index_query_scores(index._x, amscr.Shape(q, coll.params)._d, 0,
                                            ffi.cast('double *', new.ctypes.data), n) == 0
        assert np.abs(new - row).max() > 1e-6, 'the member rule changed nothing: test the rule elsewhere'
        np.testing.assert_allclose(coll.query(q), row, rtol=0, atol=1e-12)
        pi, ps = index.query(q, top=TOP, candidates=0)
        assert pi[0] == member and ps[0] == 0.0
        py = [{'index': int(i), 'distance': float(s)} for i, s in zip(pi, ps)]
        for query in (f, pts_file):
            for target in (idx_path, collection):
                t = json.loads(run(tool(), 'search', query, target, '--json', '--candidates', '0',
                                   '--top', TOP))['results']
                same(py, t, 'tool search %s in %s' % (query, target))
        c = json.loads(run(index_top(), idx_path, pts_file, 0, TOP))['results']
        same(py, c, 'C face, %s' % f)


def test_member_query_examples(tmp_path):
    folder = os.path.join(REPO, 'examples', 'collection')
    files = sorted(os.path.join(folder, f) for f in os.listdir(folder) if f.endswith('.png'))
    member_faces(tmp_path, folder, files[::4])


def test_member_query_kimia216(tmp_path):
    folder = os.path.join(DATASETS, 'kimia216')
    if not os.path.isdir(folder):
        pytest.skip('kimia216 not found (%s): the member-query test runs on examples/collection only' % folder)
    member_faces(tmp_path, folder, [os.path.join(folder, f) for f in ('bird-1.png', 'Bone-7.png')])
