"""Line-by-line Python port of libigl 2.6.3 intrinsic_delaunay_triangulation (with a flip cap and a log).

Same data layout as libigl: l[f, c] is the length of the edge opposite corner c,
half-edge h = f + c * m, Q a LIFO stack of unique-edge ids (duplicates allowed).
"""
import math

import igl
import numpy as np


np.seterr(all="ignore")  # IEEE semantics as in C++: 0/0 = nan, x/0 = inf, sqrt(<0) = nan
one, two = np.float64(1.0), np.float64(2.0)


def tan_half_angle(a, b, c):
    return np.sqrt(((a - b + c) * (a + b - c)) / ((a + b + c) * (-a + b + c)))


def cot_alpha(a, b, c):
    t = tan_half_angle(a, b, c)
    return (one - t * t) / (two * t)


def is_delaunay(l, uE2E, m, ue):
    if len(uE2E[ue]) != 2:
        return True, 0.0
    h1, h2 = uE2E[ue]
    f1, c1, f2, c2 = h1 % m, h1 // m, h2 % m, h2 // m
    e, a, b = l[f1][c1], l[f1][(c1 + 1) % 3], l[f1][(c1 + 2) % 3]
    c, d = l[f2][(c2 + 1) % 3], l[f2][(c2 + 2) % 3]
    w = cot_alpha(e, a, b) + cot_alpha(e, c, d)
    return w >= 0, w


def idt(V, F, max_flips=10**6, log=None, stop_on_nan=False):
    """Returns dict(done, flips, Q, maxQ, l, F[, nan]).  ``stop_on_nan``: stop at the first
    NaN length (libigl never recovers from one: the NaN edge fails the Delaunay test forever)."""
    F = [list(map(int, r)) for r in F]
    m = len(F)
    Ln = igl.edge_lengths(np.asarray(V, float), np.asarray(F, np.int64))
    l = [list(r) for r in Ln]  # np.float64 scalars
    E, uE, EMAP, uEC, uEE = igl.unique_edge_map(np.asarray(F, np.int64))
    EMAP = list(map(int, EMAP))
    uE2E = [list(map(int, uEE[uEC[i]:uEC[i + 1]])) for i in range(len(uEC) - 1)]
    Q = list(range(len(uE2E)))
    flips, maxQ = 0, len(Q)
    while Q:
        ue = Q.pop()
        ok, w = is_delaunay(l, uE2E, m, ue)
        if ok:
            continue
        h1, h2 = uE2E[ue]
        f1, c1, f2, c2 = h1 % m, h1 // m, h2 % m, h2 // m
        v1, v2, v4 = F[f1][(c1 + 1) % 3], F[f1][(c1 + 2) % 3], F[f1][c1]
        v3 = F[f2][c2]
        e, a, b = l[f1][c1], l[f1][(c1 + 1) % 3], l[f1][(c1 + 2) % 3]
        c, d = l[f2][(c2 + 1) % 3], l[f2][(c2 + 2) % 3]
        ta, td = tan_half_angle(a, b, e), tan_half_angle(d, e, c)
        tad = (ta + td) / (one - ta * td)
        cad = (one - tad * tad) / (one + tad * tad)
        fl = np.sqrt(b * b + c * c - two * b * c * cad)
        if stop_on_nan and not np.isfinite(fl):
            return dict(done=False, nan=True, flips=flips, Q=len(Q), maxQ=maxQ, l=np.array(l),
                        F=np.array(F))
        if log is not None and len(log) < 200:
            log.append(dict(flip=flips, ue=ue, w=w, quad=(v1, v2, v3, v4), e=e, a=a, b=b, c=c, d=d,
                            new=fl, Q=len(Q)))
        l[f1] = [fl, b, c]
        l[f2] = [fl, d, a]
        e24, e41 = f1 + ((c1 + 1) % 3) * m, f1 + ((c1 + 2) % 3) * m
        e13, e32 = f2 + ((c2 + 1) % 3) * m, f2 + ((c2 + 2) % 3) * m
        u24, u41, u13, u32 = EMAP[e24], EMAP[e41], EMAP[e13], EMAP[e32]
        F[f1] = [v1, v3, v4]
        F[f2] = [v2, v4, v3]
        n34, n41, n13, n43, n32, n24 = f1, f1 + m, f1 + 2 * m, f2, f2 + m, f2 + 2 * m
        EMAP[n34] = EMAP[n43] = ue
        EMAP[n41], EMAP[n13], EMAP[n32], EMAP[n24] = u41, u13, u32, u24

        def rep(lst, old, new):
            lst[:] = [new if x == old else x for x in lst]
        rep(uE2E[ue], h1, n34)
        rep(uE2E[ue], h2, n43)
        rep(uE2E[u13], e13, n13)
        rep(uE2E[u32], e32, n32)
        rep(uE2E[u24], e24, n24)
        rep(uE2E[u41], e41, n41)
        Q += [u24, u41, u13, u32]
        flips += 1
        maxQ = max(maxQ, len(Q))
        if flips >= max_flips:
            return dict(done=False, flips=flips, Q=len(Q), maxQ=maxQ, l=np.array(l), F=np.array(F))
    return dict(done=True, flips=flips, Q=0, maxQ=maxQ, l=np.array(l), F=np.array(F))
