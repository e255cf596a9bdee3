"""Split icospheres: the degenerate-but-valid input of issue #15 item 8.

``split_icosphere(level, n_edges, t)``: unit icosphere (same construction as
tests/conftest.py) with ``n_edges`` edges split by a new vertex at ``t`` times
the edge length from one end; both faces of each edge are split in two.  The
edges are chosen (seeded) so that no two share a face: every split is the
textbook single-edge split.
"""

import igl
import numpy as np


def icosphere(level):
    t = (1.0 + 5.0 ** 0.5) / 2.0
    V = np.array([[-1, t, 0], [1, t, 0], [-1, -t, 0], [1, -t, 0],
                  [0, -1, t], [0, 1, t], [0, -1, -t], [0, 1, -t],
                  [t, 0, -1], [t, 0, 1], [-t, 0, -1], [-t, 0, 1]], dtype=np.float64)
    F = np.array([[0, 11, 5], [0, 5, 1], [0, 1, 7], [0, 7, 10], [0, 10, 11],
                  [1, 5, 9], [5, 11, 4], [11, 10, 2], [10, 7, 6], [7, 1, 8],
                  [3, 9, 4], [3, 4, 2], [3, 2, 6], [3, 6, 8], [3, 8, 9],
                  [4, 9, 5], [2, 4, 11], [6, 2, 10], [8, 6, 7], [9, 8, 1]], dtype=np.int64)
    V = V / np.linalg.norm(V, axis=1, keepdims=True)
    for _ in range(level):
        V, F = igl.upsample(V, F)
        V = V / np.linalg.norm(V, axis=1, keepdims=True)
    return np.ascontiguousarray(V), np.ascontiguousarray(F, dtype=np.int64)


def split_edges(V, F, n_edges, t, seed=0):
    """Split ``n_edges`` face-disjoint edges at ``t`` of their length."""
    m = F.shape[0]
    E, uE, EMAP, uEC, uEE = igl.unique_edge_map(F)
    rng = np.random.default_rng(seed)
    used = np.zeros(m, bool)
    V, F = list(V), F.copy()
    new_faces, chosen = [], 0
    for e in rng.permutation(uE.shape[0]):
        h1, h2 = uEE[uEC[e]], uEE[uEC[e] + 1]
        f1, f2 = h1 % m, h2 % m
        if used[f1] or used[f2]:
            continue
        used[f1] = used[f2] = True
        c1, c2 = h1 // m, h2 // m
        # face f1 = (x, a, b) with corner c1 opposite edge (a, b) -> a = F[f1, c1+1], b = F[f1, c1+2]
        a, b, x = F[f1, (c1 + 1) % 3], F[f1, (c1 + 2) % 3], F[f1, c1]
        y = F[f2, c2]  # f2 = (y, b, a)
        p = len(V)
        V.append(V[a] + t * (V[b] - V[a]))
        F[f1] = (x, a, p)
        new_faces.append((x, p, b))
        F[f2] = (y, p, a)
        new_faces.append((y, b, p))
        chosen += 1
        if chosen == n_edges:
            break
    return np.array(V), np.vstack([F, np.array(new_faces, np.int64)])


def split_icosphere(level=3, n_edges=200, t=1e-7, seed=0):
    V, F = icosphere(level)
    return split_edges(V, F, n_edges, t, seed)


def cap_icosphere(level=3, n_faces=200, s=1e-9, seed=0):
    """Icosphere with ``n_faces`` faces (a, b, x) split 1-to-3 at p = m + s (x - m), m the midpoint
    of (a, b): the face (a, b, p) is a cap whose angle at p is within ~2 s of 180 degrees."""
    V, F = icosphere(level)
    rng = np.random.default_rng(seed)
    V = list(V)
    new = []
    for f in rng.choice(F.shape[0], n_faces, replace=False):
        a, b, x = F[f]
        mid = 0.5 * (V[a] + V[b])
        p = len(V)
        V.append(mid + s * (V[x] - mid))
        F[f] = (a, b, p)
        new += [(b, x, p), (x, a, p)]
    return np.array(V), np.vstack([F, np.array(new, np.int64)])


