"""The impact problem: M, W and the pre-impact velocity u⁻ (docs/theory.md §1)."""

from __future__ import annotations

from functools import cached_property
from typing import Any

import numpy as np

from ..base.arrays import Matrix, as_vector
from .admissible import AdmissibleSet
from .structure import ImpactStructure


class ImpactProblem:
    """One impact: M, W and the pre-impact velocity u⁻ (docs/theory.md §1), with
    frictionless contacts (the default) or frictional ones (``contact_dim`` 2 or 3,
    docs/theory.md §16).

    Parameters
    ----------
    M : (n, n) array_like or scipy.sparse matrix
        Mass matrix, symmetric positive definite (the kinetic metric).
    W : (n, d·m) array_like or scipy.sparse matrix
        Generalized force directions of the closed contacts, ``contact_dim = d`` columns per
        contact: the normal first, then the tangents, the velocities of the contact point
        along an orthonormal frame (docs/theory.md §16); no columns means no contact.
    u_minus : (n,) array_like
        Pre-impact generalized velocity. Kinematically inconsistent values (a closed contact
        already separating, γ⁻ᵢ > 0) are legal.
    contact_dim : {1, 2, 3}
        Columns of W per contact: 1 frictionless (the default; every law applies), 2 for
        frictional contacts in the plane, 3 in space (only frictional laws such as
        :class:`~impactqp.Coulomb` apply; :meth:`normal_problem` is the frictionless
        problem of the normal columns).
    structure : ImpactStructure, optional
        An already validated and factorized M and W to reuse (then M, W and
        ``contact_dim`` are ignored); :meth:`from_structure` and :meth:`with_u_minus` pass
        it.

    Raises
    ------
    ShapeError, NonFiniteError, MassMatrixError, InputError
        On malformed input (a column count of W that is not a multiple of ``contact_dim``
        included); all are ``ValueError`` subclasses.
    """

    def __init__(self, M: Matrix, W: Matrix, u_minus: Any, *, contact_dim: int = 1,
                 structure: ImpactStructure | None = None) -> None:
        self.structure = structure if structure is not None else \
            ImpactStructure(M, W, contact_dim=contact_dim)
        self.u_minus = as_vector("u_minus", u_minus, self.structure.n)
        self.u_minus.setflags(write=False)

    @classmethod
    def from_structure(cls, structure: ImpactStructure, u_minus: Any) -> ImpactProblem:
        """A problem on an already validated structure (no re-factorization)."""
        return cls(None, None, u_minus, structure=structure)

    def with_u_minus(self, u_minus: Any) -> ImpactProblem:
        """The same M and W (sharing factorizations) with another pre-impact velocity."""
        return ImpactProblem.from_structure(self.structure, u_minus)

    # --- data ------------------------------------------------------------------------
    M = property(lambda self: self.structure.M, doc="Mass matrix (n, n).")
    W = property(lambda self: self.structure.W, doc="Force directions (n, d·m).")
    n_dof = property(lambda self: self.structure.n, doc="Number of degrees of freedom n.")
    n_contacts = property(lambda self: self.structure.n_contacts,
                          doc="Number of closed contacts m (the columns of W over d).")
    n_impulses = property(lambda self: self.structure.m,
                          doc="Entries of Λ: the columns of W, d per contact.")
    contact_dim = property(lambda self: self.structure.contact_dim,
                           doc="Columns of W per contact d: 1 frictionless, 2 or 3 frictional.")
    chain = property(lambda self: self.structure.chain, doc="ChainInfo for 1-D chains, else None.")
    delassus = property(lambda self: self.structure.delassus, doc="Delassus matrix G = WᵀM⁻¹W.")

    @cached_property
    def gamma_minus(self) -> np.ndarray:
        """Pre-impact contact velocities γ⁻ = Wᵀu⁻ (γ > 0 separates)."""
        return self.structure.Wt_times(self.u_minus)

    def norm(self, u: np.ndarray) -> float:
        """Kinetic norm ‖u‖ = sqrt(uᵀMu) (no overflow or underflow)."""
        return float(self.structure.kinetic_norms(np.asarray(u, dtype=float)))

    def inner(self, a: np.ndarray, b: np.ndarray) -> float:
        """Kinetic inner product ⟨a, b⟩ = aᵀMb."""
        return float(a @ self.structure.mass_rows(b))

    def kinetic_energy(self, u: np.ndarray | None = None) -> float:
        """T = ½uᵀMu (of u⁻ when u is omitted)."""
        u = self.u_minus if u is None else u
        return 0.5 * self.norm(u) ** 2

    @cached_property
    def peak_minus(self) -> float:
        """The largest magnitude of the entries of u⁻, kept: whether u⁻ is within the
        range worked in as given (:data:`!impactqp.base.checks.UNIT_RANGE`,
        docs/theory.md §8)."""
        return float(np.abs(self.u_minus).max(initial=0.0))

    @cached_property
    def norm_minus(self) -> float:
        """‖u⁻‖ (kinetic norm, no overflow or underflow), kept: the certificates' unit V
        (docs/theory.md §8)."""
        return self.norm(self.u_minus)

    @property
    def velocity_scale(self) -> float:
        """‖u⁻‖, the natural velocity unit of certificates (1 when u⁻ = 0)."""
        s = self.norm_minus
        return s if s > 0 else 1.0

    @cached_property
    def moreau_split(self) -> tuple[np.ndarray, np.ndarray]:
        """(z, z⊥): z = prox_{T_C}(u⁻) in the metric M and z⊥ = u⁻ − z (docs/theory.md §1,
        docs/theory.md §3), by the exact projection of :meth:`AdmissibleSet.moreau_split`
        (on the normal columns for frictional contacts); cached."""
        return self.normal_problem().admissible_set().moreau_split()

    def normal_problem(self) -> ImpactProblem:
        """The frictionless problem of the normal columns W[:, ::d] with the same M and u⁻
        (itself when d = 1): what a frictionless law acts on, and what decides T_C and z
        (docs/theory.md §16)."""
        if self.contact_dim == 1:
            return self
        return ImpactProblem.from_structure(self.structure.normal_structure, self.u_minus)

    def admissible_set(self, mu: Any = None) -> AdmissibleSet:
        """The admissible set S of this impact (docs/theory.md §2); for frictional contacts
        the friction coefficients ``mu`` (one or one per contact) are required and the
        impulses lie in the friction cones (docs/theory.md §16)."""
        return AdmissibleSet(self, mu)

    def __repr__(self) -> str:
        kind = "sparse" if self.structure.sparse else "dense"
        d = f", contact_dim={self.contact_dim}" if self.contact_dim > 1 else ""
        return f"ImpactProblem(n_dof={self.n_dof}, n_contacts={self.n_contacts}{d}, {kind})"
