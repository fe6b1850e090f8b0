"""The results of impactqp's solvers, one family (scipy's ``OptimizeResult`` is the model):
:class:`ImpactResult` of an impact law on an impact problem and :class:`FrictionResult` of a
local frictional contact problem, both :class:`CertifiedResult` — ``success``, ``status``,
``message``, ``backend``, ``attempts``, ``solve_time`` and the recomputed ``certificate``.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from functools import cached_property
from typing import Any

import numpy as np

from ..base.checks import Certificate, ResidualChecks
from ..derivatives.impact import derivative_of
from ..kernels.residuals import RESIDUALS
from ..model.admissible import Membership
from ..model.classify import Classification, classify
from ..model.friction import FrictionCertificate
from ..model.problem import ImpactProblem
from .base import MOREAU_FAMILY


class CertifiedResult:
    """What every certified answer of impactqp says of itself.

    A result is only returned when its certificate passes, so ``status`` is ``"solved"`` and
    ``ok`` and ``success`` are True (as scipy's ``OptimizeResult`` and cvxpy's status say
    so); ``backend`` is the registry name of what produced the numbers, one the caller may
    pass back as ``backend=``; ``attempts`` lists what was tried, in order. The best answer
    a :class:`~impactqp.errors.CertificateError` carries (its ``best``) is the one result
    that is not returned: its ``status`` is ``"not certified"``.
    """

    backend: str
    attempts: list[str]
    solve_time: float
    certificate: ResidualChecks

    @property
    def ok(self) -> bool:
        """The certificate's verdict (True for every returned result)."""
        return self.certificate.ok

    @property
    def status(self) -> str:
        """``"solved"``, or ``"not certified"`` for an error's best answer."""
        return "solved" if self.ok else "not certified"

    @property
    def success(self) -> bool:
        """The same as :attr:`ok` (scipy's name)."""
        return self.ok


class ImpactResult(CertifiedResult):
    """Post-impact state computed by a law, with its recomputed certificate.

    A result is only returned when ``certificate.ok``; physical admissibility (u⁺ ∈ S) is a
    separate verdict in :attr:`admissible`, which a law may legitimately fail.

    Attributes
    ----------
    problem : ImpactProblem
    law : str
        The law's name: ``"moreau"``, ``"newton"``, ``"fremond"``, ``"sector"``, ...
    impact_law : ImpactLaw
        The law object that was solved.
    coefficients : float or ndarray
        ε, the eᵢ, or Frémond's matrix E.
    u_plus : (n,) ndarray
        Post-impact velocity.
    impulses : (m,) ndarray
        Impulsive contact forces Λ ≥ 0 with M(u⁺ − u⁻) = WΛ.
    backend : str
        What produced the numbers (e.g. ``"nnls"``, ``"clarabel"``, ``"exact"``).
    certificate : Certificate
        Recomputed residuals of the law that was solved. A fast path may pass a callable
        that builds it from residuals it has already checked; it is called on first read.
    form : str or None
        ``"velocity"`` or ``"impulse"`` for laws solved through a program.
    z : (n,) ndarray
        z = prox_{T_C}(u⁻), the least-energy point of S (docs/theory.md §3); given by laws of
        Moreau's family, computed on first access otherwise.
    attempts : list of str
        What the pipeline tried, in order.
    solve_time : float
        Seconds from validation to the certified answer.
    status, message, success, ok
        ``"solved"``, a human-readable summary, and True: a result is only returned when its
        certificate passes (as scipy's ``OptimizeResult`` and cvxpy's status, ``ok`` and
        ``success`` say so).
    """

    def __init__(self, problem: ImpactProblem, law: str, coefficients, u_plus: np.ndarray,
                 impulses: np.ndarray, backend: str,
                 certificate: ResidualChecks | Callable[[], ResidualChecks], *,
                 form: str | None = None, z: np.ndarray | tuple | None = None,
                 attempts: list[str] | None = None, impact_law: Any = None,
                 solve_time: float = 0.0) -> None:
        self.problem = problem
        self.law = law
        self.impact_law = impact_law
        self.solve_time = solve_time
        self.coefficients = coefficients
        self.u_plus = u_plus
        self.impulses = impulses
        self.backend = backend
        self._certificate = certificate
        self.form = form
        self.attempts = attempts or []
        self._z = z

    @property
    def certificate(self) -> ResidualChecks:
        """The recomputed residuals of the law that was solved (see the class docstring)."""
        cert = self._certificate
        if not isinstance(cert, ResidualChecks):
            cert = self._certificate = cert()
        return cert

    @property
    def message(self) -> str:
        form = f", {self.form} form" if self.form else ""
        return (f"{self.law} solved by {self.backend}{form} in {self.solve_time * 1e3:.3g} ms; "
                f"certificate {self.certificate.summary()}")

    @cached_property
    def gamma_plus(self) -> np.ndarray:
        """Post-impact contact velocities γ⁺ = Wᵀu⁺."""
        return self.problem.structure.Wt_times(self.u_plus)

    @property
    def z(self) -> np.ndarray:
        """z = prox_{T_C}(u⁻), the least-energy point of S (docs/theory.md §3)."""
        z = self._z
        if z is None:
            return self.problem.moreau_split[0]
        if callable(z):  # a fast path's recipe, evaluated when first read
            z = self._z = z()
        return z

    @property
    def z_perp(self) -> np.ndarray:
        """z⊥ = u⁻ − z (in −N)."""
        return self.problem.u_minus - self.z

    @property
    def energy_before(self) -> float:
        return self.problem.kinetic_energy()

    @property
    def energy_after(self) -> float:
        return self.problem.kinetic_energy(self.u_plus)

    @cached_property
    def admissible(self) -> Membership:
        """Whether u⁺ ∈ S (exact test, docs/theory.md §2; with the law's friction cones for
        frictional contacts, docs/theory.md §16), with its residuals: the physical verdict,
        separate from the certificate."""
        law = self.impact_law
        S = self.problem.admissible_set() if law is None else law.admissible_set(self.problem)
        return S.contains(self.u_plus)

    @cached_property
    def classification(self) -> Classification:
        """Intensity, topology, angle α and dissipation of u⁺ (docs/theory.md §4)."""
        return classify(self.problem, self.u_plus)

    def derivative(self, *, kink_tol: float = 1e-9) -> Any:
        """The derivative of the law's map at this answer, an
        :class:`~impactqp.derivatives.impact.ImpactDerivative` (docs/theory.md §18–§20):
        Jacobians, JVPs and VJPs in u⁻, M, W and the law's parameter, the status
        (``"smooth"``, ``"kink"``, ``"unsupported"``) and a certificate.

        Parameters
        ----------
        kink_tol : float
            Contacts whose scaled impulse and gap velocity are both at most this (relative
            to ‖u⁻‖) count as degenerate: the answer is then on a kink.
        """
        return derivative_of(self, kink_tol=kink_tol)

    def __repr__(self) -> str:
        return (f"ImpactResult(law={self.law!r}, backend={self.backend!r}, "
                f"u_plus={np.array2string(self.u_plus, precision=6)}, "
                f"certificate={self.certificate.summary()})")


