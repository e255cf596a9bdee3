"""Maps between two triangulations of one surface of very different sizes, and tiny surfaces
(``surface_map``).

The correspondence is known: a decimation of the fish and the fish itself.  What is checked
is that the call returns (no crash) and that its verdict agrees with the result it returns;
accuracy on such pairs is measured by ``benchmarks`` scripts, not asserted here.
"""

import subprocess
import sys
import textwrap

from conftest import DATA

# A 22-vertex surface 1 (the fish decimated by igl.decimate to 40 faces) with 15 of its
# vertices as hard landmarks, paired with the nearest vertices of the fish: the distortion
# stage's global step then solves a 7- or 8-row system.  Run in a child process: CHOLMOD
# (sksparse-minimal) corrupted the heap on it and glibc aborted the interpreter.
TINY_SURFACE_1 = textwrap.dedent("""
    import warnings
    import igl
    import numpy as np
    from igl_spheremap import count_folds, surface_map
    V, F = igl.read_triangle_mesh({path!r})
    Vd, Fd, _, _ = igl.decimate(V, F, 40)
    Vd, Fd = np.asarray(Vd), np.asarray(Fd, np.int64)
    assert Vd.shape[0] == 22
    l1 = np.arange(15)
    l2 = np.array([int(np.argmin(((V - Vd[i]) ** 2).sum(1))) for i in l1])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        r = surface_map(Vd, Fd, V, F, l1, l2, workers=1)
    met = np.linalg.norm(np.asarray(r.P @ V)[l1] - V[l2], axis=1).max() <= 1e-9 * np.sqrt(
        igl.doublearea(V, F).sum() / 2)
    folds = count_folds(r.map1.F, r.map1.U) + count_folds(r.map2.F, r.map2.U)
    assert r.success == (bool(met) and folds == 0), (r.success, met, folds)
    print("returned")
""")


def test_tiny_surface_1_with_many_landmarks_returns():
    code = TINY_SURFACE_1.format(path=str(DATA / "fish_lowres.obj"))
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         timeout=600)
    assert run.returncode == 0 and "returned" in run.stdout, run.stderr[-2000:]


# A 6-vertex surface (the octahedron) onto a stretched copy with 4 landmarks: the functional
# map's Laplace basis factorizes a 6-row matrix, where CHOLMOD corrupted the heap too.
OCTAHEDRON = textwrap.dedent("""
    import warnings
    import numpy as np
    from igl_spheremap import count_folds, surface_map
    V = np.array([[1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1]], float)
    F = np.array([[0, 2, 4], [2, 1, 4], [1, 3, 4], [3, 0, 4], [2, 0, 5], [1, 2, 5], [3, 1, 5],
                  [0, 3, 5]])
    lm = np.array([0, 1, 2, 5])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        r = surface_map(V, F, V * [1.0, 1.2, 0.9], F, lm, lm, workers=1)
    assert count_folds(r.map1.F, r.map1.U) == 0 == count_folds(r.map2.F, r.map2.U)
    assert abs(r.P.sum(axis=1) - 1).max() < 1e-12
    print("returned")
""")


def test_a_six_vertex_surface_returns():
    run = subprocess.run([sys.executable, "-c", OCTAHEDRON], capture_output=True, text=True,
                         timeout=600)
    assert run.returncode == 0 and "returned" in run.stdout, run.stderr[-2000:]
