import sys; sys.path.insert(0, '/tmp/e80/probe'); from diff import *
sets = {n: load(n) for n in ['kimia99', 'kimia216', 'mpeg7-dev', 'eth80-dev']}
for name, (D0, R, I0, cls, grp) in sets.items():
    Ds = 0.5 * (D0 + D0.T); np.fill_diagonal(Ds, np.inf); srt = np.sort(Ds, 1)
    d1 = srt[:, 0]
    for c in [1.5, 2.0]:
        ndup = (Ds <= c * d1[:, None]).sum(1)
        print(name, 'c', c, 'near-dup count median %.1f mean %.1f' % (np.median(ndup), ndup.mean()))
    print(name, 'd8/d1 median %.2f  d16/d8 %.2f d32/d8 %.2f' % (np.median(srt[:, 7] / srt[:, 0]), np.median(srt[:, 15] / srt[:, 7]), np.median(srt[:, 31] / srt[:, 7])))
    if name == 'eth80-dev':
        for k in [8, 16, 24, 32, 48, 64]:
            print(name, 'k', k, '%.2f' % score(name, rerank(D0, k), cls, grp), flush=True)
