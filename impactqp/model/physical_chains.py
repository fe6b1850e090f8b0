"""Chains of real spheres: masses from radius and density, Hertz contact stiffnesses from
radius, Young's modulus and Poisson's ratio (docs/theory.md §5, §13).

Two elastic spheres pressed together by δ carry the Hertz force F = Kδ^(3/2) with

    K = (4/3) E* √R*,   1/E* = (1 − ν₁²)/E₁ + (1 − ν₂²)/E₂,   R* = R₁R₂/(R₁ + R₂).

The builders return the chain problem of :func:`~impactqp.chain` (a striker
at v hitting resting, touching balls) together with these stiffnesses, ready for the LZB
model (``LZB(chain.stiffness, exponent=chain.exponent)``). Defaults are the steel of the
chain-of-balls example of Siconos: density 7780 kg/m³, E = 203 GPa, ν = 0.3.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from ..base.arrays import as_array, as_count, as_real
from ..errors import InputError, ShapeError
from .builders import chain
from .problem import ImpactProblem

STEEL_DENSITY = 7780.0
"""kg/m³."""
STEEL_YOUNG = 203e9
"""Pa."""
STEEL_POISSON = 0.3
HERTZ_EXPONENT = 1.5


def _positive(name: str, value: Any) -> np.ndarray:
    arr = as_array(name, value)
    if np.any(arr <= 0):
        raise InputError(f"{name} must be positive, got {arr[arr <= 0][:5].tolist()}")
    return arr


def _poisson(name: str, value: Any) -> np.ndarray:
    arr = as_array(name, value)
    if np.any((arr <= -1.0) | (arr >= 0.5)):
        raise InputError(f"{name} must lie in (-1, 0.5), got {value!r}")
    return arr


def sphere_mass(radius: Any, density: Any = STEEL_DENSITY) -> np.ndarray:
    """Mass (4/3)πR³ρ of spheres.

    Parameters
    ----------
    radius : float or array_like
        Radii in m, positive.
    density : float or array_like
        Densities in kg/m³, positive.

    Returns
    -------
    ndarray
        Masses in kg (broadcast shape of the arguments).

    Raises
    ------
    InputError, NonFiniteError
        Non-positive or non-finite values.
    """
    return 4.0 / 3.0 * np.pi * _positive("radius", radius) ** 3 * _positive("density", density)


def hertz_stiffness(radius_1: Any, radius_2: Any, young: Any = STEEL_YOUNG,
                    poisson: Any = STEEL_POISSON, *, young_2: Any = None,
                    poisson_2: Any = None) -> np.ndarray:
    """Hertz stiffness K of two spheres in contact, F = Kδ^(3/2).

    Parameters
    ----------
    radius_1, radius_2 : float or array_like
        Radii in m.
    young, poisson : float or array_like
        Young's modulus (Pa) and Poisson's ratio of the first sphere (and of the second
        unless ``young_2``, ``poisson_2`` are given).
    young_2, poisson_2 : float or array_like, optional
        Material of the second sphere.

    Returns
    -------
    ndarray
        K = (4/3)E*√R* in N/m^(3/2); for two equal spheres of one material
        K = (2/3)E/(1 − ν²)·√(R/2).

    Raises
    ------
    InputError, NonFiniteError
        Non-positive radii or moduli, ν outside (−1, 0.5).
    """
    r1, r2 = _positive("radius_1", radius_1), _positive("radius_2", radius_2)
    e1, n1 = _positive("young", young), _poisson("poisson", poisson)
    e2 = e1 if young_2 is None else _positive("young_2", young_2)
    n2 = n1 if poisson_2 is None else _poisson("poisson_2", poisson_2)
    effective_modulus = 1.0 / ((1.0 - n1**2) / e1 + (1.0 - n2**2) / e2)
    effective_radius = r1 * r2 / (r1 + r2)
    return 4.0 / 3.0 * effective_modulus * np.sqrt(effective_radius)


@dataclass(frozen=True)
class PhysicalChain:
    """A chain of touching spheres hit by the first one, with its contact stiffnesses.

    Attributes
    ----------
    problem : ImpactProblem
        The free chain (:func:`~impactqp.chain`), u⁻ = (v, 0, …, 0).
    stiffness : (N−1,) ndarray
        Hertz stiffness of each neighbour contact, N/m^(3/2).
    exponent : float
        3/2 (Hertz).
    radii, masses : (N,) ndarray
        m and kg.
    """

    problem: ImpactProblem
    stiffness: np.ndarray
    exponent: float
    radii: np.ndarray
    masses: np.ndarray


def ball_chain(radii: Any, *, velocity: float = 1.0, density: Any = STEEL_DENSITY,
               young: Any = STEEL_YOUNG, poisson: Any = STEEL_POISSON) -> PhysicalChain:
    """A chain of touching spheres of any radii; the first arrives at ``velocity``.

    Parameters
    ----------
    radii : (N,) array_like
        Radii in m, N ≥ 2.
    velocity : float
        Speed of the striker (m/s); the other balls rest.
    density, young, poisson : float or (N,) array_like
        Material of every ball (or of each ball).

    Returns
    -------
    PhysicalChain

    Raises
    ------
    ShapeError, InputError, NonFiniteError
        Fewer than two balls, or non-physical values (named).
    """
    radii = _positive("radii", radii)
    if radii.ndim != 1 or radii.size < 2:
        raise ShapeError(f"radii must be a 1-D array of at least 2 radii, got shape "
                         f"{radii.shape}")
    n = radii.size
    material = {}
    for name, value in (("density", density), ("young", young), ("poisson", poisson)):
        arr = as_array(name, value)
        if arr.ndim > 1 or (arr.ndim == 1 and arr.size != n):
            raise ShapeError(f"{name} must be a scalar or have shape ({n},), got {arr.shape}")
        material[name] = np.broadcast_to(arr, (n,)).copy()
    v = as_real("velocity", velocity)
    masses = sphere_mass(radii, material["density"])
    stiffness = hertz_stiffness(radii[:-1], radii[1:], material["young"][:-1],
                                material["poisson"][:-1], young_2=material["young"][1:],
                                poisson_2=material["poisson"][1:])
    u = np.zeros(n)
    u[0] = v
    return PhysicalChain(chain(masses, u), stiffness, HERTZ_EXPONENT, radii, masses)


def monodisperse_chain(n_balls: int = 10, radius: float = 0.01, **material: Any
                       ) -> PhysicalChain:
    """N equal touching spheres, the first arriving at ``velocity`` (default 1 m/s).

    Parameters
    ----------
    n_balls : int
        N ≥ 2.
    radius : float
        m (default 0.01).
    **material
        ``velocity``, ``density``, ``young``, ``poisson`` as in :func:`ball_chain`
        (default: steel, as in Siconos' chain-of-balls example).

    Returns
    -------
    PhysicalChain
    """
    n = as_count("n_balls", n_balls, minimum=2)
    return ball_chain(np.full(n, as_real("radius", radius, positive=True)), **material)


def tapered_chain(n_balls: int = 10, radius: float = 0.01, taper: float = 0.05,
                  **material: Any) -> PhysicalChain:
    """N touching spheres whose radii shrink by the factor (1 − taper) from ball to ball:
    Rₖ = R(1 − q)^k, the first (largest) being the striker.

    Parameters
    ----------
    n_balls : int
        N ≥ 2.
    radius : float
        Radius of the first ball, m.
    taper : float
        q ∈ [0, 1): 0 is a monodisperse chain.
    **material
        As in :func:`ball_chain`.

    Returns
    -------
    PhysicalChain
    """
    n = as_count("n_balls", n_balls, minimum=2)
    r = as_real("radius", radius, positive=True)
    q = as_real("taper", taper)
    if not 0.0 <= q < 1.0:
        raise InputError(f"taper must lie in [0, 1), got {taper!r}")
    return ball_chain(r * (1.0 - q) ** np.arange(n), **material)
