"""Chains of spheres and the dispersive LZB model of their impacts, public face: physical
chains with Hertz stiffnesses and the LZB law with its answer, certificate and record
(docs/theory.md §13). :func:`impactqp.verification.compare_chain` sets the rigid laws beside
it.

The top level of :mod:`impactqp` keeps :class:`LZB`.
"""

from .laws.lzb import LZB, LZBAnswer, LZBCertificate, LZBRecord
from .model.physical_chains import (
    PhysicalChain,
    ball_chain,
    hertz_stiffness,
    monodisperse_chain,
    sphere_mass,
    tapered_chain,
)

__all__ = [
    "LZB", "LZBAnswer", "LZBCertificate", "LZBRecord", "PhysicalChain", "ball_chain",
    "monodisperse_chain", "tapered_chain", "hertz_stiffness", "sphere_mass",
]
