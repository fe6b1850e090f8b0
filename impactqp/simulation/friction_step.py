"""Coulomb friction in one Moreau–Jean step, in step form (docs/theory.md §17).

On the contacts the step closes (:func:`impactqp.kernels.step.activation`, the rule of every
loop), the local problem of docs/theory.md §15,

    u = W r + q,    W = H_AᵀŴ⁻¹H_A,    q = H_Aᵀv_free + e ∘ γ_k (on the normal rows),

with the step's q of :func:`impactqp.kernels.step.step_q`, is gathered in contact units by
:func:`impactqp.kernels.step.gather_local` and solved and certified by
:func:`impactqp.solve_friction` (:class:`FrictionSolver`); then v_{k+1} = v_free + Ŵ⁻¹H_A r
and u is the local velocity H_Aᵀv_{k+1} shifted by eγ_k on the normal rows, as Newton's law
at velocity level reads it (Siconos' NewtonImpactFrictionNSL).
"""

from __future__ import annotations

from collections.abc import Callable
from functools import cached_property, partial

import numpy as np
import scipy.sparse as sp

from ..base.checks import FRICTION_TOL, Certificate
from ..errors import CertificateError, InputError, ShapeError
from ..kernels.friction import project_cones
from ..kernels.step import gather_local, step_q
from ..kernels.units import contact_units
from ..laws.coulomb import Coulomb
from ..laws.friction import FRICTION_BACKENDS, FrictionResult, solve_friction
from ..model.friction import FrictionContactProblem
from .system import LinearSystem

NEEDS_TANGENTS = ("Coulomb friction needs tangent columns: build the LinearSystem with "
                  "contact_dim=2 (plane) or 3 (space), H holding the normal and then the "
                  "tangents of each contact")
"""The refusal of Coulomb's law on a frictionless system."""

_NO_MATRIX = np.zeros((0, 0))
"""The restitution matrix of :func:`impactqp.kernels.step.step_q` for Coulomb's one
coefficient per contact."""

MAX_CACHED = 4096
"""Closed sets whose W and Ŵ⁻¹H_A are kept per run; the cache starts afresh when full."""


def coulomb_coefficients(law: Coulomb, system: LinearSystem) -> tuple[np.ndarray, np.ndarray]:
    """(μ, e), one of each per contact of ``system``, from the law's scalars or vectors.

    Raises
    ------
    InputError
        A system without friction columns (``contact_dim`` 1).
    ShapeError
        μ or e given per contact for another number of contacts.
    """
    if system.contact_dim == 1:
        raise InputError(NEEDS_TANGENTS)
    m = system.n_contacts
    out = []
    for name, value in (("mu", law.mu), ("restitution", law.restitution)):
        value = np.asarray(value, dtype=float)
        if value.ndim == 1 and value.size != m:
            raise ShapeError(f"Coulomb's {name} must be one number or one per contact "
                             f"({m}), got {value.size} values")
        out.append(np.broadcast_to(value, (m,)).copy())
    return out[0], out[1]


def step_backend(law: Coulomb, backend: str) -> str:
    """The method of :func:`impactqp.solve_friction` a frictional run uses: ``backend``, or
    the law's own ``method`` when ``backend`` is ``"auto"``."""
    return law.method if backend == "auto" else backend


def check_friction_backend(backend: str) -> str:
    """``backend`` when :func:`impactqp.solve_friction` takes it, else InputError."""
    if backend not in FRICTION_BACKENDS:
        raise InputError(f"with Coulomb friction backend must be one of {FRICTION_BACKENDS} "
                         f"(the methods of solve_friction), got {backend!r}")
    return backend


STEP_CHECKS = ("kinetic", "kinematic", "energetic")
"""The residuals of a frictional step's u⁺ ∈ S (:meth:`FrictionSolver.membership`)."""

StepMembership = Certificate
"""The verdict u⁺ ∈ S of a frictional step is a :class:`~impactqp.results.Certificate` (made by
:meth:`FrictionSolver.membership`); the name is kept for code written before there was one
type."""


