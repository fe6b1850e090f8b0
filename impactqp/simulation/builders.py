"""Systems to simulate (docs/theory.md §14): a bouncing ball, Newton's cradle on pendulums and
a column of beads under gravity — all 1-D chains of balls in the sense of docs/theory.md §5,
so the sector law and the O(N) isotonic path apply to their impacts."""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from ..base.arrays import as_count, as_flag, as_real
from ..errors import InputError
from ..model.builders import chain_directions
from ..model.structure import ChainInfo
from .system import LinearForce, LinearSystem


def _chain_matrices(masses: np.ndarray, *, left_wall: bool, sparse: bool):
    M = sp.diags(masses, format="csc") if sparse else np.diag(masses)
    H = chain_directions(masses.size, left_wall=left_wall, sparse=sparse)
    return M, H, ChainInfo(masses=masses.copy(), left_wall=left_wall)


def bouncing_ball(mass: float = 1.0, q0: float = 1.0, v0: float = 0.0, gravity: float = 9.81,
                  radius: float = 0.0) -> LinearSystem:
    """A ball above the ground under gravity: q is its height, the gap is q − radius.

    Parameters
    ----------
    mass : float
        Positive mass m.
    q0, v0 : float
        Initial height and vertical velocity.
    gravity : float
        g ≥ 0; the force is −mg.
    radius : float
        ≥ 0; 0 measures q from the ball's lowest point (as Siconos' BouncingBallTS does).

    Returns
    -------
    LinearSystem
        One degree of freedom, one contact (a chain of one ball against a left wall).
    """
    mass = as_real("mass", mass, positive=True)
    q0, v0 = as_real("q0", q0), as_real("v0", v0)
    gravity, radius = as_real("gravity", gravity, low=0.0), as_real("radius", radius, low=0.0)
    if q0 < radius:
        raise InputError(f"q0 must be at least the radius {radius!r}, got {q0!r}")
    M, H, info = _chain_matrices(np.array([mass]), left_wall=True, sparse=False)
    return LinearSystem(M, [q0], [v0], [-mass * gravity], H, [-radius], chain=info)


def cradle_system(n_balls: int = 3, mass: float = 1.0, length: float = 1.0,
                  gravity: float = 9.81, amplitude: float = 0.1, released: int = 1,
                  sparse: bool | None = None) -> LinearSystem:
    """Newton's cradle: equal balls hanging from pendulums that touch at rest.

    Small-angle pendulum dynamics, stated: qᵢ is the horizontal displacement of ball i from
    its rest position, the restoring force is −(mg/L)qᵢ (a :class:`LinearForce`, potential
    energy ½(mg/L)Σqᵢ²), and the gap between neighbours is q_{i+1} − qᵢ (the pivots are one
    diameter apart). The released balls start at −amplitude, at rest, the others at 0.

    Parameters
    ----------
    n_balls : int
        Number of balls, at least 2.
    mass, length, gravity : float
        Ball mass, pendulum length (positive) and g (≥ 0).
    amplitude : float
        Initial displacement of the released balls (≥ 0).
    released : int
        How many balls, from the left, are pulled out: 1 ≤ released < n_balls.
    sparse : bool, optional
        scipy.sparse matrices (default: when n_balls > 200).

    Returns
    -------
    LinearSystem
        Horizontal displacements of the balls from rest, neighbour gaps as contacts.
    """
    n = as_count("n_balls", n_balls, minimum=2)
    released = as_count("released", released, minimum=1)
    if released >= n:
        raise InputError(f"released must lie in [1, n_balls - 1] = [1, {n - 1}], "
                         f"got {released!r}")
    mass = as_real("mass", mass, positive=True)
    length = as_real("length", length, positive=True)
    gravity = as_real("gravity", gravity, low=0.0)
    amplitude = as_real("amplitude", amplitude, low=0.0)
    sparse = n > 200 if sparse is None else as_flag("sparse", sparse)
    M, H, info = _chain_matrices(np.full(n, mass), left_wall=False, sparse=sparse)
    k = mass * gravity / length
    K = sp.diags(np.full(n, k), format="csr") if sparse else k * np.eye(n)
    q0 = np.zeros(n)
    q0[:released] = -amplitude
    return LinearSystem(M, q0, np.zeros(n), LinearForce(K), H, chain=info)


def bead_chain(n_beads: int = 10, mass: float = 1.0, radius: float = 0.1, height: float = 1.0,
               spacing: float = 0.25, gravity: float = 9.81, velocity: float = 0.0,
               sparse: bool | None = None) -> LinearSystem:
    """A vertical column of equal beads falling onto the ground (as Siconos' ColumnOfBeads).

    qᵢ is the height of the centre of bead i; the ground gap is q₁ − radius, the gap between
    beads q_{i+1} − qᵢ − 2·radius; the force is −mg on every bead.

    Parameters
    ----------
    n_beads : int
        Number of beads, at least 1.
    mass, radius : float
        Bead mass (positive) and radius (≥ 0).
    height : float
        Initial height of the lowest bead's centre (≥ radius).
    spacing : float
        Initial distance between neighbouring centres (≥ 2·radius).
    gravity, velocity : float
        g (≥ 0) and the common initial vertical velocity.
    sparse : bool, optional
        scipy.sparse matrices (default: when n_beads > 200).

    Returns
    -------
    LinearSystem
        The beads' heights, with the ground and neighbour gaps as contacts.
    """
    n = as_count("n_beads", n_beads, minimum=1)
    mass = as_real("mass", mass, positive=True)
    radius = as_real("radius", radius, low=0.0)
    height, spacing = as_real("height", height), as_real("spacing", spacing)
    gravity, velocity = as_real("gravity", gravity, low=0.0), as_real("velocity", velocity)
    if height < radius:
        raise InputError(f"height must be at least the radius {radius!r}, got {height!r}")
    if spacing < 2 * radius:
        raise InputError(f"spacing must be at least a diameter {2 * radius!r}, got {spacing!r}")
    sparse = n > 200 if sparse is None else as_flag("sparse", sparse)
    M, H, info = _chain_matrices(np.full(n, mass), left_wall=True, sparse=sparse)
    b = np.concatenate([[-radius], np.full(n - 1, -2.0 * radius)])
    q0 = height + spacing * np.arange(n)
    return LinearSystem(M, q0, np.full(n, velocity), np.full(n, -mass * gravity), H, b,
                        chain=info)
