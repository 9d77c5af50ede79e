"""The evaluation protocols (amscr.per_class_scores, nn_random_split, nn_groups, precision_recall)
against slow NumPy references, and against the tool's `amscr eval --json` (build/tools/amscr)."""
import json
import os
import re
import subprocess

import numpy as np
import pytest

import amscr
from conftest import BUILD_DIR, REPO_ROOT

TOOL = os.environ.get('AMSCR_TOOL') or os.path.join(BUILD_DIR, 'tools', 'amscr')
DATASETS = os.environ.get('AMSCR_DATASETS') or os.path.join(REPO_ROOT, '..', 'shared', 'datasets')


# ---- slow references: every ranking is a stable sort of the row (ties to the lower index)

def ref_order(row, exclude=None):
    idx = [j for j in range(len(row)) if j != exclude]
    return sorted(idx, key=lambda j: (row[j], j))


def ref_per_class(D, lab):
    n = len(lab)
    classes = sorted(set(lab))
    size = {c: lab.count(c) for c in classes}
    be = {c: 0.0 for c in classes}
    nn = {c: 0.0 for c in classes}
    for i in range(n):
        c = lab[i]
        w = min(2 * size[c], n)
        be[c] += sum(lab[j] == c for j in ref_order(D[i])[:w])
        nn[c] += lab[ref_order(D[i], i)[0]] == c
    return ([be[c] / size[c] ** 2 for c in classes], [nn[c] / size[c] for c in classes])


def splitmix64(state):
    state = (state + 0x9E3779B97F4A7C15) & 0xFFFFFFFFFFFFFFFF
    z = state
    z = ((z ^ (z >> 30)) * 0xBF58476D1CE4E5B9) & 0xFFFFFFFFFFFFFFFF
    z = ((z ^ (z >> 27)) * 0x94D049BB133111EB) & 0xFFFFFFFFFFFFFFFF
    return state, z ^ (z >> 31)


def ref_nn_subset(D, lab, test, train):
    """{class: (tested, correct)} of the 1-NN of `test` among `train` (ties to the lower index)."""
    out = {}
    for i in test:
        best = min(train, key=lambda j: (D[i][j], j))
        t, c = out.get(lab[i], (0, 0))
        out[lab[i]] = (t + 1, c + (lab[best] == lab[i]))
    return out


def ref_split(D, lab, train, splits, seed):
    n, classes, state = len(lab), sorted(set(lab)), seed
    accs, cls = [], [0.0] * len(classes)
    for _ in range(splits):
        is_train = [False] * n
        for c in classes:
            members = [i for i in range(n) if lab[i] == c]
            for t in range(train):
                state, r = splitmix64(state)
                r = t + r % (len(members) - t)
                members[t], members[r] = members[r], members[t]
                is_train[members[t]] = True
        res = ref_nn_subset(D, lab, [i for i in range(n) if not is_train[i]], [i for i in range(n) if is_train[i]])
        accs.append(sum(c for _, c in res.values()) / sum(t for t, _ in res.values()))
        for k, c in enumerate(classes):
            cls[k] += res[c][1] / res[c][0] / splits
    return accs, cls


def ref_groups(D, lab, grp):
    n, classes, groups = len(lab), sorted(set(lab)), sorted(set(grp))
    ok = [False] * n
    for g in groups:
        train = [j for j in range(n) if grp[j] != g]
        for i in range(n):
            if grp[i] == g:
                best = min(train, key=lambda j: (D[i][j], j))
                ok[i] = lab[best] == lab[i]
    frac = lambda sel: sum(ok[i] for i in sel) / len(sel)  # noqa: E731
    return (sum(ok) / n, [frac([i for i in range(n) if grp[i] == g]) for g in groups],
            [frac([i for i in range(n) if lab[i] == c]) for c in classes])


def ref_pr(D, lab, levels):
    n, acc, queries = len(lab), [0.0] * levels, 0
    for i in range(n):
        relevant = lab.count(lab[i]) - 1
        if relevant == 0:
            continue
        best, hits = [0.0] * levels, 0
        for r, j in enumerate(ref_order(D[i], i)):
            if lab[j] != lab[i]:
                continue
            hits += 1
            rec, prec = hits / relevant, hits / (r + 1)
            for lv in range(levels):
                if lv / (levels - 1) <= rec + 1e-12 and prec > best[lv]:
                    best[lv] = prec
            if hits == relevant:
                break
        acc = [a + b for a, b in zip(acc, best)]
        queries += 1
    return [a / queries for a in acc]


def random_problem(seed, n=None, k=None):
    rng = np.random.default_rng(seed)
    n = n or int(rng.integers(8, 40))
    k = k or int(rng.integers(2, 5))
    lab = [int(x) for x in rng.permutation(np.arange(n) % k)]  # every class has n // k shapes or more
    D = np.floor(rng.uniform(0, 6, size=(n, n))) + np.array([[0.0 if a == b else 2.5 for b in lab] for a in lab])
    return D, lab


