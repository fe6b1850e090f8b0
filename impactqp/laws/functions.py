"""The familiar one-call forms of the laws: thin wrappers over :func:`impactqp.solve`."""

from __future__ import annotations

from typing import Any

from ..base.checks import DEFAULT_TOL
from ..model.problem import ImpactProblem
from .complementarity import Fremond, Newton
from .moreau import Moreau
from .pipeline import solve
from .planner import check_problem
from .reflection import ReflectionLaw
from .result import ImpactResult
from .sector import SectorLaw


def moreau(problem: ImpactProblem, eps: float = 0.0, backend: str = "auto", *,
           form: str = "auto", tol: float = DEFAULT_TOL) -> ImpactResult:
    """Moreau's impact law with global restitution ε (docs/theory.md §3):
    ``solve(problem, Moreau(eps), backend, form=form, tol=tol)``.

    u⁺ = z − εz⊥ with z = prox_{T_C}(u⁻) in the metric M; equivalently
    ``0 ≤ Λ ⟂ GΛ + (1+ε)γ⁻ ≥ 0``.

    Parameters
    ----------
    problem : ImpactProblem
    eps : float
        Restitution ε ∈ [0, 1]; 0 dissipates the most, 1 conserves kinetic energy.
    backend : str
        ``"auto"`` or a registered backend (:func:`impactqp.available_backends`).
    form : {"auto", "velocity", "impulse"}
        Which QP to solve; both give the same u⁺.
    tol : float
        Tolerance of the recomputed certificate.

    Returns
    -------
    ImpactResult
        Only when the certificate passes.

    Raises
    ------
    RestitutionError, UnknownBackendError, BackendUnsuitableError, CertificateError
    """
    check_problem(problem)
    return solve(problem, Moreau(eps), backend, form=form, tol=tol)


def newton(problem: ImpactProblem, e: Any, backend: str = "auto", *,
           tol: float = DEFAULT_TOL) -> ImpactResult:
    """Local Newton law ``0 ≤ Λᵢ ⟂ γ⁺ᵢ + eᵢγ⁻ᵢ ≥ 0`` (docs/theory.md §3):
    ``solve(problem, Newton(e), backend, tol=tol)``.

    Parameters
    ----------
    problem : ImpactProblem
    e : float or (m,) array_like
        One restitution coefficient per contact (a scalar applies to all), each in [0, 1].
    backend : str
    tol : float

    Returns
    -------
    ImpactResult
        u⁺ may leave S (``result.admissible`` says so); the result is returned when its
        certificate passes.

    Raises
    ------
    RestitutionError, ShapeError, UnknownBackendError, BackendUnsuitableError,
    NoSolutionError, CertificateError
    """
    check_problem(problem)
    return solve(problem, Newton(e), backend, tol=tol)


def fremond(problem: ImpactProblem, E: Any, backend: str = "auto", *,
            tol: float = DEFAULT_TOL) -> ImpactResult:
    """Frémond's law with an (m, m) matrix of impact coefficients (docs/theory.md §3):
    ``0 ≤ Λᵢ ⟂ γ⁺ᵢ + Σⱼ Eᵢⱼ γ⁻ⱼ ≥ 0``, i.e. ``solve(problem, Fremond(E), backend, tol=tol)``.

    Parameters
    ----------
    problem : ImpactProblem
    E : (m, m) array_like
    backend : str
    tol : float

    Returns
    -------
    ImpactResult
        u⁺ may leave S; ``result.admissible`` reports it.

    Raises
    ------
    ShapeError, NonFiniteError, UnknownBackendError, BackendUnsuitableError,
    NoSolutionError, CertificateError
    """
    check_problem(problem)
    return solve(problem, Fremond(E), backend, tol=tol)


def sector_law(problem: ImpactProblem, *, tol: float = DEFAULT_TOL) -> ImpactResult:
    """The maximal-monotone sector law u⁺ = sort(u⁻) (docs/theory.md §6):
    ``solve(problem, SectorLaw(), tol=tol)``.

    Parameters
    ----------
    problem : ImpactProblem
        A chain of equal masses without walls (``impactqp.chain``, ``newtons_cradle``).
    tol : float

    Returns
    -------
    ImpactResult
        ``law="sector"``, ``backend="sort"``, ``coefficients=None``.

    Raises
    ------
    SectorLawError
        Not a chain, walls, or unequal masses (the message says why).
    CertificateError
        When rounding (velocities of wildly different magnitudes) breaks the certificate.
    """
    return solve(problem, SectorLaw(), tol=tol)


def reflection_law(problem: ImpactProblem, *, tol: float = DEFAULT_TOL) -> ImpactResult:
    """The elastic law of a chain whose contact angles are π/k, by reflections
    (docs/theory.md §10): ``solve(problem, ReflectionLaw(), tol=tol)``.

    Parameters
    ----------
    problem : ImpactProblem
        A chain whose every angle of T_C is π/k, free or with one wall.
    tol : float

    Returns
    -------
    ImpactResult
        ``law="reflection"``, ``backend="reflections"``, ``coefficients=None``.

    Raises
    ------
    SectorLawError
        Not a chain, two walls, or an angle that is not π/k (the message gives the angle,
        the nearest π/k, the mass reaching it and two collision orders that disagree).
    CertificateError
        When rounding breaks the certificate.
    """
    return solve(problem, ReflectionLaw(), tol=tol)
