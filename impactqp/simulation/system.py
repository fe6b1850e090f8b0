"""A linear mechanical system with unilateral contacts (docs/theory.md §14):

    M q̈ = f(t, q, q̇) + H Λ̇,      g = Hᵀq + b ≥ 0,      Λ ≥ 0,

with a constant symmetric positive definite mass matrix M (dense or scipy.sparse), one column
of H per contact (the contact matrix W of every impact is H restricted to the closed contacts)
and an external force that is a constant vector, a :class:`LinearForce` c − Kq, or any
callable force(t, q, v). With friction (``contact_dim`` d = 2 or 3, docs/theory.md §17) H
holds d columns per contact, the normal first and then the tangents; the gaps use the normal
columns only.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
import scipy.sparse as sp

from ..base.arrays import Matrix, as_count, as_matrix, as_vector
from ..errors import InputError, MassMatrixError, NonFiniteStateError, ShapeError
from ..model.builders import chain_directions
from ..model.structure import ChainInfo, ImpactStructure
from .coordinates import Coordinate, Scene, as_coordinates

Force = Callable[[float, np.ndarray, np.ndarray], Any]

CONTACT_DIMS = (1, 2, 3)
"""Columns of H per contact: frictionless, planar friction, spatial friction."""


class LinearForce:
    """The force f(q) = c − Kq of springs and of uniform fields, with its potential.

    Parameters
    ----------
    stiffness : (n, n) array_like or scipy.sparse matrix
        K, symmetric positive semidefinite (not checked beyond symmetry).
    constant : (n,) array_like, optional
        c (gravity, say); zero when omitted.

    Raises
    ------
    ShapeError, NonFiniteError
        K not square, c of another length, non-finite entries.
    MassMatrixError
        K not symmetric.
    """

    def __init__(self, stiffness: Matrix, constant: Any = None) -> None:
        K = as_matrix("stiffness", stiffness)
        if K.ndim != 2 or K.shape[0] != K.shape[1]:
            raise ShapeError(f"stiffness must be a square (n, n) matrix, got shape {K.shape}")
        asym = abs(K - K.T).max() if sp.issparse(K) else np.abs(K - K.T).max(initial=0.0)
        scale = abs(K).max() if sp.issparse(K) else np.abs(K).max(initial=0.0)
        if asym > 1e-12 * max(scale, 1e-300):
            raise MassMatrixError(f"stiffness must be symmetric; max |K - Kᵀ| = {asym:.3g}")
        n = K.shape[0]
        self.stiffness = sp.csr_matrix(K) if sp.issparse(K) else K
        self.constant = np.zeros(n) if constant is None else as_vector("constant", constant, n)

    @property
    def n(self) -> int:
        """Number of degrees of freedom."""
        return self.constant.size

    def __call__(self, t: float, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        return self.constant - self.stiffness @ q

    def potential(self, q: np.ndarray) -> float:
        """V(q) = ½qᵀKq − cᵀq, so that f = −∇V."""
        return float(0.5 * q @ (self.stiffness @ q) - self.constant @ q)


def _check_force(force: Any, n: int) -> tuple[Force, Callable[[np.ndarray], float] | None,
                                              np.ndarray | None]:
    """(callable, potential or None, constant vector or None) from the user's force."""
    if force is None:
        force = np.zeros(n)
    if isinstance(force, LinearForce):
        if force.n != n:
            raise ShapeError(f"force acts on {force.n} degrees of freedom, the system has {n}")
        return force, force.potential, None
    if callable(force):
        return force, None, None
    f = as_vector("force", force, n)
    f.setflags(write=False)
    return (lambda t, q, v: f), (lambda q: float(-f @ q)), f


