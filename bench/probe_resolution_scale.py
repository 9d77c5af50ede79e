#!/usr/bin/env python3
"""Probe (not kept): the confidence's halving scale read from the input's resolution.
Run: `probe_resolution_scale.py OUT.json [registration_traced.py options]` records, a pair, the tool's
confidence parts and the target's median point spacing over its RMS radius (h);
`probe_resolution_scale.py --analyse A.json,B.json,...` recomputes the confidence with the scale
max(0.01, c h) for both the forward-backward error and the standard error."""
import sys, os, json, subprocess, time
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import numpy as np, cv2
import registration_traced as rt
import amscr
LOG = []
def hr(path):
    img = cv2.imread(path, cv2.IMREAD_UNCHANGED)
    p = np.asarray(amscr.contour_from_mask(img, join=True), float)
    st = np.linalg.norm(np.diff(np.vstack([p, p[:1]]), axis=0), axis=1)
    c = p - p.mean(0)
    R = np.sqrt((c ** 2).sum(1).mean())
    return float(np.median(st) / R), float(st.mean() / R), len(p)
def tool_register(tool, sp, tp, extra):
    t0 = time.perf_counter()
    r = subprocess.run([tool, 'register', sp, tp, '--json'] + extra, capture_output=True, text=True)
    ms = 1000 * (time.perf_counter() - t0)
    if r.returncode != 0:
        LOG.append(None)
        return None, 0.0, ms
    j = json.loads(r.stdout)
    rec = {k: j.get(k) for k in ('confidence', 'ambiguity', 'symmetry_ambiguity', 'inlier_fraction', 'overlap',
                                 'backward_error', 'standard_error', 'partial', 'source_points', 'target_points')}
    rec['ht'] = hr(tp); rec['hs'] = hr(sp)
    LOG.append(rec)
    M = np.hstack([np.array(j['A'], float), np.array(j['B'], float)[:, None]])
    return M, float(j.get('confidence', 0.0)), ms
rt.tool_register = tool_register
import collections, math
def analyse(paths):
  global rows
  rows = []
  for p in paths.split(','):
    rows += json.load(open(p))['pairs']
  bad = sum(1 for r in rows if r['rec'] and abs(conf(r['rec'], .01, .01) - r['sub'][2]) > 1e-6)
  print('pairs', len(rows), 'mismatch', bad)
  run(0.0, show=True)
  for c in (0.2, 1 / 12 ** 0.5, 0.35, 0.5):
    run(c, show=abs(c - 1 / 12 ** 0.5) < 1e-9)
def conf(rec, S_fb, S_se):
    fb = rec['backward_error']; se = rec['standard_error']
    fb = fb / S_fb if fb is not None and math.isfinite(fb) else 0.0
    se = se / S_se if se is not None and math.isfinite(se) else 0.0
    amb = max(rec['ambiguity'] or 0, rec['symmetry_ambiguity'] or 0)
    return (1 - amb) * min(rec['inlier_fraction'], rec['overlap']) / (1 + fb * fb) / (1 + se * se)
def variant(rec, c, which, hkey):
    h = rec['ht'][hkey] if which == 't' else max(rec['ht'][hkey], rec['hs'][hkey])
    S = max(0.01, c * h)
    return conf(rec, S, S)
def run(c, which='t', hkey=0, show=False):
    cell = collections.defaultdict(lambda: [0, 0, 0, 0])
    tot = [0, 0, 0]
    for r in rows:
        rec = r['rec']
        thr = 4.0 if r['condition'].startswith(('lowres', 'grey', 'binary')) else 2.0
        ok = r['sub'][0] < thr
        cf = variant(rec, c, which, hkey) if rec else 0.0
        k = (r['condition'], r['fold']); x = cell[k]
        x[0] += 1; x[1] += ok; x[2] += (not ok) and cf >= 0.25; x[3] += ok and cf >= 0.25
        tot[0] += (not ok) and cf >= 0.25; tot[1] += ok; tot[2] += ok and cf >= 0.25
    print('c=%.3f %s h%d: w+c %d, ok+c %.2f%%' % (c, which, hkey, tot[0], 100 * tot[2] / tot[1]))
    if show:
        for k in sorted(cell, key=lambda k: (k[0], k[1])):
            n, ok, wc, okc = cell[k]
            if wc or okc < 0.95 * ok:
                print('   %-14s %s  w+c %d/%d  ok+c %.1f%%' % (k[0], k[1], wc, n, 100 * okc / max(ok, 1)))

if sys.argv[1] == '--analyse':
    analyse(sys.argv[2])
    sys.exit(0)
out = sys.argv.pop(1)
orig_dump = json.dump
def dump(obj, fp, **kw):
    if isinstance(obj, dict) and 'pairs' in obj:
        for row, rec in zip(obj['pairs'], LOG):
            row['rec'] = rec
        assert len(obj['pairs']) == len(LOG)
    return orig_dump(obj, fp, **kw)
rt.json.dump = dump
sys.argv += ['--json', out]
if __name__ == "__main__" and sys.argv[1] != "--analyse":
    sys.exit(rt.main())
