"""How far the robots are from their formation: position, shape and heading errors.

Two questions with different answers:
  * Is every follower in its slot? Compare the actual positions with the desired ones (the slots
    placed on the leader): `rms`, `max`.
  * Is the shape right, wherever and however it is turned? Move the desired shape rigidly (rotate
    + translate, no scaling) to best cover the actual positions, then compare: `fit_rms`,
    `fit_max`. A well-formed formation that lags behind its leader's turn has large plain errors
    and fit errors near 0. `edge_max` says the same without any fit: it compares the distances
    between every pair of robots.
Pure numpy, no ROS.
"""
from collections import namedtuple

import numpy as np

from mbot_common.geometry import normalize_angle

#: All distances [m], angles [rad]. rms/max: followers to their slots; fit_rms/fit_max: the
#: same after the best rigid fit of the whole shape; edge_max: largest |d_ij - d*_ij| over all
#: pairs; heading_max: largest follower heading error to the leader's heading, or to each
#: follower's own desired heading when given (0 if no headings are given).
ShapeErrors = namedtuple("ShapeErrors", "rms max fit_rms fit_max edge_max heading_max")


def _points(name, value):
    points = np.asarray(value, dtype=float)
    if points.ndim != 2 or points.shape[1] != 2 or len(points) == 0:
        raise ValueError("%s: expected an (n, 2) array of [x, y] with n >= 1, got shape %s"
                         % (name, points.shape))
    if not np.all(np.isfinite(points)):
        raise ValueError("%s: every coordinate must be finite" % name)
    return points


def rigid_fit(actual, desired):
    """Best rotation R (2x2) and translation t (2,) with R @ desired[i] + t ~ actual[i].

    Least squares over all rows (Kabsch / Umeyama without scale): centre both point sets, the
    rotation comes from the SVD of their cross-covariance, with a sign fix so that R is a proper
    rotation (det = +1), never a mirror image. Returns (R, t, fitted) with fitted = desired
    moved by (R, t), shape (n, 2).
    """
    a = _points("actual", actual)
    d = _points("desired", desired)
    if a.shape != d.shape:
        raise ValueError("rigid_fit: actual has %d points, desired %d" % (len(a), len(d)))
    a_mean = a.mean(axis=0)
    d_mean = d.mean(axis=0)
    h = (d - d_mean).T @ (a - a_mean)          # 2x2 cross-covariance
    u, _, vt = np.linalg.svd(h)
    mirror = np.sign(np.linalg.det(vt.T @ u.T)) or 1.0
    r = vt.T @ np.diag([1.0, mirror]) @ u.T
    t = a_mean - r @ d_mean
    return r, t, d @ r.T + t


def _rms_max(distances):
    if len(distances) == 0:
        return 0.0, 0.0
    return float(np.sqrt(np.mean(distances ** 2))), float(np.max(distances))


def shape_errors(actual, desired, headings=None, leader_heading=None, desired_headings=None):
    """ShapeErrors of a formation. Row 0 is the leader, rows 1..n-1 the followers.

    actual: (n, 2) positions [m]; desired: (n, 2) the slots in the same frame [m];
    headings: optional n headings [rad] of the robots (row 0 = the leader); each follower's
    heading error is to leader_heading [rad] (default headings[0]), or, when
    desired_headings (n headings [rad], row 0 = the leader's slot) are given, to its own slot's
    heading (a column bent around a corner: each robot faces the path where it is). The fit uses
    every row (the leader is part of the shape); the errors count the followers only, like the
    plain ones.
    """
    a = _points("actual", actual)
    d = _points("desired", desired)
    if a.shape != d.shape:
        raise ValueError("shape_errors: actual has %d points, desired %d" % (len(a), len(d)))
    n = len(a)

    rms, worst = _rms_max(np.linalg.norm(a[1:] - d[1:], axis=1))
    _, _, fitted = rigid_fit(a, d)
    fit_rms, fit_worst = _rms_max(np.linalg.norm(a[1:] - fitted[1:], axis=1))

    edge_max = 0.0
    if n >= 2:
        i, j = np.triu_indices(n, k=1)
        actual_edges = np.linalg.norm(a[i] - a[j], axis=1)
        desired_edges = np.linalg.norm(d[i] - d[j], axis=1)
        edge_max = float(np.max(np.abs(actual_edges - desired_edges)))

    heading_max = 0.0
    if headings is not None:
        headings = [float(h) for h in headings]
        if len(headings) != n:
            raise ValueError("shape_errors: %d headings for %d robots" % (len(headings), n))
        if desired_headings is not None:
            if leader_heading is not None:
                raise ValueError("shape_errors: give leader_heading or desired_headings, not both")
            wanted = [float(h) for h in desired_headings]
            if len(wanted) != n:
                raise ValueError("shape_errors: %d desired_headings for %d robots" % (len(wanted), n))
        else:
            wanted = [headings[0] if leader_heading is None else float(leader_heading)] * n
        heading_max = max([abs(normalize_angle(h - w)) for h, w in zip(headings[1:], wanted[1:])] or [0.0])
    elif leader_heading is not None or desired_headings is not None:
        raise ValueError("shape_errors: %s given without the robots' headings"
                         % ("leader_heading" if leader_heading is not None else "desired_headings"))
    return ShapeErrors(rms, worst, fit_rms, fit_worst, edge_max, heading_max)
