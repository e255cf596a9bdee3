"""Energies of spherical maps minimized by Algorithm 1 (:func:`igl_spheremap.algorithm1.minimize`)."""

from .base import Energy, Evaluation
from .harmonic import HarmonicEnergy

__all__ = ["Energy", "Evaluation", "HarmonicEnergy"]
