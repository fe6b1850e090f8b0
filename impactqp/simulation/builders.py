"""Systems to simulate (docs/theory.md §14): a bouncing ball, Newton's cradle on pendulums and
a column of beads under gravity — all 1-D chains of balls in the sense of docs/theory.md §5,
so the sector law and the O(N) isotonic path apply to their impacts; and, with friction
(docs/theory.md §17), a block on an incline, a sphere and a box on a floor.

Each names its coordinates for figures (``y`` the height of a ball, ``x1 … xN`` the
displacements of a cradle's balls, ``x, y, φ`` a sphere's centre and rotation; bodies are
numbered from 1) and describes its bodies for animations
(:class:`~impactqp.simulation.coordinates.Scene`)."""

from __future__ import annotations

from typing import Any

import numpy as np
import scipy.sparse as sp

from ..base.arrays import as_count, as_flag, as_real, as_vector
from ..errors import InputError
from ..model.builders import chain_directions
from ..model.structure import ChainInfo
from .coordinates import Coordinate, Scene
from .system import LinearForce, LinearSystem


def _numbered(name: str, n: int, kind: str = "translation") -> list[Coordinate]:
    """``name`` alone for one body, ``name1 … nameN`` (1-based) for several."""
    if n == 1:
        return [Coordinate(name, kind)]
    return [Coordinate(f"{name}{i + 1}", kind) for i in range(n)]


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
    return LinearSystem(M, [q0], [v0], [-mass * gravity], H, [-radius], chain=info,
                        coordinates=_numbered("y", 1),
                        scene=Scene("vertical balls", {"radius": radius}))


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
    return LinearSystem(M, q0, np.zeros(n), LinearForce(K), H, chain=info,
                        coordinates=_numbered("x", n),
                        scene=Scene("pendulums", {"length": length}))


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
                        chain=info, coordinates=_numbered("y", n),
                        scene=Scene("vertical balls", {"radius": radius}))


def block_on_incline(angle: float, mass: float = 1.0, gravity: float = 9.81, dim: int = 2,
                     position: float = 0.0, speed: float = 0.0, gap: float = 0.0,
                     normal_speed: float = 0.0, twist: float = 0.0) -> LinearSystem:
    """A block (a point mass) on a plane inclined by ``angle``, under gravity, with friction.

    q is the block's position in a fixed frame whose last axis points up; the plane passes
    through the origin and rises along the first axis. Its contact (``contact_dim`` =
    ``dim``) has the plane's unit normal n = (−sin α, [0,] cos α) first and then the
    tangents: in the plane the up-slope direction t = (cos α, sin α); in space the up-slope
    direction (cos α, 0, sin α) and the horizontal (0, 1, 0), both turned about n by
    ``twist`` (Coulomb's cone is isotropic, so the motion does not depend on it). The gap is
    nᵀq. docs/theory.md §17 derives the Moreau–Jean motion in closed form.

    Parameters
    ----------
    angle : float
        α in radians, in [0, π/2).
    mass, gravity : float
        Positive mass and g ≥ 0.
    dim : int
        2 (the plane, q = (x, y)) or 3 (space, q = (x, y, z)).
    position, speed : float
        Initial distance and velocity up the slope.
    gap, normal_speed : float
        Initial height above the plane and velocity along n. A slightly negative ``gap``
        (an overlap of, say, 10⁻⁹) keeps a resting contact closed under the activation rule
        g + ½hγ ≤ 0 against the round-off of nᵀq.
    twist : float
        Angle (radians) of the tangents about the normal in space; unused in the plane.

    Returns
    -------
    LinearSystem
        n = ``dim`` degrees of freedom, one contact with ``contact_dim = dim``.
    """
    angle = as_real("angle", angle, low=0.0)
    if not angle < 0.5 * np.pi:
        raise InputError(f"angle must lie in [0, π/2) radians, got {angle!r}")
    dim = as_count("dim", dim)
    if dim not in (2, 3):
        raise InputError(f"dim must be 2 (the plane) or 3 (space), got {dim}")
    mass = as_real("mass", mass, positive=True)
    gravity = as_real("gravity", gravity, low=0.0)
    position, speed = as_real("position", position), as_real("speed", speed)
    gap, normal_speed = as_real("gap", gap), as_real("normal_speed", normal_speed)
    twist = as_real("twist", twist)
    s, c = np.sin(angle), np.cos(angle)
    if dim == 2:
        normal, up = np.array([-s, c]), np.array([c, s])
        tangents = [up]
    else:
        normal, up, side = np.array([-s, 0.0, c]), np.array([c, 0.0, s]), np.array([0., 1., 0.])
        tangents = [np.cos(twist) * up + np.sin(twist) * side,
                    -np.sin(twist) * up + np.cos(twist) * side]
    H = np.column_stack([normal, *tangents])
    weight = np.zeros(dim)
    weight[-1] = -mass * gravity
    q0 = position * up + gap * normal
    v0 = speed * up + normal_speed * normal
    names = ("x", "y") if dim == 2 else ("x", "y", "z")
    return LinearSystem(mass * np.eye(dim), q0, v0, weight, H, contact_dim=dim,
                        coordinates=[Coordinate(c, "translation") for c in names],
                        scene=Scene("block on incline", {"angle": angle, "dim": dim}))


