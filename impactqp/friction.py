"""Coulomb friction, public face: FCLib's local contact problems u = W r + q with their
certified solver, the frictional impact law and builders of frictional impacts, and FCLib
files (docs/theory.md §15, §16).

The top level of :mod:`impactqp` keeps :class:`FrictionContactProblem`,
:func:`solve_friction`, :class:`Coulomb`, :func:`load_fclib` and :func:`save_fclib`.
"""

from .io.fclib import load_fclib, save_fclib
from .laws.coulomb import Coulomb
from .laws.friction import FRICTION_BACKENDS, FrictionResult, solve_friction
from .model.friction import FrictionCertificate, FrictionContactProblem
from .model.friction_builders import point_on_plane, sphere_on_plane, two_spheres

__all__ = [
    "FrictionContactProblem", "solve_friction", "FrictionResult", "FrictionCertificate",
    "FRICTION_BACKENDS", "Coulomb", "point_on_plane", "sphere_on_plane", "two_spheres",
    "load_fclib", "save_fclib",
]
