"""Spherical harmonics of functions on a spherical map, and their correlation over all rotations.

:func:`sh_coefficients` expands a per-vertex function of a spherical map in
complex spherical harmonics up to a degree ``L`` (sampled on a Gauss-Legendre
grid by point location, then integrated exactly for that degree: Driscoll,
Healy, "Computing Fourier transforms and convolutions on the 2-sphere", Adv.
Appl. Math. 15, 1994).  :func:`rotational_correlation` evaluates

    C(R) = int_{S^2} f(x) g(R^T x) dx

on a grid of ZYZ Euler angles, one 2-D FFT per polar angle (Kovacs, Wriggers,
"Fast rotational matching", Acta Cryst. D 58, 2002), and
:func:`best_rotations` returns its best local maxima, refined.  Registration uses
it to align two conformal maps by their log conformal factors (Baden, Crane,
Kazhdan, "Möbius Registration", SGP 2018).
"""

import functools

import numpy as np
import scipy.special
from scipy.spatial.transform import Rotation

#: Reflection used for the improper half of O(3): ``x -> diag(1, 1, -1) x``.
MIRROR = np.diag([1.0, 1.0, -1.0])


def sample_grid(degree):
    """Gauss-Legendre grid for functions of degree <= ``degree``: directions and weights.

    Returns
    -------
    X : (nt, np_, 3) float64 array
        Unit directions: ``nt = 2 (degree + 1)`` polar nodes, ``np_ = 2 nt`` azimuths.
    theta : (nt,) float64 array
        Polar angles (radians).
    weights : (nt,) float64 array
        Gauss-Legendre weights in ``cos(theta)`` (sum 2).
    """
    nt = 2 * (degree + 1)
    z, w = np.polynomial.legendre.leggauss(nt)
    theta = np.arccos(z)[::-1]
    w = w[::-1]
    phi = 2.0 * np.pi * np.arange(2 * nt) / (2 * nt)
    st = np.sin(theta)[:, None]
    X = np.stack([st * np.cos(phi), st * np.sin(phi),
                  np.repeat(np.cos(theta)[:, None], phi.size, axis=1)], axis=2)
    return X, theta, w


def _legendre(degree, theta):
    """``N_lm P_l^m(cos theta)`` for ``0 <= m <= l <= degree``: (degree+1, degree+1, nt) float64."""
    out = np.zeros((degree + 1, degree + 1, theta.size))
    for m in range(degree + 1):
        ls = np.arange(m, degree + 1)
        out[ls, m] = scipy.special.sph_harm_y(ls[:, None], m, theta[None], 0.0).real
    return out


def sh_coefficients(samples, theta, weights, degree):
    """Complex spherical harmonic coefficients ``f_lm`` of a real function sampled on :func:`sample_grid`.

    Parameters
    ----------
    samples : (nt, np_) float64 array
        The function at the grid's directions.
    theta, weights : (nt,) float64 arrays
        From :func:`sample_grid`.
    degree : int

    Returns
    -------
    (degree + 1, 2 degree + 1) complex128 array
        ``c[l, degree + m] = int f conj(Y_lm)`` (scipy's ``sph_harm_y``, Condon-Shortley
        phase); 0 for ``|m| > l``.
    """
    nphi = samples.shape[1]
    Fm = np.fft.fft(samples, axis=1) * (2.0 * np.pi / nphi)  # int f e^{-i m phi} dphi
    P = _legendre(degree, theta)
    c = np.zeros((degree + 1, 2 * degree + 1), dtype=np.complex128)
    for m in range(degree + 1):
        pos = (P[:, m] * weights) @ Fm[:, m]
        c[:, degree + m] = pos
        if m:
            # real f: f_{l,-m} = (-1)^m conj(f_{l,m})
            c[:, degree - m] = (-1) ** m * np.conj(pos)
    for m in range(1, degree + 1):
        c[:m, degree + m] = c[:m, degree - m] = 0.0
    return c


