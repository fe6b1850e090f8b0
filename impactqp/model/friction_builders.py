"""Builders of impacts with frictional contacts (docs/theory.md §16): a point mass or a rigid
sphere hitting a fixed plane, and two spheres colliding.

Each returns an :class:`~impactqp.ImpactProblem` with ``contact_dim`` 2 (motion in a plane)
or 3 (in space), chosen by the length of u⁻; the columns of W per contact are the normal
(pointing so that a positive normal velocity separates) and then the tangents. Solve them
with :class:`~impactqp.Coulomb`.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ..base.arrays import as_array, as_real
from ..errors import ShapeError
from .problem import ImpactProblem

__all__ = ["point_on_plane", "sphere_on_plane", "two_spheres"]


def _velocity(u_minus: Any, sizes: tuple[int, int], what: str) -> np.ndarray:
    """u⁻ as a 1-D float array of one of two lengths (planar, spatial)."""
    u = as_array("u_minus", u_minus, ndim=1)
    if u.size not in sizes:
        raise ShapeError(f"u_minus must have {sizes[0]} entries ({what[0]}) or {sizes[1]} "
                         f"({what[1]}), got {u.size}")
    return u


def _inertia(inertia: Any, mass: float, radius: float) -> float:
    """The moment of inertia about a diameter: given, or a solid sphere's 2/5 m R²."""
    if inertia is None:
        return 0.4 * mass * radius ** 2
    return as_real("inertia", inertia, positive=True)


def point_on_plane(mass: float, u_minus: Any) -> ImpactProblem:
    """A point mass hitting the fixed plane below it, with friction.

    Parameters
    ----------
    mass : float
        Positive mass.
    u_minus : (2,) or (3,) array_like
        Pre-impact velocity: (vₓ, v_y) in the plane, the plane being y = 0 (normal +y), or
        (vₓ, v_y, v_z) in space, the plane z = 0 (normal +z). A falling mass has a negative
        last entry.

    Returns
    -------
    ImpactProblem
        One contact with ``contact_dim`` 2 (columns: normal y, tangent x) or 3 (normal z,
        tangents x and y).

    Raises
    ------
    InputError, NonFiniteError, ShapeError
        A mass that is not a positive finite number; u⁻ of another length or not finite.
    """
    mass = as_real("mass", mass, positive=True)
    u = _velocity(u_minus, (2, 3), ("planar", "spatial"))
    d = u.size
    W = np.zeros((d, d))
    W[d - 1, 0] = 1.0  # normal: the last coordinate
    for j in range(d - 1):
        W[j, j + 1] = 1.0  # tangents: the others
    return ImpactProblem(mass * np.eye(d), W, u, contact_dim=d)


def sphere_on_plane(mass: float, radius: float, u_minus: Any, *,
                    inertia: Any = None) -> ImpactProblem:
    """A rigid sphere (or disk) hitting the fixed plane below it, with friction at the
    contact point.

    Parameters
    ----------
    mass, radius : float
        Positive mass and radius.
    u_minus : (3,) or (6,) array_like
        Planar motion (vₓ, v_y, ω), the plane y = 0, ω about z (counter-clockwise): the
        contact point slides at vₓ + Rω. Spatial motion (vₓ, v_y, v_z, ωₓ, ω_y, ω_z), the
        plane z = 0: the contact point slides at (vₓ − Rω_y, v_y + Rωₓ).
    inertia : float, optional
        Moment of inertia about a diameter; default 2/5 m R² (a solid sphere, whose
        effective tangential mass at the contact is 2/7 m).

    Returns
    -------
    ImpactProblem
        One contact: ``contact_dim`` 2 (normal, tangent x) or 3 (normal, tangents x, y).

    Raises
    ------
    InputError, NonFiniteError, ShapeError
        Non-positive or non-finite mass, radius or inertia; u⁻ of another length.
    """
    mass = as_real("mass", mass, positive=True)
    radius = as_real("radius", radius, positive=True)
    inertia = _inertia(inertia, mass, radius)
    u = _velocity(u_minus, (3, 6), ("planar: vx, vy, ω", "spatial: v, ω"))
    if u.size == 3:
        M = np.diag([mass, mass, inertia])
        W = np.array([[0.0, 1.0], [1.0, 0.0], [0.0, radius]])
        return ImpactProblem(M, W, u, contact_dim=2)
    M = np.diag([mass] * 3 + [inertia] * 3)
    W = np.zeros((6, 3))
    W[2, 0] = 1.0
    W[0, 1], W[4, 1] = 1.0, -radius  # x: vₓ − Rω_y
    W[1, 2], W[3, 2] = 1.0, radius   # y: v_y + Rωₓ
    return ImpactProblem(M, W, u, contact_dim=3)