# ---- against the references

@pytest.mark.parametrize('seed', range(12))
def test_per_class_matches_reference(seed):
    D, lab = random_problem(seed)
    r = amscr.per_class_scores(D, lab)
    be, nn = ref_per_class(D.tolist(), lab)
    assert r.classes.tolist() == sorted(set(lab))
    assert r.sizes.tolist() == [lab.count(c) for c in sorted(set(lab))]
    np.testing.assert_array_equal(r.bullseye, be)
    np.testing.assert_array_equal(r.nn_accuracy, nn)
    s = r.sizes.astype(float)
    assert np.sum(r.bullseye * s ** 2) / np.sum(s ** 2) == pytest.approx(amscr.bullseye(D, lab), abs=1e-12)
    assert np.sum(r.nn_accuracy * s) / len(lab) == pytest.approx(amscr.nn_accuracy(D, lab), abs=1e-12)


@pytest.mark.parametrize('seed', range(12))
def test_split_matches_reference(seed):
    D, lab = random_problem(100 + seed)
    train = 1 + seed % (min(lab.count(c) for c in set(lab)) - 1)
    r = amscr.nn_random_split(D, lab, train, splits=4, seed=2 ** 63 + seed)
    accs, cls = ref_split(D.tolist(), lab, train, 4, 2 ** 63 + seed)
    np.testing.assert_array_equal(r.accuracies, accs)
    np.testing.assert_array_equal(r.class_accuracy, cls)
    assert r.mean == pytest.approx(np.mean(accs), abs=1e-15) and r.std == pytest.approx(np.std(accs, ddof=1))
    again = amscr.nn_random_split(D, lab, train, splits=4, seed=2 ** 63 + seed)
    np.testing.assert_array_equal(again.accuracies, r.accuracies)


@pytest.mark.parametrize('seed', range(12))
def test_groups_match_reference(seed):
    D, lab = random_problem(200 + seed)
    grp = [int(g) for g in np.random.default_rng(seed).integers(0, 2 + seed % 4, size=len(lab))]
    if len(set(grp)) < 2:
        grp[0] = 1 - grp[1]
    r = amscr.nn_groups(D, lab, grp)
    acc, ga, ca = ref_groups(D.tolist(), lab, grp)
    assert r.accuracy == acc and r.groups.tolist() == sorted(set(grp))
    np.testing.assert_array_equal(r.group_accuracy, ga)
    np.testing.assert_array_equal(r.class_accuracy, ca)


@pytest.mark.parametrize('seed', range(12))
def test_precision_recall_matches_reference(seed):
    D, lab = random_problem(300 + seed)
    levels = [2, 3, 11, 21][seed % 4]
    r = amscr.precision_recall(D, lab, levels)
    np.testing.assert_allclose(r.precision, ref_pr(D.tolist(), lab, levels), rtol=0, atol=1e-15)
    assert r.recall.tolist() == [lv / (levels - 1) for lv in range(levels)]


def test_named_labels_and_groups():
    D, lab = random_problem(7, n=12, k=3)
    names = np.array(['cat', 'ant', 'bee'])[lab]
    r = amscr.per_class_scores(D, names)
    assert r.classes.tolist() == ['ant', 'bee', 'cat']
    # the names sort as the codes 1, 2, 0: the same scores, reordered
    ints = amscr.per_class_scores(D, lab)
    np.testing.assert_array_equal(r.nn_accuracy, ints.nn_accuracy[[1, 2, 0]])
    g = amscr.nn_groups(D, names, ['x', 'y'] * 6)
    assert g.groups.tolist() == ['x', 'y'] and g.classes.tolist() == ['ant', 'bee', 'cat']


@pytest.mark.parametrize('call,msg', [
    (lambda D, l: amscr.nn_random_split(D, l, 4), 'leaves no shape to test in class 0 (4 shapes)'),
    (lambda D, l: amscr.nn_random_split(D, l, 0), 'train'),
    (lambda D, l: amscr.nn_random_split(D, l, 1, splits=0), 'splits'),
    (lambda D, l: amscr.nn_groups(D, l, [3] * 8), 'at least 2 groups'),
    (lambda D, l: amscr.precision_recall(D, l, 1), 'levels'),
    (lambda D, l: amscr.per_class_scores(D[:1, :1], l[:1]), 'n = 1 < 2'),
    (lambda D, l: amscr.per_class_scores(np.where(np.eye(8) > 0, np.nan, D), l), 'is NaN'),
    (lambda D, l: amscr.nn_groups(np.where(np.eye(8) > 0, -np.inf, D), l, [0, 1] * 4), '-inf'),
    (lambda D, l: amscr.per_class_scores(D[:, :7], l), 'square'),
    (lambda D, l: amscr.nn_random_split(D, l[:7], 1), 'labels'),
])
def test_bad_input_raises_with_the_library_message(call, msg):
    D, lab = random_problem(9, n=8, k=2)
    with pytest.raises(amscr.InvalidArgumentError, match=re.escape(msg)):
        call(D, np.array(lab))


