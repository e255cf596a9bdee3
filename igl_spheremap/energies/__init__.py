"""Energies of spherical maps minimized by Algorithm 1 (:func:`igl_spheremap.algorithm1.minimize`)."""

from .base import Energy, Evaluation
from .harmonic import HarmonicEnergy
from .landmark import LandmarkEnergy
from .p_harmonic import PHarmonicEnergy

__all__ = ["Energy", "Evaluation", "HarmonicEnergy", "LandmarkEnergy", "PHarmonicEnergy"]
