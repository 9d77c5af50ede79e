"""What a silhouette still says: per-shape numbers the default's frames or outline discard."""
import sys, csv, numpy as np
from skimage import io, measure, morphology
from scipy import ndimage as ndi

def feats(path):
    im = io.imread(path)
    if im.ndim == 3: im = im[..., 0]
    m = im > 127
    lab, k = ndi.label(m)
    if k > 1:
        sizes = ndi.sum(m, lab, range(1, k + 1)); m = lab == (1 + int(np.argmax(sizes)))
    filled = ndi.binary_fill_holes(m)
    area = filled.sum()
    ys, xs = np.nonzero(filled)
    c = np.cov(np.vstack([xs, ys]))
    ev = np.sort(np.linalg.eigvalsh(c))
    aspect = np.sqrt(ev[0] / ev[1])                       # removed by the affine frame only
    hw = (ys.max() - ys.min() + 1) / (xs.max() - xs.min() + 1)  # upright height / width: removed by both (rotation)
    hull = morphology.convex_hull_image(filled)
    deficiency = 1 - area / hull.sum()
    holes = (filled.sum() - m.sum()) / area
    r = max(1, int(round(0.04 * np.sqrt(area))))
    closed = ndi.binary_fill_holes(morphology.binary_closing(filled, morphology.disk(r)))
    closing_gain = (closed.sum() - area) / area
    return dict(aspect=aspect, hw=hw, deficiency=deficiency, holes=holes, closing=closing_gain)

def auc(a, b):
    a, b = np.asarray(a), np.asarray(b)
    from scipy.stats import rankdata
    x = np.concatenate([a, b])
    order = rankdata(x)
    ra = order[:len(a)].sum()
    u = ra - len(a) * (len(a) + 1) / 2
    v = u / (len(a) * len(b))
    return max(v, 1 - v)

man = sys.argv[1]; import os; d = os.path.dirname(man)
rows = list(csv.DictReader(open(man), delimiter='\t'))
step = int(sys.argv[2]) if len(sys.argv) > 2 else 1
rows = rows[::step]
F = {}
for r in rows:
    F.setdefault(r['class'], []).append(feats(os.path.join(d, r['file'])))
keys = ['aspect', 'hw', 'deficiency', 'holes', 'closing']
print('class\t' + '\t'.join(keys))
for c, L in F.items():
    print(c + '\t' + '\t'.join('%.3f' % np.median([f[k] for f in L]) for k in keys))
pairs = [p.split('/') for p in sys.argv[3].split(',')] if len(sys.argv) > 3 else []
for a, b in pairs:
    print('AUC %s/%s\t' % (a, b) + '\t'.join('%.2f' % auc([f[k] for f in F[a]], [f[k] for f in F[b]]) for k in keys))