# ---- against the tool

needs_tool = pytest.mark.skipif(not os.access(TOOL, os.X_OK),
                                reason='the amscr tool is not built (%s); build it with meson compile -C build' % TOOL)


def _tool(*args):
    r = subprocess.run([TOOL, *map(str, args)], capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, 'amscr %s failed: %s' % (' '.join(map(str, args)), r.stderr)
    return r.stdout


def _pr_from_svg(path):
    """The precision of the tool's plot (polyline "pr": x = 560 + 320 recall, y = 380 - 320 precision)."""
    pts = re.search(r'<polyline id="pr"[^>]* points="([^"]*)"', open(path).read()).group(1).split()
    return np.array([(60 + 320 - float(p.split(',')[1])) / 320 for p in pts])


def _compare_with_tool(tmp_path, coll, labels, opts, groups=None):
    """`amscr matrix` then every protocol in Python against `amscr eval --json` on coll."""
    out = tmp_path / 'D.npy'
    _tool('matrix', coll, '-o', out, *opts)
    D = np.load(out)
    j = json.loads(_tool('eval', coll, '--json', '--plot', tmp_path / 'p.svg', *opts))
    pc = amscr.per_class_scores(D, labels)
    assert [c['n'] for c in j['per_class']] == pc.sizes.tolist()
    assert [c['bullseye'] for c in j['per_class']] == pc.bullseye.tolist()
    assert [c['nn_accuracy'] for c in j['per_class']] == pc.nn_accuracy.tolist()
    np.testing.assert_allclose(amscr.precision_recall(D, labels).precision, _pr_from_svg(tmp_path / 'p.svg'),
                               rtol=0, atol=2e-5)
    for train, splits, seed in ((1, 3, 7), (2, 10, 1)):
        j = json.loads(_tool('eval', coll, '--json', '--protocol', 'split', '--train', train, '--splits', splits,
                             '--seed', seed, *opts))
        sp = amscr.nn_random_split(D, labels, train, splits, seed)
        assert j['split']['accuracies'] == sp.accuracies.tolist()
        assert j['split']['accuracy_mean'] == sp.mean and j['split']['accuracy_std'] == sp.std
        assert [c['split_accuracy'] for c in j['per_class']] == sp.class_accuracy.tolist()
    if groups is not None:
        j = json.loads(_tool('eval', coll, '--json', '--protocol', 'groups', *opts))
        g = amscr.nn_groups(D, labels, groups)
        assert j['groups']['accuracy'] == g.accuracy
        assert {x['group']: x['accuracy'] for x in j['groups']['per_group']} == dict(zip(g.groups.tolist(),
                                                                                      g.group_accuracy.tolist()))
        assert [c['groups_accuracy'] for c in j['per_class']] == g.class_accuracy.tolist()
    return pc


@needs_tool
def test_examples_collection_equals_tool(tmp_path):
    coll = os.path.join(REPO_ROOT, 'examples', 'collection')
    names = sorted(os.listdir(coll), key=os.fsencode)  # the tool's order; its classes: first appearance
    labels = [n.rsplit('-', 1)[0] for n in names]
    assert labels == sorted(labels)  # so sorted names are the tool's class order
    groups = ['g' + n.rsplit('-', 1)[1].split('.')[0] for n in names]
    manifest = tmp_path / 'grouped.tsv'
    manifest.write_text('file\tclass\tgroup\n' + ''.join(
        '%s\t%s\t%s\n' % (os.path.join(coll, n), c, g) for n, c, g in zip(names, labels, groups)))
    pc = _compare_with_tool(tmp_path, str(manifest), labels, [], groups)
    assert pc.classes.tolist() == ['bird', 'fish', 'leaf', 'star']


@needs_tool
def test_kimia99_equals_tool(tmp_path):
    """Settings that make mistakes, so the comparison is not all ones; class codes in the tool's order."""
    src = os.path.join(DATASETS, 'kimia99', 'manifest.tsv')
    if not os.path.exists(src):
        pytest.skip('dataset kimia99 not found under %s' % DATASETS)
    rows = [line.split('\t')[:2] for line in open(src).read().splitlines()[1:] if line and line[0] != '#']
    order = list(dict.fromkeys(c for _, c in rows))  # the tool's classes: first appearance
    labels = [order.index(c) for _, c in rows]
    groups = ['v%d' % (int(f.rsplit('-', 1)[1].split('.')[0]) % 4) for f, _ in rows]
    manifest = tmp_path / 'k99.tsv'
    manifest.write_text('file\tclass\tgroup\n' + ''.join(
        '%s\t%s\t%s\n' % (os.path.join(os.path.dirname(src), f), c, g) for (f, c), g in zip(rows, groups)))
    pc = _compare_with_tool(tmp_path, str(manifest), labels,
                            ['--no-rerank', '--refine', '0', '--channel-weight', '0', '--points', '32'], groups)
    assert pc.nn_accuracy.min() < 1  # the comparison saw mistakes
