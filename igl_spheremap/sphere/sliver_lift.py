"""Lift isolated faces of a fold-free spherical map above their rounding margin (not in the paper).

A face whose input triangle is a sliver (a needle or a tiny face, as marching cubes
leaves them) keeps a sliver image under any map of bounded distortion, and so can sit
below its float32 rounding margin (:func:`igl_spheremap.sphere.folds.rounding_margin`)
while every face around it has room.  Cluster inflation
(:mod:`igl_spheremap.precision.inflation`) re-embeds crowded regions; an isolated sliver
needs only one of its corners moved a little off the opposite edge.  The signed volume
``s = det[U_a, U_b, U_c]`` is linear in each corner, with gradient ``U_b x U_c`` at ``U_a``,
so the move along that gradient's tangent part that brings ``s`` to a target is known to
first order; it is kept only if the face then clears its margin and no face at the moved
corner folds or falls to its margin.  Faces below the margin that form a large cluster
(sharing corners) are crowding, not slivers: no single-corner move clears them, and they
are left to the re-embeddings.
"""

import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components

from ..mesh.arrays import cross_rows
from ..mesh.topology import vertex_face_incidence
from .folds import unit_roundoff, volumes_and_margins

#: Signed volumes a lift aims at, in rounding margins, tried in turn (the first kept).
LIFT_TARGETS = (4.0, 2.0, 1.25)

#: Faces below the margin in a cluster (faces sharing corners) of more than this many are
#: crowding and are not lifted.
LIFT_CLUSTER = 16


def lift_slivers(F, U, precision="float32", passes=3):
    """Move one corner of each face below its rounding margin until it clears it.

    Parameters
    ----------
    F : (m, 3) int64 array
        Faces, oriented outward.
    U : (n, 3) float64 array
        Fold-free spherical map (unit rows).
    precision : {"float32", "float64"}
        Whose rounding margin (:func:`igl_spheremap.sphere.folds.unit_roundoff`); with
        ``"float64"`` the margin is 0 and ``U`` is returned as it is.
    passes : int
        Sweeps over the faces still below their margin.

    Returns
    -------
    (n, 3) float64 array
        A copy of ``U`` in which each face below its margin whose lift was possible has
        one corner moved (unit rows); faces in a cluster of more than
        :data:`LIFT_CLUSTER` faces below the margin are not tried.  Every face at a moved
        corner that was above its margin stays above it, and none folds; faces still below
        their margin are those no single-corner move could lift (count them with
        :func:`igl_spheremap.sphere.folds.below_margin`).

    Raises
    ------
    ValueError
        If ``precision`` is not a known precision.
    """
    u = unit_roundoff(precision)
    U = np.array(U, dtype=np.float64, copy=True)
    if u == 0.0:
        return U
    F, incidence = np.asarray(F, dtype=np.int64), None
    for _ in range(passes):
        s, margin = volumes_and_margins(F, U, u)
        low = _isolated(F, U.shape[0], np.flatnonzero((s > 0.0) & (s <= margin)))
        if low.size == 0:
            break
        if incidence is None:
            incidence = vertex_face_incidence(F, U.shape[0])
        for f in low:
            _lift_face(F, U, f, incidence, u)
    return U


def _isolated(F, n, faces):
    """The faces of ``faces`` (int array) whose cluster in it (faces sharing a corner) has at
    most :data:`LIFT_CLUSTER` faces."""
    if faces.size <= LIFT_CLUSTER:
        return faces
    rows = np.repeat(np.arange(faces.size), 3)
    corners = sp.csr_matrix((np.ones(rows.size), (rows, F[faces].ravel())), shape=(faces.size, n))
    _, label = connected_components(corners @ corners.T, directed=False)
    return faces[np.bincount(label)[label] <= LIFT_CLUSTER]


def _lift_face(F, U, f, incidence, u):
    """Lift face ``f`` by moving one of its corners, if a move is found (``U`` in place)."""
    s, margin = volumes_and_margins(F[f:f + 1], U, u)
    if s[0] > margin[0]:
        return  # a neighbour's lift already did it
    corners = F[f]
    steps = []
    for a in range(3):
        v, b, c = corners[a], corners[(a + 1) % 3], corners[(a + 2) % 3]
        g = cross_rows(U[b], U[c])
        g -= (g @ U[v]) * U[v]  # tangent part of ds / dU_v
        steps.append((np.linalg.norm(g), v, g))
    for norm, v, g in sorted(steps, key=lambda t: -t[0]):
        if not norm > 0.0:
            continue
        around = incidence[v].indices
        s0, m0 = volumes_and_margins(F[around], U, u)
        keep = (s0 > m0) | (around == f)  # faces that must end above their margin
        old = U[v].copy()
        for target in LIFT_TARGETS:
            moved = old + ((target * margin[0] - s[0]) / norm ** 2) * g
            U[v] = moved / np.linalg.norm(moved)
            s1, m1 = volumes_and_margins(F[around], U, u)
            if np.all(s1 > 0.0) and np.all(s1[keep] > m1[keep]):
                return
            U[v] = old