def star_icosphere(level=3, n_vertices=30, t=1e-5, seed=0):
    """Icosphere with every edge around ``n_vertices`` vertices (no two adjacent, no common
    neighbour) split at ``t`` of its length from that vertex: a tiny copy of each star, its
    new vertices pairwise almost opposite across the centre (the configuration whose
    flips first produced a NaN length in the disjoint splits)."""
    V, F = icosphere(level)
    A = igl.adjacency_matrix(F).tocsr()
    rng = np.random.default_rng(seed)
    blocked = np.zeros(V.shape[0], bool)
    centres = []
    for v in rng.permutation(V.shape[0]):
        ring = A[v].indices
        if blocked[v] or blocked[ring].any():
            continue
        centres.append(v)
        blocked[v] = True
        blocked[ring] = True
        for w in ring:
            blocked[A[w].indices] = True
        if len(centres) == n_vertices:
            break
    V, F = list(V), F.tolist()
    for v in centres:
        for w in list(A[v].indices):
            _split(V, F, v, w, t)
    return np.array(V), np.array(F, np.int64)


def _split(V, F, a, b, t):
    """Split edge (a, b) of the face list ``F`` (lists) at ``t`` from ``a``."""
    hit = [(f, c) for f in range(len(F)) for c in range(3)
           if (F[f][(c + 1) % 3], F[f][(c + 2) % 3]) in ((a, b), (b, a))]
    p = len(V)
    V.append(V[a] + t * (V[b] - V[a]))
    for f, c in hit:
        x, u, w = F[f][c], F[f][(c + 1) % 3], F[f][(c + 2) % 3]
        F[f] = [x, u, p]
        F.append([x, p, w])


def grid_cube(n=8):
    """Closed cube [-1, 1]^3, each side an n x n grid of squares cut along one diagonal (flat
    regions: every interior grid vertex has three exactly collinear pairs of neighbours)."""
    Vs, Fs, off = [], [], 0
    u = np.linspace(-1, 1, n + 1)
    A, B = np.meshgrid(u, u, indexing="ij")
    idx = np.arange((n + 1) ** 2).reshape(n + 1, n + 1)
    q = np.stack([idx[:-1, :-1], idx[1:, :-1], idx[1:, 1:], idx[:-1, 1:]], -1).reshape(-1, 4)
    T = np.vstack([q[:, [0, 1, 2]], q[:, [0, 2, 3]]])
    for axis in range(3):
        for sign in (-1.0, 1.0):
            P = np.zeros(((n + 1) ** 2, 3))
            P[:, axis] = sign
            P[:, (axis + 1) % 3] = A.ravel()
            P[:, (axis + 2) % 3] = B.ravel()
            Vs.append(P)
            Fs.append((T if sign > 0 else T[:, ::-1]) + off)
            off += P.shape[0]
    V, F = np.vstack(Vs), np.vstack(Fs)
    V, _, _, F = igl.remove_duplicate_vertices(V, F, 1e-12)
    return np.ascontiguousarray(V), np.ascontiguousarray(F, dtype=np.int64)


def flat_opposite_splits(n=8, t=1e-2, seed=0, k=None):
    """grid_cube(n) with, at interior grid vertices v (no two sharing a face), the two edges to
    v's +u and -u neighbours split at t from v: tiny vertices exactly collinear through v."""
    V, F = grid_cube(n)
    A = igl.adjacency_matrix(F).tocsr()
    rng = np.random.default_rng(seed)
    V, F = list(V), F.tolist()
    used = set()
    done = 0
    for v in rng.permutation(len(V)):
        ring = A[v].indices
        P = np.array(V)[ring] - V[v]
        pair = None
        for i in range(len(ring)):
            for j in range(i + 1, len(ring)):
                c = np.cross(P[i], P[j])
                if np.dot(c, c) < 1e-24 and np.dot(P[i], P[j]) < 0:
                    pair = (ring[i], ring[j])
                    break
            if pair:
                break
        if pair is None:
            continue
        faces = {f for f in range(len(F)) if v in F[f]}
        if faces & used:
            continue
        used |= faces
        for w in pair:
            _split(V, F, v, w, t)
        done += 1
        if k and done == k:
            break
    return np.array(V), np.array(F, np.int64)
