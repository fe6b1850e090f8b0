"""The LZB model of Liu, Zhao and Brogliato as an impact law: a multiple impact resolved by
integrating the contact impulses against the impulse of a primary contact, with a compliance
and an energetic restitution coefficient per contact (docs/theory.md §13).

Unlike the rigid laws of docs/theory.md §3 and §6 the outcome depends on the contacts'
stiffnesses and exponents: the model disperses the striker's energy along a chain as real
chains of beads do. It is a closed-form law for the solve pipeline (``forms = ()``, backend
``"lzb"``): its "solver" is the integration of :mod:`impactqp.laws.lzb.integration`, and its
certificate is recomputed from u⁺, Λ and the final state of that integration.
"""

from __future__ import annotations

from typing import Any, NamedTuple

import numpy as np

from ...base.arrays import as_array, as_real, as_vector
from ...base.checks import DEFAULT_TOL, Certificate
from ...errors import InputError, RestitutionError, ShapeError
from ...model.problem import ImpactProblem
from ...model.structure import ImpactStructure
from ..base import ImpactLaw
from .certificate import LZB_RESIDUALS, integration_tolerance, lzb_certificate, lzb_residuals
from .dynamics import LZBDynamics, delassus_rows
from .integration import LZBRecord, integrate

DEFAULT_RTOL = 1e-12
"""Relative (and, in the dimensionless variables, absolute) tolerance of the adaptive
integration."""
ENERGY_TARGET = 1e-10
"""Default ``energy_target``: adaptive integrations whose energy balance (docs/theory.md §13)
misses it are repeated at a tolerance ten times tighter, down to MIN_RTOL."""
MIN_RTOL = 1e-13
MIN_EXPONENT, MAX_EXPONENT = 1.0, 3.0
"""The compliance exponents the model accepts (docs/theory.md §13)."""
TARGET_CONTACTS = 10
"""With an ``energy_target``, the first integration of an impact of m > TARGET_CONTACTS
contacts runs at rtol·TARGET_CONTACTS/m (not below MIN_RTOL): its energy balance gathers
the error of every contact the wave crosses, and one integration at the tolerance that
meets the target costs less than a missed one and its repetition."""


def first_rtol(rtol: float, m: int) -> float:
    """The tolerance of the first integration with an energy target (TARGET_CONTACTS)."""
    return max(MIN_RTOL, min(rtol, rtol * TARGET_CONTACTS / max(m, 1)))


def _per_contact(name: str, value: np.ndarray, m: int) -> np.ndarray:
    if value.ndim == 0:
        return np.full(m, float(value))
    if value.shape != (m,):
        raise ShapeError(f"{name} must be a scalar or have one entry per contact, shape "
                         f"({m},), got {value.shape}")
    return value


def _coefficients(name: str, value: Any, *, low: float, high: float | None = None,
                  open_low: bool = True, error: type[InputError] = InputError) -> np.ndarray:
    arr = as_array(name, value)
    if arr.ndim > 1 or arr.size == 0:
        raise ShapeError(f"{name} must be a scalar or a 1-D array, got shape {arr.shape}")
    bad = (arr <= low) if open_low else (arr < low)
    if high is not None:
        bad |= arr > high
    if np.any(bad):
        where = f"({low}, ∞)" if high is None else f"[{low}, {high}]"
        raise error(f"{name} must lie in {where}, got {arr[bad][:5].tolist()}")
    return arr


class LZBAnswer(NamedTuple):
    """u⁺, Λ and the record of the integration that produced them.

    Attributes
    ----------
    u_plus : (n,) ndarray
    impulses : (m,) ndarray
        Λ, the contact impulses accumulated over the impact.
    z : None
        Unused (Moreau's projection has no meaning here); kept for the Answer shape.
    record : LZBRecord or None
        Energy left and dissipated per contact, primary switches, steps.
    """

    u_plus: np.ndarray
    impulses: np.ndarray
    z: np.ndarray | None
    record: LZBRecord | None


