"""Coulomb's law of frictional impacts with Newton's restitution in the normal
(docs/theory.md §16).

At each contact c (d = 2 or 3 columns of W, the normal first) the impulse Λ_c and the
Newton-shifted contact velocity U_c = W_cᵀu⁺ + e_c γ⁻_n,c e_n satisfy De Saxcé's
complementarity Λ_c ∈ K_μc ⟂ U_c + μ_c‖U_T,c‖e_n ∈ K*_μc, with M(u⁺ − u⁻) = WΛ. Eliminating
u⁺ leaves the local problem U = GΛ + q of :class:`~impactqp.FrictionContactProblem`
(G = WᵀM⁻¹W, q = Wᵀu⁻ plus e∘γ⁻_n on the normal rows), posed once in contact units as the
law's program of form ``"friction"`` and solved by the registry's friction methods through the
one certified loop, like any law's program; u⁺ = u⁻ + M⁻¹WΛ, and the law's certificate is the
only one computed.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ..base.arrays import as_array
from ..derivatives.coulomb import coulomb_map
from ..errors import InputError, NonFiniteError, RestitutionError
from ..kernels.coulomb_certificate import (
    COULOMB_RESIDUALS,
    FrictionalAnswer,
    FrictionalSystem,
    LocalFreeVelocity,
    coulomb_residuals,
)
from ..kernels.friction import kernel_mu
from ..model.admissible import AdmissibleSet
from ..model.friction import FrictionContactProblem, certify_friction, friction_coefficients
from ..model.problem import ImpactProblem
from ..model.residuals import (
    DENSE_CONTACTS,
    certificate_operand,
    impact_residuals,
    normalized_rows,
)
from ..model.structure import ImpactStructure
from ..qp.backends import FRICTION
from ..qp.friction import FrictionSolution
from .base import Answer, ImpactLaw
from .friction import FRICTION_BACKENDS

__all__ = ["Coulomb", "local_problem"]


def local_problem(structure: ImpactStructure, u_minus: np.ndarray, mu: np.ndarray,
                  restitution: np.ndarray) -> tuple[FrictionContactProblem, np.ndarray]:
    """The local problem of a frictional impact in each contact's own units
    (docs/theory.md §8, §16).

    Returns (problem, s): with G = WᵀM⁻¹W, q = Wᵀu⁻ + e∘γ⁻_n on the normal rows and
    sᵢ = √G_nn of the contact of entry i (:func:`impactqp.kernels.units.contact_units`,
    through ``structure.contact_delassus``), the problem Ũ = G̃ r + q̃ with G̃ = D G D,
    q̃ = D q and D = diag(1/s): the contacts' columns scaled by 1/s_c, which changes no
    cone, so its reaction r = sΛ solves the impact's problem U = GΛ + q, Ũ = DU. Velocities
    are measured in contact units and r is a velocity, so the natural-map error does not
    depend on the unit of mass or on the length of the columns.

    Parameters
    ----------
    structure : ImpactStructure
        With ``contact_dim`` 2 or 3 and at least one contact.
    u_minus : (n,) ndarray
    mu, restitution : (m,) ndarray
        Per contact.
    """
    d = structure.contact_dim
    q = np.array(structure.Wt_times(u_minus), dtype=float)
    q[::d] *= 1.0 + restitution
    G, s = structure.contact_delassus
    q /= s
    if not np.isfinite(q).all():
        raise NonFiniteError("the local problem's free velocity q is not finite: u⁻ is "
                             "beyond the floats in the contacts' units")
    return FrictionContactProblem.of_contact_units(G, q, mu, d), s


def _coefficient(name: str, value: Any) -> np.ndarray:
    """A coefficient as a float array: one number or one per contact (a 1-D array)."""
    arr = as_array(name, value)
    if arr.ndim > 1:
        raise InputError(f"{name} must be a number or one per contact, got shape {arr.shape}")
    arr.setflags(write=False)
    return arr


class Coulomb(ImpactLaw):
    """Coulomb friction in De Saxcé's form with Newton's restitution in the normal
    (docs/theory.md §16), for problems with frictional contacts (``contact_dim`` 2 or 3).

    Parameters
    ----------
    mu : float or (m,) array_like
        Friction coefficients, one for all contacts or one per contact, each ≥ 0.
    restitution : float or (m,) array_like
        Newton's coefficients e_c ∈ [0, 1] of the normal velocities.
    method : str
        The friction method of the local problem when ``iq.solve`` is called with
        ``backend="auto"``: ``"auto"`` or a name of
        :data:`~impactqp.laws.friction.FRICTION_BACKENDS` (``backend=`` of ``iq.solve``, when
        named, takes precedence).

    Attributes
    ----------
    mu, restitution : ndarray
        The coefficients as given (0-d for one number, (m,) per contact).

    Raises
    ------
    InputError, NonFiniteError, RestitutionError
        A negative, NaN or not numeric μ; e outside [0, 1]; an unknown method.

    Notes
    -----
    A solution exists when W has independent columns, and for μ = 0 with one e (Moreau's
    law); not always otherwise (μ = 0 with unequal eᵢ is local Newton), so an answer that
    no method certifies is a CertificateError, never a claim that none exists.

    A problem with frictionless contacts (``contact_dim = 1``) is refused: it has no
    tangent columns, and ``iq.Newton(e)`` is the law there (the same as Coulomb's with
    μ = 0 on the normal problem).
    """

    name = "coulomb"
    title = "Coulomb's law"
    forms = (FRICTION,)
    by_name = True
    coefficient_keys = ("mu", "e")
    coefficient_symbol = "(μ, e)"
    needs_coefficients = True
    always_solvable = False  # μ = 0 with unequal eᵢ is local Newton, which may have none
    homogeneous = True
    frictional = True
    residual_names = ("momentum", "natural_map", "cone", "complementarity", "non_penetration")

    def __init__(self, mu: Any, restitution: Any = 0.0, *, method: str = "auto") -> None:
        self.mu = _coefficient("mu", mu)
        self.restitution = _coefficient("restitution", restitution)
        if (self.mu < 0).any():
            raise InputError(f"mu must be ≥ 0, got {mu!r}")
        if not np.all((self.restitution >= 0) & (self.restitution <= 1)):
            raise RestitutionError(f"restitution must lie in [0, 1], got {restitution!r}")
        if method not in FRICTION_BACKENDS:
            raise InputError(f"method must be one of {', '.join(FRICTION_BACKENDS)}, got "
                             f"{method!r}")
        self.method = method
        self._per_contact: dict[int, tuple[np.ndarray, np.ndarray]] = {}
        self._operands: tuple[ImpactStructure, FrictionalSystem | None] | None = None
        self._posed: tuple[ImpactStructure, np.ndarray, FrictionContactProblem,
                           np.ndarray] | None = None

    @property
    def default_backend(self) -> str:
        """The backend ``iq.solve(..., backend="auto")`` uses: the law's ``method``."""
        return self.method

    # --- coefficients -----------------------------------------------------------------
    @classmethod
    def from_coefficients(cls, coefficients: Any = None) -> Coulomb:
        """The law named in a file or on the command line by the pair (μ, e) of
        :attr:`coefficients` (keys ``mu`` and ``e``; e None for 0); InputError (or
        NonFiniteError, RestitutionError) for no pair or refused coefficients."""
        if not isinstance(coefficients, tuple) or len(coefficients) != 2:
            raise InputError("law 'coulomb' needs its coefficients as the pair (mu, e): mu "
                             f"required, e optional (default 0); got {coefficients!r}")
        mu, e = coefficients
        if mu is None:
            raise InputError("law 'coulomb' needs its friction coefficient 'mu'")
        return cls(mu) if e is None else cls(mu, e)

    @property
    def coefficients(self) -> tuple[np.ndarray, np.ndarray]:
        """(μ, e) as given."""
        return self.mu, self.restitution

    def per_contact(self, m: int) -> tuple[np.ndarray, np.ndarray]:
        """(μ, e) as one entry per contact for ``m`` contacts, read-only and kept per m (the
        law is immutable); ShapeError or RestitutionError when a per-contact array has
        another length."""
        found = self._per_contact.get(m)
        if found is not None:
            return found
        mu = friction_coefficients(self.mu, m)
        e = self.restitution
        if e.ndim == 0:
            e = np.full(m, float(e))
        elif e.shape != (m,):
            raise RestitutionError(f"restitution must be one number or one per contact "
                                   f"({m},), got shape {e.shape}")
        mu.setflags(write=False)
        e.setflags(write=False)
        self._per_contact[m] = mu, e
        return mu, e

    def coefficients_for(self, problem: ImpactProblem) -> tuple[np.ndarray, np.ndarray]:
        return self.per_contact(problem.n_contacts)

    def restrict(self, contacts: np.ndarray) -> Coulomb:
        mu = self.mu if self.mu.ndim == 0 else self.mu[contacts]
        e = self.restitution if self.restitution.ndim == 0 else self.restitution[contacts]
        return Coulomb(mu, e, method=self.method)

    def check(self, problem: ImpactProblem) -> None:
        if problem.contact_dim == 1:
            raise InputError("Coulomb's law needs frictional contacts: build the problem with "
                             "contact_dim=2 (planar) or 3 (spatial) and d columns of W per "
                             "contact; for frictionless contacts use iq.Newton(e)")
        self.per_contact(problem.n_contacts)

    def admissible_set(self, problem: ImpactProblem) -> AdmissibleSet:
        """S with the law's friction cones (docs/theory.md §16)."""
        return problem.admissible_set(mu=self.per_contact(problem.n_contacts)[0])

    def local_problem(self, problem: ImpactProblem) -> tuple[FrictionContactProblem,
                                                             np.ndarray]:
        """The local problem of this impact in contact units and the units s
        (:func:`local_problem`): its reaction r is sΛ."""
        self.check(problem)
        return self._local(problem.structure, problem.u_minus)

    def _local(self, structure: ImpactStructure,
               u_minus: np.ndarray) -> tuple[FrictionContactProblem, np.ndarray]:
        """:func:`local_problem` of (structure, u⁻), posed once: the program and the
        certificate of one solve share it (u⁻ of a problem is read-only, so the same array
        means the same problem)."""
        posed = self._posed
        if posed is not None and posed[0] is structure and posed[1] is u_minus \
                and not u_minus.flags.writeable:
            return posed[2], posed[3]
        local, units = local_problem(structure, u_minus, *self.per_contact(structure.n_contacts))
        self._posed = structure, u_minus, local, units
        return local, units

    # --- solve ------------------------------------------------------------------------
    def preferred_forms(self, problem: ImpactProblem) -> tuple[str, ...]:
        return self.forms

    def program(self, problem: ImpactProblem, form: str) -> FrictionContactProblem:
        """The local problem in contact units (:meth:`local_problem`), the law's one program
        (form ``"friction"``), for the registry's friction methods (the entry points have
        checked the problem)."""
        return self._local(problem.structure, problem.u_minus)[0]

    def recover(self, problem: ImpactProblem, form: str, solution: FrictionSolution) -> Answer:
        """Λ = r/s and u⁺ = u⁻ + M⁻¹WΛ from the local problem's reaction r."""
        impulses = solution.r / self._local(problem.structure, problem.u_minus)[1]
        u_plus = problem.u_minus + problem.structure.impulse_velocity(impulses)
        return Answer(u_plus, impulses, None)

    def derivative(self, problem: ImpactProblem, answer: Any, *, kink_tol: float) -> Any:
        """Per-contact modes and the implicit function theorem (docs/theory.md §18–§19)."""
        return coulomb_map(self, problem, answer, kink_tol)

    # --- certificate ------------------------------------------------------------------
    def residuals(self, structure: ImpactStructure, U_minus: np.ndarray, U_plus: np.ndarray,
                  impulses: np.ndarray) -> dict[str, Any]:
        """The momentum residual every law shares and the friction checks of the local
        problem recomputed from Λ (docs/theory.md §16): ``natural_map`` ‖F(sΛ)‖/‖q̃‖,
        ``cone`` (Λ in the friction cones) and ``complementarity`` (r_c·ũ_c = 0 contact by
        contact) of the reduced problem in contact units
        (:func:`~impactqp.model.friction.certify_friction`), and
        ``non_penetration`` ‖(−U_n/s)₊‖/‖q̃‖ of the Newton-shifted normal velocity of u⁺
        itself.

        One impact with dense M and W is judged in one compiled pass of the same formulas
        (:func:`~impactqp.kernels.coulomb_certificate.coulomb_residuals`); rows, sparse
        structures and velocities to be rescaled first by :meth:`reference_residuals`."""
        if np.ndim(U_minus) == 1:
            compiled = self._compiled_residuals(structure, U_minus, U_plus, impulses)
            if compiled is not None:
                return compiled
        return self.reference_residuals(structure, U_minus, U_plus, impulses)

    def reference_residuals(self, structure: ImpactStructure, U_minus: np.ndarray,
                            U_plus: np.ndarray, impulses: np.ndarray) -> dict[str, Any]:
        """:meth:`residuals` by numpy products and
        :func:`~impactqp.model.friction.certify_friction` (the reference the compiled pass
        is tested against), one impact (1-D arrays) or rows."""
        U_minus, U_plus, impulses = normalized_rows(U_minus, U_plus, impulses)
        momentum = impact_residuals(structure, U_minus, U_plus, impulses)[1]["momentum"]
        if np.ndim(U_minus) == 1:
            return {"momentum": momentum,
                    **self._friction_residuals(structure, U_minus, U_plus, impulses)}
        rows = [self._friction_residuals(structure, *row)
                for row in zip(U_minus, U_plus, impulses, strict=True)]
        return {"momentum": momentum,
                **{k: np.array([r[k] for r in rows]) for k in FRICTION_RESIDUALS}}

    def _compiled_residuals(self, structure: ImpactStructure, u_minus: np.ndarray,
                            u_plus: np.ndarray, impulses: np.ndarray
                            ) -> dict[str, float] | None:
        """:meth:`residuals` of one impact with dense M and W in one compiled pass
        (:func:`impactqp.kernels.coulomb_certificate.coulomb_residuals`, the same formulas);
        None where it does not apply (sparse or large structures, answers not float vectors
        of the problem's sizes, u⁻ to be rescaled first), and the reference computation
        answers."""
        system = self._system(structure)
        if system is None:
            return None
        n, size = structure.n, structure.m
        for x, length in ((u_minus, n), (u_plus, n), (impulses, size)):
            if not (isinstance(x, np.ndarray) and x.dtype == np.float64
                    and x.shape == (length,)):
                return None
        posed = self._local(structure, u_minus)[0]
        unit = posed.in_contact_units()
        local = LocalFreeVelocity(posed.q, unit.problem.q, unit.k)
        out = np.empty(len(COULOMB_RESIDUALS))
        answer = FrictionalAnswer(u_minus, u_plus, impulses, np.empty(n + 2 * size))
        if not coulomb_residuals(system, local, answer, out):
            return None
        return dict(zip(COULOMB_RESIDUALS, out.tolist(), strict=True))

    def _system(self, structure: ImpactStructure) -> FrictionalSystem | None:
        """The compiled certificate's operands of ``structure``, kept for the last structure
        (None for sparse, chain or very large structures)."""
        kept = self._operands
        if kept is not None and kept[0] is structure:
            return kept[1]
        system = None
        if not structure.sparse and structure.chain is None and 0 < structure.m <= \
                DENSE_CONTACTS:
            G, s = structure.contact_delassus
            mu, e = self.per_contact(structure.n_contacts)
            system = FrictionalSystem(structure.dense_mass, structure.dense_Wt,
                                      certificate_operand(structure),
                                      np.ascontiguousarray(G, dtype=float), s,
                                      kernel_mu(mu), np.ascontiguousarray(e, dtype=float),
                                      structure.contact_dim)
        self._operands = structure, system
        return system

    def _friction_residuals(self, structure: ImpactStructure, u_minus: np.ndarray,
                            u_plus: np.ndarray, impulses: np.ndarray) -> dict[str, float]:
        if structure.m == 0:
            return dict.fromkeys(FRICTION_RESIDUALS, 0.0)
        e = self.per_contact(structure.n_contacts)[1]
        d = structure.contact_dim
        local, units = self._local(structure, u_minus)
        with np.errstate(over="ignore", invalid="ignore"):
            checks = certify_friction(local, units * impulses).values
            shifted_normal = (structure.Wt_times(u_plus)[::d] +
                              e * structure.Wt_times(u_minus)[::d]) / units[::d]
            q_norm = float(np.linalg.norm(local.q))
            penetration = float(np.linalg.norm(np.minimum(shifted_normal, 0.0)))
        return {"natural_map": checks["natural_map"], "cone": checks["cone"],
                "complementarity": checks["complementarity"],
                "non_penetration": penetration / (q_norm if q_norm > 0 else 1.0)}

    def __repr__(self) -> str:
        def show(a: np.ndarray) -> str:
            return np.array2string(a, precision=6) if a.ndim else f"{float(a):g}"
        return f"Coulomb(mu={show(self.mu)}, restitution={show(self.restitution)})"


FRICTION_RESIDUALS = ("natural_map", "cone", "complementarity", "non_penetration")
"""The friction checks of :meth:`Coulomb.residuals`, beside the shared momentum."""