class FrictionEvent:
    """One frictional Moreau–Jean step with closed contacts, with its certificate.

    Parameters
    ----------
    time : float
        The end of the step.
    contacts : ndarray
        The closed contacts, ascending; their d components each are the rows of the local
        problem, in that order.
    problem : FrictionContactProblem
        W, q and μ of the step in contact units: the rows of contact c divided by
        s_c = √W_nn (docs/theory.md §16, §17), so that reactions and velocities are
        measured alike.
    result : FrictionResult
        The certified answer of :func:`impactqp.solve_friction` to ``problem``.
    units : ndarray
        s_c of each row: the impulses are ``result.r / units``.
    u_minus, u_plus : ndarray
        v_free and v_{k+1}.
    verdict : callable
        Computes the u⁺ ∈ S certificate of the step (called on first read of
        :attr:`admissible`).

    Attributes
    ----------
    kind : str
        ``"step"``.
    dofs : ndarray
        Every degree of freedom of the system (the step is one local problem).
    settled : ndarray
        Empty (event-driven settling does not apply).
    """

    kind = "step"
    law = "coulomb"

    def __init__(self, time: float, contacts: np.ndarray, problem: FrictionContactProblem,
                 result: FrictionResult, units: np.ndarray, u_minus: np.ndarray,
                 u_plus: np.ndarray, verdict: Callable[[], Certificate]) -> None:
        self.time, self.contacts, self.problem, self.result = time, contacts, problem, result
        self.units = units
        self.u_minus, self.u_plus = u_minus, u_plus
        self.dofs = np.arange(u_minus.size)
        self.settled = np.zeros(0, dtype=int)
        self._verdict = verdict

    impulses = property(lambda self: self.result.r / self.units,
                        doc="The impulses on the closed contacts' components.")

    @property
    def certificate(self) -> Certificate:
        """The recomputed certificate of the local problem."""
        return self.result.certificate

    @property
    def certified(self) -> bool:
        """The certificate's verdict (True for every recorded event)."""
        return bool(self.result.certificate.ok)

    @cached_property
    def admissible(self) -> Certificate:
        """u⁺ ∈ S of the step, with r as witness (:meth:`!FrictionSolver.membership`)."""
        return self._verdict()

    def __repr__(self) -> str:
        return (f"FrictionEvent(t={self.time:.12g}, contacts={self.contacts.tolist()[:6]}, "
                f"certificate={'ok' if self.certified else 'FAILED'})")