class LZB(ImpactLaw):
    """The LZB multiple-impact model (Liu, Zhao, Brogliato) as an impact law
    (docs/theory.md §13).

    Parameters
    ----------
    stiffness : float or (m,) array_like
        Kᵢ > 0 of each contact's compliance Fᵢ = Kᵢδᵢ^ηᵢ (N/m^ηᵢ); a scalar for all
        contacts. :mod:`!impactqp.model.physical_chains` computes Hertz stiffnesses.
    exponent : float or (m,) array_like
        ηᵢ ∈ [1, 3]: 3/2 for Hertz contact, 1 for a linear spring (MIN_EXPONENT,
        MAX_EXPONENT: below 1 the force is not Lipschitz at contact, which the model's
        rates need; above 3 no contact law of the literature).
    restitution : float or (m,) array_like
        Energetic restitution eᵢ ∈ [0, 1]: expansion gives back eᵢ² of the energy stored
        in compression (1: elastic, 0: plastic).
    step : float, optional
        None (default): adaptive steps (DOP853) at relative tolerance ``rtol``. A positive
        finite number: fixed DOP853 steps of that length in the primary impulse (N·s); an
        impact whose impulse scale needs more steps than the budget is refused
        (:class:`~impactqp.errors.IntegrationBudgetError`, docs/theory.md §13).
    rtol : float
        Tolerance of the adaptive integration, in [1e-13, 1e-3].
    energy_target : float or None
        With adaptive steps, the integration is repeated at a tolerance ten times tighter
        (down to 1e-13) while its energy balance (kinetic + potential + dissipated energy,
        relative to ‖u⁻‖²) misses this; None integrates once at ``rtol``.

    Notes
    -----
    Solved by :func:`impactqp.solve` in closed form (backend ``"lzb"``). The result's
    certificate (:func:`!impactqp.laws.lzb.certificate.lzb_certificate`) carries the
    integration's record (its extra ``record``): potential energy left per contact,
    dissipated energy, primary-contact switches, steps.
    """

    name = "lzb"
    title = "the LZB model"
    by_name = True
    coefficient_keys = ("stiffness", "exponent", "e")
    coefficient_symbol = "(K, η, e)"
    needs_coefficients = True
    closed_form_backend = "lzb"
    always_solvable = True
    compliant = True
    residual_names = LZB_RESIDUALS

    def __init__(self, stiffness: Any, exponent: Any = 1.5, restitution: Any = 1.0,
                 step: float | None = None, *, rtol: float = DEFAULT_RTOL,
                 energy_target: float | None = ENERGY_TARGET) -> None:
        self.stiffness = _coefficients("stiffness", stiffness, low=0.0)
        self.exponent = _coefficients("exponent", exponent, low=MIN_EXPONENT,
                                      high=MAX_EXPONENT, open_low=False)
        self.restitution = _coefficients("restitution", restitution, low=0.0, high=1.0,
                                         open_low=False, error=RestitutionError)
        self.step = None if step is None else as_real("step", step, positive=True)
        self.rtol = as_real("rtol", rtol, low=MIN_RTOL, high=1e-3)
        self.energy_target = None if energy_target is None else \
            as_real("energy_target", energy_target, positive=True)


    @classmethod
    def from_coefficients(cls, coefficients: Any = None) -> LZB:
        """The LZB model named in a file or on the command line: ``coefficients`` is the
        triple (K, η, e) of the keys ``stiffness``, ``exponent`` and ``e`` (η None for
        Hertz's 3/2, e None for 1), or the mapping :attr:`coefficients`.

        Raises
        ------
        InputError, RestitutionError
            No stiffness, or coefficients the law refuses.
        """
        if isinstance(coefficients, dict):
            coefficients = tuple(coefficients.get(k) for k in ("stiffness", "exponent",
                                                                "restitution"))
        if not isinstance(coefficients, tuple) or len(coefficients) != 3 \
                or coefficients[0] is None:
            raise InputError("law 'lzb' needs its coefficients: the contact stiffness "
                             "'stiffness' (required), 'exponent' (default 1.5) and 'e' "
                             f"(default 1); got {coefficients!r}")
        stiffness, exponent, e = coefficients
        return cls(stiffness, 1.5 if exponent is None else exponent, 1.0 if e is None else e)

    @property
    def homogeneous(self) -> bool:
        """One exponent for every contact: only then does the impact scale with u⁻ (with
        several, the stiffness ratios weigh differently at other energies; docs/theory.md
        §13)."""
        return bool(np.all(np.asarray(self.exponent) == np.ravel(self.exponent)[0]))
    def contact_laws(self, m: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(Kᵢ, ηᵢ, eᵢ) spread over ``m`` contacts."""
        return (_per_contact("stiffness", self.stiffness, m),
                _per_contact("exponent", self.exponent, m),
                _per_contact("restitution", self.restitution, m))

    def restrict(self, contacts: Any) -> LZB:
        """The same law on a subset of the contacts (per-contact coefficients taken at
        ``contacts``, indices or a boolean mask), e.g. for one cluster of a larger system."""
        idx = np.asarray(contacts)

        def pick(a: np.ndarray) -> np.ndarray:
            return a if a.ndim == 0 else a[idx]

        return LZB(pick(self.stiffness), pick(self.exponent), pick(self.restitution),
                   self.step, rtol=self.rtol, energy_target=self.energy_target)

    @property
    def coefficients(self) -> dict:
        return {"stiffness": self.stiffness, "exponent": self.exponent,
                "restitution": self.restitution}

    def coefficients_for(self, problem: ImpactProblem) -> dict:
        K, eta, e = self.contact_laws(problem.n_contacts)
        return {"stiffness": K, "exponent": eta, "restitution": e}

    @property
    def elastic(self) -> bool:
        """Every contact has eᵢ = 1."""
        return bool(np.all(self.restitution == 1.0))

    def check(self, problem: ImpactProblem) -> None:
        """Refuse coefficients that do not fit the contacts, and an elastic impact between
        two walls (T_C = {0}: no velocity lets every contact open, so it never ends)."""
        e = self.contact_laws(problem.n_contacts)[2]
        chain = problem.chain
        if chain is not None and chain.left_wall and chain.right_wall and np.all(e == 1):
            raise InputError("the LZB model cannot end an elastic impact of a chain between "
                             "two walls (T_C = {0}); give some contact restitution < 1")

    def integrate(self, problem: ImpactProblem, u_minus: Any = None, *,
                  reference: bool = False) -> LZBAnswer:
        """Run the LZB integration on ``problem`` (or on its M and W with ``u_minus``),
        without certificate (:func:`impactqp.solve` adds it).

        Parameters
        ----------
        problem : ImpactProblem
        u_minus : (n,) array_like, optional
            Another pre-impact velocity for the same M and W.
        reference : bool
            Integrate with scipy's DOP853 piece by piece (the slow reference the compiled
            stepper is tested against) instead of the compiled stepper.

        Returns
        -------
        LZBAnswer
            u⁺, Λ and the integration's record (None when no contact approaches).

        Raises
        ------
        ShapeError
            Coefficients or ``u_minus`` that do not fit the problem.
        IntegrationBudgetError
            A fixed ``step`` too small for this impact's budget of steps, or the budget spent.
        CertificateError
            The integration failed.
        """
        st = problem.structure
        u = problem.u_minus if u_minus is None else as_vector("u_minus", u_minus, st.n)
        gamma = st.Wt_times(u)
        if st.m == 0 or not np.any(gamma < 0):
            return LZBAnswer(u.copy(), np.zeros(st.m), None, None)
        K, eta, e = self.contact_laws(st.m)
        dyn = LZBDynamics(delassus_rows(st), gamma, K, eta, e)
        rtol = self.rtol if self.energy_target is None else first_rtol(self.rtol, st.m)
        while True:
            record = integrate(dyn, rtol=rtol, step=self.step, reference=reference)
            u_plus = u + st.impulse_velocity(record.impulses)
            if self.step is not None or self.energy_target is None or rtol <= MIN_RTOL:
                break
            balance = lzb_residuals(st, u, u_plus, record.impulses,
                                    stored=record.stored_dimensionless,
                                    energy_unit=record.energy_unit)
            if balance["energy_balance"] <= self.energy_target:
                break
            rtol = max(rtol / 10.0, MIN_RTOL)
        return LZBAnswer(u_plus, record.impulses, None, record)

    def closed_form(self, problem: ImpactProblem) -> LZBAnswer:
        return self.integrate(problem)

    def closed_form_rows(self, problem: ImpactProblem,
                         U_minus: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        answers = [self.integrate(problem, u) for u in U_minus]
        return (np.array([a.u_plus for a in answers]).reshape(U_minus.shape),
                np.array([a.impulses for a in answers]).reshape(len(U_minus),
                                                                problem.n_contacts))

    def residuals(self, structure: ImpactStructure, U_minus: np.ndarray, U_plus: np.ndarray,
                  impulses: np.ndarray) -> dict[str, np.ndarray]:
        return lzb_residuals(structure, U_minus, U_plus, impulses, elastic=self.elastic)

    def certificate(self, problem: ImpactProblem, answer: Any,
                    tol: float = DEFAULT_TOL) -> Certificate:
        record = getattr(answer, "record", None)
        if record is None:
            res = lzb_residuals(problem.structure, problem.u_minus, answer.u_plus,
                                answer.impulses)
            return lzb_certificate(res, tol, tol)
        res = lzb_residuals(problem.structure, problem.u_minus, answer.u_plus,
                            answer.impulses, stored=record.stored_dimensionless,
                            left=record.left_dimensionless, energy_unit=record.energy_unit)
        return lzb_certificate(res, tol, integration_tolerance(tol, record), record)

    def __repr__(self) -> str:
        step = "" if self.step is None else f", step={self.step:g}"
        def short(a: np.ndarray) -> str:
            return np.array2string(a, precision=4, threshold=6)
        return (f"LZB(stiffness={short(self.stiffness)}, exponent={short(self.exponent)}, "
                f"restitution={short(self.restitution)}{step})")