class LinearSystem:
    """Motion of a linear mechanical system with unilateral contacts (docs/theory.md §14).

    Parameters
    ----------
    M : (n, n) array_like or scipy.sparse matrix
        Constant mass matrix, symmetric positive definite.
    q0, v0 : (n,) array_like
        Initial generalized positions and velocities.
    force : (n,) array_like, LinearForce or callable, optional
        External force: a constant vector, ``LinearForce(K, c)`` (c − Kq), or any callable
        ``force(t, q, v)`` returning an (n,) array. Zero when omitted.
    H : (n, d·m) array_like or scipy.sparse matrix, optional
        d = ``contact_dim`` columns per contact, the normal hᵢ first: gap gᵢ = hᵢᵀq + bᵢ, open
        when positive (docs/theory.md §12 for the sign); then the d − 1 tangents of a
        frictional contact (docs/theory.md §17). No contact when omitted.
    b : (m,) array_like, optional
        Gap offsets (zero when omitted).
    potential : callable, optional
        V(q) with f = −∇V, for a callable force; constant and linear forces bring their own.
        Without one the potential energy of a callable force is reported as NaN.
    chain : ChainInfo, optional
        Marks a 1-D chain of balls (docs/theory.md §5): M = diag(masses) and H in the column
        order of :func:`impactqp.chain`, checked here. Chains are what the sector law and the
        O(N) isotonic path need. Frictionless systems only.
    contact_dim : int
        d, the columns of H per contact: 1 (frictionless, the default), 2 (normal and one
        tangent, motion in the plane) or 3 (normal and two tangents, in space). A system with
        d > 1 is simulated with ``iq.Coulomb(mu, restitution)``.
    coordinates : sequence, optional
        What each qᵢ is, for figures: n entries, each a
        :class:`~impactqp.simulation.coordinates.Coordinate` (name, kind, unit), a name or a
        pair (name, kind) with kind ``"translation"``, ``"rotation"`` or ``"generalized"``.
        Default ``q1 … qn`` of unknown kind. The builders name theirs (``x``, ``y``, ``φ``).
    scene : Scene, optional
        The bodies an animation draws (the builders set it; a system built from matrices
        has none and :meth:`Trajectory.animate <impactqp.Trajectory.animate>` refuses it).

    Attributes
    ----------
    coordinates : tuple of Coordinate
        One per degree of freedom.
    scene : Scene or None

    Raises
    ------
    ShapeError, NonFiniteError, MassMatrixError, InputError
        On malformed input, naming the argument.
    """

    def __init__(self, M: Matrix, q0: Any, v0: Any, force: Any = None, H: Matrix = None,
                 b: Any = None, *, potential: Callable[[np.ndarray], float] | None = None,
                 chain: ChainInfo | None = None, contact_dim: int = 1,
                 coordinates: Any = None, scene: Scene | None = None) -> None:
        d = as_count("contact_dim", contact_dim, minimum=1)
        if d not in CONTACT_DIMS:
            raise InputError(f"contact_dim must be one of {CONTACT_DIMS} (frictionless, planar "
                             f"or spatial friction), got {d}")
        if d > 1 and chain is not None:
            raise InputError(f"chain marks frictionless chains of balls; a system with "
                             f"contact_dim = {d} takes none")
        M = as_matrix("M", M)
        if M.ndim != 2 or M.shape[0] != M.shape[1] or M.shape[0] == 0:
            raise ShapeError(f"M must be a non-empty square (n, n) matrix, got shape {M.shape}")
        n = M.shape[0]
        H = np.zeros((n, 0)) if H is None else as_matrix("H", H)
        if H.ndim != 2 or H.shape[0] != n:
            raise ShapeError(f"H must have shape (n, m) = ({n}, m), one column per contact, "
                             f"got {H.shape}")
        if H.shape[1] % d:
            raise ShapeError(f"H must hold contact_dim = {d} columns per contact (normal, then "
                             f"tangents), got {H.shape[1]} columns")
        norms = np.asarray(abs(H).sum(axis=0)).ravel()
        if np.any(norms == 0):
            raise ShapeError(f"H column(s) {np.flatnonzero(norms == 0).tolist()[:5]} are zero: "
                             "every contact needs a non-zero direction")
        self.contact_dim = d
        self.structure = ImpactStructure(M, H, chain=self._check_chain(chain, M, H),
                                         contact_dim=d)
        n, m = self.structure.n, self.structure.n_contacts
        self.q0 = as_vector("q0", q0, n)
        self.v0 = as_vector("v0", v0, n)
        self.b = np.zeros(m) if b is None else as_vector("b", b, m)
        self.coordinates: tuple[Coordinate, ...] = as_coordinates(coordinates, n)
        if scene is not None and not isinstance(scene, Scene):
            raise InputError(f"scene must be an impactqp Scene, got {type(scene).__name__}")
        self.scene = scene
        self.force, self._potential, self.constant_force = _check_force(force, n)
        if potential is not None:
            if not callable(potential):
                raise InputError(f"potential must be a callable V(q), got "
                                 f"{type(potential).__name__}")
            self._potential = potential
        self.linear_force = force if isinstance(force, LinearForce) else None
        as_vector("force(0, q0, v0)", self.force(0.0, self.q0, self.v0), n)
        normals = self.H[:, ::d]
        self.Ht = sp.csr_matrix(normals.T) if self.structure.sparse else np.asarray(normals).T

    @staticmethod
    def _check_chain(chain: Any, M: Matrix, H: Matrix) -> ChainInfo | None:
        if chain is None:
            return None
        if not isinstance(chain, ChainInfo):
            raise InputError(f"chain must be an impactqp ChainInfo, got {type(chain).__name__}")
        n = chain.masses.size
        Ms, Hs = sp.csr_matrix(M), sp.csr_matrix(as_matrix("H", H))
        if Ms.shape != (n, n) or (Ms - sp.diags(chain.masses)).count_nonzero():
            raise InputError("chain: M must be diag(chain.masses)")
        W = chain_directions(n, left_wall=chain.left_wall, right_wall=chain.right_wall,
                             sparse=True)
        if Hs.shape != W.shape or (Hs - W).count_nonzero():
            raise InputError("chain: H must hold the chain's contact directions in the order "
                             "[left wall, q₂ − q₁, …, q_N − q_{N−1}, right wall] "
                             "(impactqp.model.builders.chain_directions)")
        return chain

    # --- data ----------------------------------------------------------------------------
    M = property(lambda self: self.structure.M, doc="Mass matrix (n, n).")
    H = property(lambda self: self.structure.W,
                 doc="Contact directions (n, d·m): per contact the normal, then the tangents.")
    n_dof = property(lambda self: self.structure.n, doc="Number of degrees of freedom n.")
    n_contacts = property(lambda self: self.structure.n_contacts, doc="Number of contacts m.")
    chain = property(lambda self: self.structure.chain, doc="ChainInfo of a 1-D chain, or None.")

    # --- contact geometry and energy -----------------------------------------------------
    def gaps(self, q: np.ndarray) -> np.ndarray:
        """g = Hᵀq + b (normal columns of H) for a position or every row of a (k, n) array."""
        return np.asarray(self.Ht @ np.asarray(q).T).T + self.b

    def contact_velocities(self, v: np.ndarray) -> np.ndarray:
        """γ = Hᵀv on the normal columns (γᵢ > 0 opens contact i) for a velocity or every row
        of a (k, n) array."""
        return np.asarray(self.Ht @ np.asarray(v).T).T

    def force_at(self, t: float, q: np.ndarray, v: np.ndarray) -> np.ndarray:
        """The external force as a float vector.

        Raises
        ------
        NonFiniteStateError
            When the force (or the state it is evaluated at) is not finite, with the time.
        """
        f = np.asarray(self.force(t, q, v), dtype=float)
        if not np.isfinite(f).all():
            raise NonFiniteStateError(f"the force is not finite at t = {t:.12g} (q or v NaN or "
                                      "infinite, or the force function returned NaN/inf)")
        return f

    def kinetic_energy(self, v: np.ndarray) -> np.ndarray | float:
        """T = ½vᵀMv of a velocity or of every row of a (k, n) array."""
        v = np.asarray(v, dtype=float)
        return 0.5 * np.sum(self.structure.mass_rows(v) * v, axis=-1)

    def potential_energy(self, q: np.ndarray) -> np.ndarray | float:
        """V(q) of a position or of every row; NaN for a callable force without potential."""
        q = np.asarray(q, dtype=float)
        if self._potential is None:
            return np.full(q.shape[:-1], np.nan) if q.ndim > 1 else float("nan")
        if q.ndim == 1:
            return float(self._potential(q))
        K = self.linear_force
        if K is not None:
            return 0.5 * np.sum(np.asarray(K.stiffness @ q.T).T * q, axis=-1) - q @ K.constant
        if self.constant_force is not None:
            return -(q @ self.constant_force)
        return np.array([self._potential(row) for row in q])

    def energy(self, q: np.ndarray, v: np.ndarray) -> np.ndarray | float:
        """Total mechanical energy T + V."""
        return self.kinetic_energy(v) + self.potential_energy(q)

    def __repr__(self) -> str:
        kind = "chain" if self.chain is not None else \
            ("sparse" if self.structure.sparse else "dense")
        dim = f", contact_dim={self.contact_dim}" if self.contact_dim > 1 else ""
        return f"LinearSystem(n_dof={self.n_dof}, n_contacts={self.n_contacts}{dim}, {kind})"