def standardized_coefficients(values_at, degree):
    """Coefficients (:func:`sh_coefficients`) of a function standardized to mean 0, variance 1.

    Parameters
    ----------
    values_at : callable
        ``values_at(X) -> (k,) float64``, the function at unit directions ``X`` (k, 3).
    degree : int

    Returns
    -------
    (degree + 1, 2 degree + 1) complex128 array
        The correlation of such a function with itself is ``4 pi``.
    """
    X, theta, w = sample_grid(degree)
    s = np.asarray(values_at(X.reshape(-1, 3)), dtype=np.float64).reshape(X.shape[:2])
    wq = np.repeat(w[:, None], s.shape[1], axis=1)
    mean = float(np.sum(wq * s) / np.sum(wq))
    sd = float(np.sqrt(np.sum(wq * (s - mean) ** 2) / np.sum(wq)))
    return sh_coefficients((s - mean) / max(sd, 1e-300), theta, w, degree)


@functools.lru_cache(maxsize=8)
def _jy_eigenvectors(degree):
    """For ``l = 0 .. degree``: the eigenvectors ``V`` ((2l+1, 2l+1) complex) of the angular
    momentum ``J_y`` in the basis ``|l, m>``, columns in the order of its eigenvalues
    ``m = -l .. l`` (``J_y = V diag(m) V^H``)."""
    out = []
    for l in range(degree + 1):
        m = np.arange(-l, l)
        up = np.sqrt(l * (l + 1) - m * (m + 1.0))  # <m+1| J+ |m>
        Jp = np.diag(up, -1)  # column m -> row m + 1
        out.append(np.linalg.eigh((Jp - Jp.T) / 2j)[1])
    return tuple(out)


def wigner_d(degree, beta):
    """Wigner small-d matrices ``d^l(beta) = exp(-i beta J_y)``: (degree+1, 2 degree+1, 2 degree+1).

    Entry ``[l, degree + m, degree + m']`` is ``d^l_{m m'}(beta)`` (real); zero outside ``|m|, |m'| <= l``.
    The exponential is taken on the eigenvectors of ``J_y`` (found once per degree), whose
    eigenvalues are the integers ``-l .. l``: ``d^l = Re(V diag(exp(-i beta m)) V^H)``.
    """
    out = np.zeros((degree + 1, 2 * degree + 1, 2 * degree + 1))
    for l, V in enumerate(_jy_eigenvectors(degree)):
        phase = np.exp(-1j * beta * np.arange(-l, l + 1))
        out[l, degree - l:degree + l + 1, degree - l:degree + l + 1] = ((V * phase) @ V.conj().T).real
    return out


def euler_zyz(alpha, beta, gamma):
    """Rotation matrix ``Rz(alpha) Ry(beta) Rz(gamma)`` (3, 3)."""
    def rz(a):
        c, s = np.cos(a), np.sin(a)
        return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    c, s = np.cos(beta), np.sin(beta)
    ry = np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])
    return rz(alpha) @ ry @ rz(gamma)


def zyz_angles(R):
    """ZYZ Euler angles ``(alpha, beta, gamma)`` of a rotation matrix (inverse of :func:`euler_zyz`)."""
    beta = float(np.arccos(np.clip(R[2, 2], -1.0, 1.0)))
    if np.sin(beta) < 1e-12:  # gimbal lock: only alpha + gamma (or alpha - gamma) matters
        return float(np.arctan2(R[1, 0], R[0, 0])) * (1.0 if R[2, 2] > 0 else -1.0), beta, 0.0
    return (float(np.arctan2(R[1, 2], R[0, 2])), beta, float(np.arctan2(R[2, 1], -R[2, 0])))


