"""Shared test data: smooth asymmetric closed curves and affine maps."""
import numpy as np


def blob(n=400, seed=0, phase=0.0):
    """A smooth, star-like, asymmetric closed curve (counter-clockwise), n points."""
    rng = np.random.default_rng(seed)
    t = np.linspace(0.0, 2.0 * np.pi, n, endpoint=False) + phase
    r = 1.0
    for k in range(2, 6):
        r = r + rng.uniform(0.04, 0.15) * np.cos(k * t + rng.uniform(0, 2 * np.pi))
    return np.column_stack([r * np.cos(t), r * np.sin(t)])


def affine(points, A, B):
    return np.asarray(points) @ np.asarray(A).T + np.asarray(B)


A_TRUE = np.array([[1.3, 0.4], [-0.2, 0.8]])
B_TRUE = np.array([5.0, -2.0])