class CompiledImpactResult(ImpactResult):
    """An :class:`ImpactResult` of one compiled call (:mod:`impactqp.laws.small`), its
    fields read off the call's output buffer when first asked for.

    The compiled call has already recomputed every residual of the certificate and checked
    it against the tolerance (a result is only formed when it passed); what is left is
    bookkeeping, done lazily: u⁺, Λ and the residuals are views of ``out`` (``at`` says
    where: n, where Λ starts and ends, where the residuals start; u⁺ is ``out[:n]``), the
    :class:`Certificate` is built from those residuals on first read, z by the law's
    projection. The attributes are those of :class:`ImpactResult`.
    """

    _certificate = None
    _z = None

    def __init__(self, problem: ImpactProblem, impact_law: Any, out: np.ndarray,
                 at: tuple[int, int, int, int], names: tuple[str, ...], tol: float,
                 backend: str, form: str, solve_time: float) -> None:
        self.problem = problem
        self.impact_law = impact_law
        self.solve_time = solve_time
        self.backend = backend
        self.form = form
        self._out = out
        self._at = at
        self._names = names
        self._tol = tol

    @property
    def law(self) -> str:  # type: ignore[override]
        return self.impact_law.name

    @cached_property
    def coefficients(self) -> Any:  # type: ignore[override]
        return self.impact_law.coefficients_for(self.problem)

    @cached_property
    def u_plus(self) -> np.ndarray:  # type: ignore[override]
        return self._out[:self._at[0]]

    @cached_property
    def impulses(self) -> np.ndarray:  # type: ignore[override]
        return self._out[self._at[1]:self._at[2]]

    @property
    def attempts(self) -> list[str]:  # type: ignore[override]
        return [f"{self.backend} (compiled): certified"]

    @property
    def certificate(self) -> ResidualChecks:
        cert = self._certificate
        if cert is None:
            start = self._at[3]
            values = self._out[start:start + len(self._names)].tolist()
            cert = self._certificate = Certificate(dict(zip(self._names, values)), self._tol,
                                                   names=RESIDUALS)
        return cert

    @property
    def z(self) -> np.ndarray:
        z = self._z
        if z is None:
            law = self.impact_law
            z = self._z = (law.projection(self.problem, self.u_plus)
                           if law.family == MOREAU_FAMILY else self.problem.moreau_split[0])
        return z


@dataclass(frozen=True, repr=False)
class FrictionResult(CertifiedResult):
    """A certified answer of :func:`impactqp.solve_friction` (docs/theory.md §15).

    Attributes
    ----------
    r, u : ndarray
        The reaction and the velocity u = W r + q.
    error : float
        ‖F‖/‖q‖, the natural-map error of the certificate (ABH).
    certificate : FrictionCertificate
        The recomputed checks; ``certificate.ok`` is always True here.
    iterations : int
        Sweeps, cone programs and Newton steps done.
    solve_time : float
        Wall-clock seconds.
    backend : str
        The friction method that produced the answer, a name ``backend=`` takes
        (``"kernel"``, ``"nsgs-short"``, ``"newton"``, ``"clarabel"``, ...; ``attempts`` says
        whether Newton polished it).
    attempts : list of str
        What was tried, in order.
    status, message, success, ok
        As for :class:`ImpactResult`.
    """

    r: np.ndarray
    u: np.ndarray
    error: float
    certificate: FrictionCertificate
    iterations: int
    solve_time: float
    backend: str
    attempts: list[str] = field(default_factory=list)

    @property
    def message(self) -> str:
        verb = "solved" if self.ok else "NOT certified (the best answer found)"
        return (f"frictional contact problem {verb} by {self.backend} in {self.iterations} "
                f"iterations, {self.solve_time * 1e3:.3g} ms; certificate "
                f"{self.certificate.summary()}")

    def __repr__(self) -> str:
        d = self.certificate.values
        return (f"FrictionResult(unknowns={self.r.size}, backend={self.backend!r}, "
                f"status={self.status!r}, error={self.error:.1e}, "
                f"certificate={'ok' if self.certificate.ok else 'FAILED'} "
                f"(tol {self.certificate.tol:.0e}, {len(d)} checks))")