class FrictionSolver:
    """The closed contacts' frictional problem of one Moreau–Jean step, in step form
    (docs/theory.md §17): what :class:`~.impacts.ImpactSolver` is for the frictionless laws,
    with the same :meth:`solve`.

    The step's q = H_Aᵀv_free + eγ_k (normal rows; :func:`impactqp.kernels.step.step_q`)
    and the local problem gathered in contact units
    (:func:`impactqp.kernels.step.gather_local`, the units of
    :func:`impactqp.kernels.units.contact_units`) are the compiled loop's; the problem is
    solved and certified by :func:`impactqp.solve_friction`.

    Parameters
    ----------
    system : LinearSystem
        With ``contact_dim`` 2 or 3.
    free : callable
        v_free(t, q, v) of the θ-method, with its iteration matrix ``metric`` and its
        factorization ``solver`` (the loop's ``_FreeVelocity``).
    law : Coulomb
    backend : str
        Method of :func:`impactqp.solve_friction` (``"auto"``: the law's ``method``).
    tol : float
        Certificate tolerance of every local problem.
    """

    def __init__(self, system: LinearSystem, free, law: Coulomb, *, backend: str = "auto",
                 tol: float = FRICTION_TOL) -> None:
        self.system, self.free = system, free
        self.mu, self.e = coulomb_coefficients(law, system)
        self.backend, self.tol = check_friction_backend(step_backend(law, backend)), tol
        self.d = system.contact_dim
        self.impulse_size = system.n_contacts * self.d
        self._cache: dict[bytes, tuple[np.ndarray, ...]] = {}

    def local(self, contacts: np.ndarray) -> tuple[np.ndarray, ...]:
        """(columns, H_A, Ŵ⁻¹H_A, W = H_AᵀŴ⁻¹H_A, s) of a closed set (H_A dense), formed once
        per set: s holds each row's contact unit (:func:`impactqp.kernels.units.contact_units`
        of W's diagonal), in which the step's local problem is posed (docs/theory.md §16,
        §17)."""
        key = contacts.tobytes()
        hit = self._cache.get(key)
        if hit is None:
            if len(self._cache) >= MAX_CACHED:
                self._cache.clear()
            d = self.d
            cols = (contacts[:, None] * d + np.arange(d)).ravel()
            H = self.system.H[:, cols]
            H = H.toarray() if sp.issparse(H) else np.asarray(H, dtype=float)
            MinvH = self.free.solver.solve_mass(H)
            W = H.T @ MinvH
            W = np.ascontiguousarray(0.5 * (W + W.T))
            hit = (cols, H, np.ascontiguousarray(MinvH), W, contact_units(np.diag(W).copy(), d))
            self._cache[key] = hit
        return hit

    def solve(self, time: float, u_minus: np.ndarray, closed: np.ndarray, *,
              v_previous: np.ndarray, gamma_previous: np.ndarray,
              ) -> tuple[np.ndarray, np.ndarray, list[FrictionEvent]]:
        """(v_{k+1}, impulses over every column of H, events) of the step ending at ``time``
        from u⁻ = v_free, the closed contacts (boolean mask) and γ_k = H_nᵀv_k of all
        contacts (``v_previous`` = v_k, unused beyond γ_k).

        Raises
        ------
        CertificateError
            No method of :func:`impactqp.solve_friction` certifies the step (with its time
            and contacts).
        """
        d = self.d
        contacts = np.flatnonzero(closed)
        cols, H, MinvH, W, units = self.local(contacts)
        q = np.empty(cols.size)
        if not step_q(np.ascontiguousarray(H.T @ u_minus), gamma_previous, self.e, _NO_MATRIX,
                      contacts, d, q):
            return u_minus, np.zeros(self.impulse_size), []  # r = 0 is exact
        W_local, q_local = gather_local(W, units, np.arange(cols.size), q,
                                        np.empty((cols.size, cols.size)), np.empty(cols.size))
        problem = FrictionContactProblem(W_local, q_local, self.mu[contacts], contact_dim=d)
        try:
            result = solve_friction(problem, backend=self.backend, tol=self.tol)
        except CertificateError as exc:
            raise CertificateError(f"the frictional Moreau–Jean step ending at "
                                   f"t = {time:.12g} (contacts "
                                   f"{contacts.tolist()[:8]}): {exc}") from exc
        r = result.r / units
        v_next = u_minus + MinvH @ r
        lam = np.zeros(self.impulse_size)
        lam[cols] = r
        verdict = partial(self.membership, contacts, u_minus, v_next, r)
        return v_next, lam, [FrictionEvent(time, contacts, problem, result, units, u_minus,
                                           v_next, verdict)]

    def membership(self, contacts: np.ndarray, u_minus: np.ndarray, u_plus: np.ndarray,
                   r: np.ndarray) -> Certificate:
        """u⁺ ∈ S of one recorded step, proven by the reaction r as witness
        (docs/theory.md §17): a :class:`~impactqp.results.Certificate` of

        - kinetic: ‖Ŵ(u⁺ − u⁻) − H_A P_K(r)‖ / ‖H_A P_K(r)‖ (u⁺ − u⁻ is an impulse from the
          friction cones, P_K the projection onto them);
        - kinematic: largest −γ⁺ᵢ/(sᵢ‖u⁻‖) on the closed contacts, or 0 (no penetrating
          normal velocity; sᵢ² = Wᵢᵢ of the normal row, ‖·‖ the Ŵ-norm);
        - energetic: (‖u⁺‖² − ‖u⁻‖²)₊ / ‖u⁻‖² in the Ŵ-norm (no kinetic energy gained),

        each within the step's ``tol``."""
        _, H, _, _, units = self.local(contacts)
        d = self.d
        metric = self.free.metric
        impulse = H @ project_cones(r, self.mu[contacts], d)
        miss = float(np.linalg.norm(np.asarray(metric @ (u_plus - u_minus)).ravel() - impulse))
        scale = float(np.linalg.norm(impulse))
        kinetic = miss / scale if scale > 0 else (0.0 if miss == 0 else np.inf)
        norm_minus = float(u_minus @ np.asarray(metric @ u_minus).ravel())
        norm_plus = float(u_plus @ np.asarray(metric @ u_plus).ravel())
        gamma = H[:, ::d].T @ u_plus
        s = units[::d]
        ref = np.sqrt(norm_minus) if norm_minus > 0 else 1.0
        kinematic = max(0.0, float(np.max(-gamma / (s * ref))))
        energetic = max(0.0, norm_plus - norm_minus) / (norm_minus if norm_minus > 0 else 1.0)
        return Certificate({"kinetic": kinetic, "kinematic": kinematic,
                            "energetic": energetic}, self.tol, names=STEP_CHECKS)
