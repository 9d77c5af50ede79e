"""amscr — affine multi-scale registration and retrieval of 2-D shapes (Python bindings of libamscr).

Quick start::

    import numpy as np, amscr
    r = amscr.register(src, tgt)              # src, tgt: (n, 2) arrays of contour points
    r.A, r.B, r.distance, r.apply(src)        # tgt ~= src @ r.A.T + r.B

    db = amscr.Collection(reflections=True)
    for pts, cls in shapes:
        db.add(pts, label=cls)
    D = db.distance_matrix(progress=True)      # GIL released, POSIX threads in C
    amscr.bullseye(D, db.labels)

Points are NumPy arrays of shape (n, 2) (x, y rows; for images x = column, y = row); any
array-like of real numbers is accepted and validated (finite, at least one point) before it
reaches C. OpenCV contours ((n, 1, 2) from ``cv2.findContours``) are taken as they are;
(row, col) points from scikit-image's ``measure.find_contours`` with ``order='rc'``
(:func:`register`, :class:`Shape`, :class:`Collection`, :func:`as_points`). Affine maps are
returned as 3x3 matrices. C failures raise subclasses of :class:`AmscrError` (``amscr.Error``) that carry the
library's message. Library handles are freed automatically. The GIL is released during every C
call (cffi does that in both API and ABI mode), so Python threads run registrations in parallel.
"""
from __future__ import annotations

from ._lib import API_MODE, LIBRARY_PATH, SOVERSION, ffi, lib
from ._version import __version__
from . import errors
from .errors import (AmscrError, CancelledError, DegenerateError, Error, FileError, FormatError,
                     InternalError, InvalidArgumentError, IOError_, LimitError, NoMemoryError, NotConvergedError,
                     NotFoundError, NumericalError, NumericError, StateError, UnsupportedError, _check)
from ._util import ArrayLike, ProgressArg
from .library import has_threads, library_version
from .params import Params
from .contour import (ImageContour, as_points, contour_from_mask, contours_from_mask, orient_ccw, parse_points,
                      read_points, signed_area, validate_contour, write_points)
from .shape import PointsLike, Shape
from .result import Alternative, Mixture, Registration, channel_distance, distance, register
from .collection import Collection, distance_matrix
from .scores import bullseye, nn_accuracy, nn_split, topk, topk_table
from .scores import (ClassScores, GroupScores, PrecisionRecall, SplitScores, nn_groups, nn_random_split,
                     per_class_scores, precision_recall)
from .rerank import rerank_diffusion
from .curves import affine_arclength, gaussian_kernel, normalize_whiten, resample_affine, resample_euclidean, smooth
from .linalg import affine_apply, affine_fit, affine_invert, lstsq
from .clustering import KMeansResult, elbow, kmeans
from .gmm import GMM1D, bayes_threshold, gmm1d
# The reconstructors that pickles made by amscr 0.1 name as amscr.<name>.
from .params import _params_from_dict
from .shape import _shape_from_state
from .collection import _collection_from_state
from .index import Index

__all__ = [
    '__version__', 'API_MODE', 'SOVERSION', 'LIBRARY_PATH', 'library_version', 'has_threads', 'errors',
    # errors
    'AmscrError', 'Error', 'InvalidArgumentError', 'NoMemoryError', 'FileError', 'IOError_', 'FormatError',
    'UnsupportedError', 'DegenerateError', 'NumericError', 'NumericalError', 'NotConvergedError',
    'NotFoundError', 'StateError', 'InternalError', 'CancelledError', 'LimitError',
    # registration and retrieval
    'Params', 'Shape', 'Registration', 'Mixture', 'Alternative', 'register', 'distance', 'channel_distance', 'Collection',
    'distance_matrix',
    'bullseye', 'topk_table', 'nn_accuracy', 'nn_split', 'topk', 'rerank_diffusion',
    # contours
    'as_points', 'contour_from_mask', 'contours_from_mask', 'ImageContour', 'read_points', 'parse_points', 'write_points', 'signed_area', 'orient_ccw',
    'validate_contour',
    # building blocks
    'smooth', 'gaussian_kernel', 'resample_euclidean', 'resample_affine', 'affine_arclength',
    'normalize_whiten', 'lstsq', 'affine_fit', 'affine_apply', 'affine_invert',
    'kmeans', 'KMeansResult', 'elbow', 'GMM1D', 'gmm1d', 'bayes_threshold',
    # one-vs-many retrieval
    'Index',
    # evaluation protocols
    'per_class_scores', 'nn_random_split', 'nn_groups', 'precision_recall', 'ClassScores', 'SplitScores',
    'GroupScores', 'PrecisionRecall',
]
