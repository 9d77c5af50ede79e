import sys, csv, numpy as np, scipy.sparse as sp
def load(name):
    if name == 'eth80-dev':
        rows = list(csv.DictReader(open('/work/shared/datasets/eth80-dev/manifest.tsv'), delimiter='\t'))
        cls = np.array([r['class'] for r in rows]); grp = np.array([r['group'] for r in rows])
        return np.load('/tmp/e80/norr.npy'), np.load('/tmp/e80/def.npy'), None, cls, grp
    rows = list(csv.reader(open('/tmp/e80/%s_names.tsv' % name), delimiter='\t'))[1:]
    cls = np.array([r[1] for r in rows])
    return np.load('/tmp/e80/%s_norr.npy' % name), np.load('/tmp/e80/%s_def.npy' % name), np.load('/tmp/e80/%s_in0.npy' % name), cls, None

def rerank(D0, k, iters=10, kvec=None):
    n = len(D0); D = 0.5 * (D0 + D0.T); np.fill_diagonal(D, 0); dmax = D.max()
    order = np.argsort(D, axis=1, kind='stable')
    ks = kvec if kvec is not None else np.full(n, k)
    rows, cols, vals = [], [], []
    sc = D[np.arange(n), order[np.arange(n), ks - 1]]
    tiny = 1e-12 * dmax
    for i in range(n):
        nb = order[i, :ks[i]]
        s = np.sqrt((sc[i] + tiny) * (sc[nb] + tiny))
        w = np.exp(-D[i, nb] / s); w /= w.sum()
        rows += [i] * len(nb); cols += list(nb); vals += list(w)
    P = sp.csr_matrix((vals, (rows, cols)), shape=(n, n))
    Q = P.toarray()
    for _ in range(iters):
        Q = np.asarray((P @ (P @ Q).T).T) + np.eye(n)  # P Q P^T
    qmax = Q.max(1, keepdims=True)
    out = np.where(Q > 0, 1 - Q / qmax, 1 + D / dmax) * 0.5
    np.fill_diagonal(out, 0)
    return out

def score(name, M, cls, grp):
    n = len(M)
    if grp is not None:
        M = M.copy(); M[grp[:, None] == grp[None, :]] = np.inf
        return 100 * (cls[np.argmin(M, 1)] == cls).mean()
    if name == 'mpeg7-dev':
        o = np.argsort(M, 1, kind='stable')[:, :40]
        return 100 * (cls[o] == cls[:, None]).sum() / (n * 20)
    kmax = 10 if n < 100 else 11
    o = np.argsort(M + np.diag(np.full(n, np.inf)), 1, kind='stable')[:, :kmax]
    return (cls[o] == cls[:, None]).sum()
