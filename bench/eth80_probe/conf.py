import sys, csv, numpy as np
rows = list(csv.DictReader(open('/work/shared/datasets/eth80-dev/manifest.tsv'), delimiter='\t'))
cls = np.array([r['class'] for r in rows]); grp = np.array([r['group'] for r in rows])
C = sorted(set(cls))
for f in sys.argv[1:]:
    D = np.load(f).copy()
    D[grp[:, None] == grp[None, :]] = np.inf
    nn = np.argmin(D, axis=1)
    pred = cls[nn]
    acc = (pred == cls).mean()
    conf = {}
    for a, b in zip(cls, pred):
        if a != b: conf[(a, b)] = conf.get((a, b), 0) + 1
    top = sorted(conf.items(), key=lambda x: -x[1])[:8]
    percls = ' '.join('%s %.0f' % (c, 100 * (pred[cls == c] == c).mean()) for c in C)
    print(f, '%.2f' % (100 * acc), '|', percls, '|', ', '.join('%s>%s %d' % (a, b, n) for (a, b), n in top))
