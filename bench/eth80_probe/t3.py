import sys; sys.path.insert(0, '/tmp/e80/probe'); from diff import *
for name in ['kimia99', 'kimia216', 'mpeg7-dev', 'eth80-dev']:
    D0, R, I0, cls, grp = load(name)
    D = 0.5 * (D0 + D0.T); np.fill_diagonal(D, 0)
    q = 1 - 2 * R
    res = ['default %.2f' % score(name, R, cls, grp)]
    for eps in [0.01, 0.03, 0.05, 0.1]:
        M = np.where(q > eps, R, 0.5 + 0.5 * D / D.max()); np.fill_diagonal(M, 0)
        res.append('eps %g: %.2f (reach %.1f)' % (eps, score(name, M, cls, grp), np.median((q > eps).sum(1))))
    print(name, ' | '.join(res), flush=True)
