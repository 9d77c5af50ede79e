import sys, csv, numpy as np
rows = list(csv.DictReader(open('/work/shared/datasets/eth80-dev/manifest.tsv'), delimiter='\t'))
cls = np.array([r['class'] for r in rows]); grp = np.array([r['group'] for r in rows])
R = np.load('/tmp/e80/def.npy'); D = np.load('/tmp/e80/norr.npy'); D = 0.5 * (D + D.T); np.fill_diagonal(D, 0)
q = 1 - 2 * R  # q/qmax where reached (>0), <=0 where not
same = grp[:, None] == grp[None, :]
def acc(M):
    M = M.copy(); M[same] = np.inf; return 100 * (cls[np.argmin(M, 1)] == cls).mean()
print('default %.2f  raw %.2f' % (acc(R), acc(D)))
print('reached fraction per row: median %.3f' % np.median((q > 0).mean(1)))
for eps in [1e-8, 1e-6, 1e-4, 1e-3, 1e-2, 0.05, 0.1]:
    M = np.where(q > eps, R, 0.5 + 0.5 * D / D.max())
    print('eps %g: %.2f  reached %.3f' % (eps, acc(M), np.median((q > eps).mean(1))))
# where is the nearest other-object shape in q terms
M = D.copy(); M[same] = np.inf; j = np.argmin(M, 1)
print('q of raw nearest other-object: quantiles', np.quantile(q[np.arange(len(q)), j], [0.1, 0.25, 0.5, 0.75, 0.9]))
M = R.copy(); M[same] = np.inf; j = np.argmin(M, 1)
print('q of reranked nearest other-object: quantiles', np.quantile(q[np.arange(len(q)), j], [0.1, 0.25, 0.5, 0.75, 0.9]))