def rolling_sphere(mass: float = 1.0, radius: float = 0.1, gravity: float = 9.81,
                   velocity: float = 1.0, spin: float = 0.0, height: float | None = None,
                   vertical_velocity: float = 0.0, gap: float = 0.0) -> LinearSystem:
    """A solid sphere on a horizontal floor in the plane, with friction at its lowest point.

    q = (x, y, φ): the centre and the rotation angle (counter-clockwise), with
    M = diag(m, m, I), I = 2/5 mR². The contact has the normal (0, 1, 0) (gap y − R) and the
    tangent (1, 0, R): the slip velocity of the lowest point is ẋ + Rφ̇, zero when the
    sphere rolls. docs/theory.md §17 derives sliding to rolling and the oblique bounce.

    Parameters
    ----------
    mass, radius : float
        Positive mass and radius R.
    gravity : float
        g ≥ 0, acting on y.
    velocity, spin : float
        Initial ẋ and angular velocity φ̇ (ω₀).
    height : float, optional
        Initial y of the centre (R + ``gap`` when omitted; at least R).
    vertical_velocity : float
        Initial ẏ.
    gap : float
        Initial gap of a sphere on the floor when ``height`` is omitted; a slightly negative
        one keeps the contact closed under the activation rule against round-off.

    Returns
    -------
    LinearSystem
        Three degrees of freedom, one contact with ``contact_dim = 2``.
    """
    mass = as_real("mass", mass, positive=True)
    radius = as_real("radius", radius, positive=True)
    gravity = as_real("gravity", gravity, low=0.0)
    velocity, spin = as_real("velocity", velocity), as_real("spin", spin)
    vertical_velocity, gap = as_real("vertical_velocity", vertical_velocity), as_real("gap", gap)
    if height is None:
        height = radius + gap
    else:
        height = as_real("height", height)
        if height < radius:
            raise InputError(f"height must be at least the radius {radius!r}, got {height!r}")
    M = np.diag([mass, mass, 0.4 * mass * radius**2])
    H = np.array([[0.0, 1.0], [1.0, 0.0], [0.0, radius]])
    return LinearSystem(M, [0.0, height, 0.0], [velocity, vertical_velocity, spin],
                        [0.0, -mass * gravity, 0.0], H, [-radius], contact_dim=2,
                        coordinates=[Coordinate("x", "translation"),
                                     Coordinate("y", "translation"),
                                     Coordinate("φ", "rotation")],
                        scene=Scene("sphere", {"radius": radius}))