def _tangents(normal: np.ndarray) -> np.ndarray:
    """Unit tangents completing ``normal``: (−n_y, nₓ) in the plane; in space t₁ ⟂ n built
    from the axis least aligned with n, and t₂ = n × t₁."""
    if normal.size == 2:
        return np.array([[-normal[1], normal[0]]])
    axis = np.zeros(3)
    axis[int(np.argmin(np.abs(normal)))] = 1.0
    t1 = np.cross(normal, axis)
    t1 /= np.linalg.norm(t1)
    return np.array([t1, np.cross(normal, t1)])


def two_spheres(masses: Any, radii: Any, u_minus: Any, *, normal: Any = None,
                inertias: Any = None) -> ImpactProblem:
    """Two rigid spheres (or disks) in contact, with friction at the contact point.

    Parameters
    ----------
    masses, radii : (2,) array_like
        Positive masses and radii of sphere 1 and sphere 2.
    u_minus : (6,) or (12,) array_like
        Planar motion: (vₓ, v_y, ω) of sphere 1 then of sphere 2. Spatial motion:
        (v, ω) of sphere 1 then of sphere 2 (three entries each).
    normal : (2,) or (3,) array_like, optional
        Direction from the centre of sphere 1 to that of sphere 2 (normalized here); default
        the x axis. The normal contact velocity n·(v₂ − v₁) is negative when they approach.
    inertias : (2,) array_like, optional
        Moments of inertia; default 2/5 m R² each (solid spheres).

    Returns
    -------
    ImpactProblem
        One contact, ``contact_dim`` 2 or 3: the normal column, then the tangents
        (t = ẑ × n in the plane; t₁, t₂ = n × t₁ in space).

    Raises
    ------
    InputError, NonFiniteError, ShapeError
        Non-positive or non-finite masses, radii or inertias, a zero normal, lengths that do
        not fit.
    """
    m = [as_real(f"masses[{i}]", v, positive=True)
         for i, v in enumerate(as_array("masses", masses, ndim=1))]
    R = [as_real(f"radii[{i}]", v, positive=True)
         for i, v in enumerate(as_array("radii", radii, ndim=1))]
    if len(m) != 2 or len(R) != 2:
        raise ShapeError(f"masses and radii must hold two entries each, got {len(m)} and "
                         f"{len(R)}")
    inert = [None, None] if inertias is None else list(as_array("inertias", inertias, ndim=1))
    if len(inert) != 2:
        raise ShapeError(f"inertias must hold two entries, got {len(inert)}")
    inert = [_inertia(inert[i], m[i], R[i]) for i in range(2)]
    u = _velocity(u_minus, (6, 12), ("planar", "spatial"))
    planar = u.size == 6
    dim = 2 if planar else 3
    n = np.eye(dim)[0] if normal is None else as_array("normal", normal, ndim=1)
    if n.size != dim:
        raise ShapeError(f"normal must have {dim} entries for this motion, got {n.size}")
    if not np.linalg.norm(n) > 0:
        raise ShapeError("normal must be a non-zero direction")
    n = n / np.linalg.norm(n)
    k = 3 if planar else 6  # entries per sphere
    M = np.diag([m[0]] * dim + [inert[0]] * (k - dim) + [m[1]] * dim + [inert[1]] * (k - dim))
    W = np.zeros((2 * k, dim))
    W[:dim, 0], W[k:k + dim, 0] = -n, n
    for j, t in enumerate(_tangents(n), start=1):
        W[:dim, j], W[k:k + dim, j] = -t, t
        # the contact points R₁n and −R₂n add t·(ω × a) = ω·(a × t) to the slip
        spin = 1.0 if planar else np.cross(n, t)
        W[dim:k, j] = -R[0] * spin
        W[k + dim:, j] = -R[1] * spin
    return ImpactProblem(M, W, u, contact_dim=dim)
