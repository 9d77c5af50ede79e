"""Seeded procedural silhouettes: shapes beyond the dataset's classes, for the registration bench.

silhouette(seed, i) is shape i of the set `seed`: a smooth random blob (or an n-fold / mirror
shape broken by a 1-4 % harmonic: a near symmetry) with the features of kind KINDS[i % 5] -- thin
limbs (bent strokes 4-7 % of the span wide), holes, spikes, deep narrow notches -- and, for half
the shapes, a second kind's. White (255) on black, one 8-connected piece, its longer side `size`
px, in a square canvas 1.3 x size. The same (seed, i) gives the same image on every machine
(NumPy's PCG64 and OpenCV's integer rasterizer).
"""
import math

import cv2
import numpy as np

KINDS = ('limbs', 'symmetric', 'holes', 'spikes', 'concave')
U, W = 100.0, 640  # the working unit radius and canvas (px)


def _profile(rng, kinds, t):
    if 'symmetric' in kinds:
        n = int(rng.integers(2, 7))
        r = 1 + rng.uniform(0.15, 0.35) * np.cos(n * t) + rng.uniform(0, 0.15) * np.cos(2 * n * t)
        if rng.random() < 0.5:  # mirror only: the n-fold profile plus a term odd in t
            r += rng.uniform(0.1, 0.2) * np.cos(t)
        return r + rng.uniform(0.01, 0.04) * np.cos(int(rng.integers(1, 4)) * t + rng.uniform(0, 2 * math.pi))
    return 1 + sum(rng.uniform(0, 0.3) / k * np.cos(k * t + rng.uniform(0, 2 * math.pi)) for k in range(1, 5))


def silhouette(seed, i, size=200):
    rng = np.random.default_rng([seed, i])
    kinds = [KINDS[i % len(KINDS)]] + ([KINDS[int(rng.integers(len(KINDS)))]] if rng.random() < 0.5 else [])
    t = np.linspace(0, 2 * math.pi, 1440, endpoint=False)
    r = _profile(rng, kinds, t) * (0.6 if 'limbs' in kinds or 'spikes' in kinds else 1.0)
    if 'concave' in kinds:  # 2-4 notches taking 55-85 % of the radius, 5-15 degrees wide
        for phi in rng.uniform(0, 2 * math.pi, int(rng.integers(2, 5))):
            d = np.angle(np.exp(1j * (t - phi)))
            r = r * (1 - rng.uniform(0.55, 0.85) * np.exp(-0.5 * (d / rng.uniform(0.04, 0.12)) ** 2))
    c = np.array([W / 2, W / 2])
    xy = lambda rad, ang: c + U * rad * np.array([math.cos(ang), math.sin(ang)])
    img = np.zeros((W, W), np.uint8)
    pts = np.column_stack([c[0] + U * r * np.cos(t), c[1] + U * r * np.sin(t)])
    cv2.fillPoly(img, [np.round(pts * 16).astype(np.int32)], 255, cv2.LINE_8, 4)
    body = img.copy()
    at = lambda ang: float(np.interp(ang % (2 * math.pi), t, r))
    if 'limbs' in kinds:  # 2-5 strokes from the centre, bent once
        for phi in rng.uniform(0, 2 * math.pi, int(rng.integers(2, 6))):
            a = xy(0, phi)
            b = xy(at(phi) + rng.uniform(0.3, 0.6), phi)
            e = b + U * rng.uniform(0.3, 0.6) * np.array([math.cos(phi + rng.uniform(-0.8, 0.8)),
                                                          math.sin(phi + rng.uniform(-0.8, 0.8))])
            cv2.polylines(img, [np.round(np.array([a, b, e]) * 16).astype(np.int32)], False, 255,
                          int(rng.integers(16, 26)), cv2.LINE_8, 4)
    if 'spikes' in kinds:  # 3-7 triangles 0.4-0.9 units long on a base of 5-10 degrees
        for phi in rng.uniform(0, 2 * math.pi, int(rng.integers(3, 8))):
            h = rng.uniform(0.04, 0.09)
            tri = [xy(0.9 * at(phi - h), phi - h), xy(at(phi) + rng.uniform(0.4, 0.9), phi),
                   xy(0.9 * at(phi + h), phi + h)]
            cv2.fillPoly(img, [np.round(np.array(tri) * 16).astype(np.int32)], 255, cv2.LINE_8, 4)
    if 'holes' in kinds:  # 1-3 ellipses well inside the body
        want, tries = int(rng.integers(1, 4)), 0
        while want and tries < 50:
            tries += 1
            hole = np.zeros_like(img)
            a = rng.uniform(0, 2 * math.pi)
            p = xy(rng.uniform(0, 0.7) * at(a), a)
            ax = (int(U * rng.uniform(0.08, 0.2)), int(U * rng.uniform(0.06, 0.15)))
            cv2.ellipse(hole, (int(p[0]), int(p[1])), ax, rng.uniform(0, 180), 0, 360, 255, -1)
            if np.all(body[cv2.dilate(hole, np.ones((25, 25), np.uint8)) > 0] > 0):
                img[hole > 0], want = 0, want - 1
    x, y, w, h = cv2.boundingRect(img)
    s = size / max(w, h)
    small = cv2.resize(img[y:y + h, x:x + w], (max(1, round(w * s)), max(1, round(h * s))), None, 0, 0, cv2.INTER_AREA)
    side = int(round(1.3 * size))
    out = np.zeros((side, side), np.uint8)
    oy, ox = (side - small.shape[0]) // 2, (side - small.shape[1]) // 2
    out[oy:oy + small.shape[0], ox:ox + small.shape[1]] = small
    n, lab, stats, _ = cv2.connectedComponentsWithStats((out > 127).astype(np.uint8), connectivity=8)
    return np.where(lab == 1 + int(np.argmax(stats[1:, cv2.CC_STAT_AREA])), 255, 0).astype(np.uint8)