def box_on_floor(dim: int = 3, mass: float = 1.0, half_sizes: Any = None,
                 gravity: float = 9.81, velocity: Any = 0.0, gap: float = 0.0) -> LinearSystem:
    """A rigid box resting flat on a horizontal floor on its corners, with friction there.

    Small rotations, linearized (constant H): in the plane q = (x, y, φ) and the box stands
    on its two lower corners; in space q = (x, y, z, ρx, ρy, ρz) and it stands on its four
    lower corners, the last coordinate axis pointing up. The contact at a corner p (relative
    to the centre) has the columns (n; p × n) of the floor's normal and then of the
    horizontal axes, so its velocity along a direction n is nᵀ(v + ω × p); the gap is the
    corner's height. M = diag(m, …, I) with the box's principal moments of inertia. A box
    sliding flat decelerates at μg until it stops (docs/theory.md §17).

    Parameters
    ----------
    dim : int
        2 (the plane) or 3 (space).
    mass : float
        Positive mass.
    half_sizes : array_like, optional
        Half the box's sides, horizontal first and the height last ((0.5, 0.25) in the plane,
        (0.5, 0.4, 0.25) in space when omitted), each positive.
    gravity : float
        g ≥ 0.
    velocity : float or (2,) array_like
        The initial horizontal velocity of the centre (one number in the plane).
    gap : float
        Initial height of the corners above the floor; a slightly negative one keeps the
        contacts closed under the activation rule against round-off.

    Returns
    -------
    LinearSystem
        3 (plane) or 6 (space) degrees of freedom; 2 or 4 contacts with ``contact_dim`` =
        ``dim``.
    """
    dim = as_count("dim", dim)
    if dim not in (2, 3):
        raise InputError(f"dim must be 2 (the plane) or 3 (space), got {dim}")
    mass = as_real("mass", mass, positive=True)
    gravity, gap = as_real("gravity", gravity, low=0.0), as_real("gap", gap)
    sizes = np.array([0.5, 0.25] if dim == 2 else [0.5, 0.4, 0.25]) if half_sizes is None \
        else as_vector("half_sizes", half_sizes, dim)
    if not (sizes > 0).all():
        raise InputError(f"half_sizes must be positive, got {sizes.tolist()}")
    horizontal = as_vector("velocity", np.atleast_1d(velocity), dim - 1)
    height = sizes[-1]
    axes = np.eye(dim)
    directions = [axes[-1], *axes[:-1]]  # the normal first, then the horizontal tangents
    if dim == 2:
        a = sizes[0]
        corners = [np.array([x, -height]) for x in (a, -a)]
        inertia = [mass * (a**2 + height**2) / 3.0]
    else:
        a, b = sizes[0], sizes[1]
        corners = [np.array([x, y, -height]) for x in (a, -a) for y in (b, -b)]
        inertia = [mass * (b**2 + height**2) / 3.0, mass * (a**2 + height**2) / 3.0,
                   mass * (a**2 + b**2) / 3.0]
    def moment(p: np.ndarray, d: np.ndarray) -> np.ndarray:  # p × d (its z in the plane)
        return np.cross(p, d) if dim == 3 else np.array([p[0] * d[1] - p[1] * d[0]])

    columns = [np.concatenate([d, moment(p, d)]) for p in corners for d in directions]
    M = np.diag([mass] * dim + inertia)
    n = M.shape[0]
    q0 = np.zeros(n)
    q0[dim - 1] = height + gap
    v0 = np.zeros(n)
    v0[:dim - 1] = horizontal
    weight = np.zeros(n)
    weight[dim - 1] = -mass * gravity
    names = [("x", "translation"), ("y", "translation"), ("φ", "rotation")] if dim == 2 else \
        [(c, "translation") for c in ("x", "y", "z")] + \
        [(c, "rotation") for c in ("ρx", "ρy", "ρz")]
    return LinearSystem(M, q0, v0, weight, np.column_stack(columns),
                        np.full(len(corners), -height), contact_dim=dim, coordinates=names,
                        scene=Scene("box", {"half_sizes": tuple(sizes.tolist()), "dim": dim}))