def correlation(f, g, R):
    """``C(R) = int f(x) g(R^T x) dx`` from the coefficients of :func:`sh_coefficients` (float)."""
    degree = f.shape[0] - 1
    alpha, beta, gamma = zyz_angles(R)
    m = np.arange(-degree, degree + 1)
    d = wigner_d(degree, beta)
    D = d * np.exp(-1j * m * alpha)[None, :, None] * np.exp(-1j * m * gamma)[None, None, :]
    return float(np.einsum("lm,lmk,lk->", np.conj(f), D, g).real)


def correlation_grid(f, g, n_beta=None, n_angle=None):
    """:func:`correlation` on a ZYZ Euler-angle grid, one 2-D FFT per ``beta``.

    Returns
    -------
    C : (n_beta, n_angle, n_angle) float64 array
        ``C[b, j, k]`` at ``alpha = 2 pi j / n_angle``, ``beta = pi (b + 1/2) / n_beta``,
        ``gamma = 2 pi k / n_angle``.
    betas : (n_beta,) float64 array
    """
    degree = f.shape[0] - 1
    n_beta = n_beta or 2 * (degree + 1)
    n_angle = n_angle or max(4 * (degree + 1), 32)
    betas = np.pi * (np.arange(n_beta) + 0.5) / n_beta
    C = np.empty((n_beta, n_angle, n_angle))
    m = np.arange(-degree, degree + 1) % n_angle
    for b, beta in enumerate(betas):
        T = np.einsum("lm,lmk,lk->mk", np.conj(f), wigner_d(degree, beta), g)
        W = np.zeros((n_angle, n_angle), dtype=np.complex128)
        np.add.at(W, (m[:, None], m[None, :]), T)
        C[b] = np.fft.fft2(W).real
    return C, betas


def best_rotations(f, g, count=4, separation=np.radians(30.0)):
    """The ``count`` best local maxima of :func:`correlation` over rotations, refined.

    The local maxima of :func:`correlation_grid` (grid points not below any of
    their 26 neighbours), best first, are refined by Nelder-Mead on a rotation
    vector; a maximum within ``separation`` radians (the angle of ``R_a^T R_b``)
    of one already kept is skipped.

    Parameters
    ----------
    f, g : complex128 arrays
        Coefficients of :func:`sh_coefficients` (same degree).
    count : int
    separation : float

    Returns
    -------
    list of (float, (3, 3) float64 array)
        ``(C(R), R)``, best first; ``f(x) ~ g(R^T x)`` at a good match.
    """
    from scipy.ndimage import maximum_filter
    from scipy.optimize import minimize

    C, betas = correlation_grid(f, g)
    n = C.shape[1]
    peaks = np.flatnonzero((C == maximum_filter(C, size=3, mode="wrap")).ravel())
    out = []
    for flat in peaks[np.argsort(C.ravel()[peaks])[::-1]]:
        b, j, k = np.unravel_index(flat, C.shape)
        R0 = euler_zyz(2 * np.pi * j / n, betas[b], 2 * np.pi * k / n)
        if any(rotation_angle(R0.T @ Q) < separation for _, Q in out):
            continue
        res = minimize(lambda r, R0=R0: -correlation(f, g, rotvec_matrix(r) @ R0), np.zeros(3),
                       method="Nelder-Mead", options=dict(
                           xatol=1e-4, fatol=1e-10, maxiter=400,
                           initial_simplex=0.05 * np.vstack([np.zeros(3), np.eye(3)])))
        R = rotvec_matrix(res.x) @ R0
        if all(rotation_angle(R.T @ Q) >= separation for _, Q in out):
            out.append((-float(res.fun), R))
        if len(out) == count:
            break
    return sorted(out, key=lambda t: -t[0])


def rotvec_matrix(r):
    """The rotation matrix (3, 3) of the rotation vector ``r`` (3,), radians (``exp([r]_x)``)."""
    return Rotation.from_rotvec(np.asarray(r, dtype=np.float64)).as_matrix()


def rotation_angle(R):
    """The angle (radians, in ``[0, pi]``) of the rotation matrix ``R`` (3, 3)."""
    return float(Rotation.from_matrix(R).magnitude())
