"""Moreau's law, local Newton and Frémond's matrix law as quadratic programs (§3).

All three are the complementarity law ``0 ≤ Λ ⟂ γ⁺ + Eγ⁻ ≥ 0`` with E = εI (Moreau),
E = diag(eᵢ) (local Newton) or a full matrix (Frémond). Moreau's law is also the M-metric
projection of u⁻ onto the tangent cone (velocity form), which stays well posed with
redundant contacts.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import scipy.sparse as sp

from .backends import parse_backend
from .certificate import DEFAULT_TOL, certify
from .dispatch import solve_certified
from .errors import CertificateError, InputError, NonFiniteError, RestitutionError, ShapeError
from .fastpaths import FAST_PATHS, applies, lcp_fast, moreau_fast
from .problem import ImpactProblem
from .program import QPSolution, QuadraticProgram
from .result import ImpactResult

FORMS = ("auto", "velocity", "impulse")


def check_eps(value: Any) -> float:
    """Validate Moreau's global restitution ε ∈ [0, 1]."""
    try:
        e = float(value)
    except (TypeError, ValueError):
        raise RestitutionError(f"eps must be one number in [0, 1], got {value!r}") from None
    if not 0.0 <= e <= 1.0:  # NaN fails too
        raise RestitutionError(f"eps must lie in [0, 1] (and not be NaN), got {value!r}")
    return e


def check_restitution(name: str, value: Any, m: int, *, matrix: bool = False) -> np.ndarray:
    """Validate local coefficients eᵢ (a scalar for all, or an m-vector, each in [0, 1]) or
    Frémond's E (a finite (m, m) matrix)."""
    arr = np.asarray(value, dtype=float)
    if matrix:
        if arr.shape != (m, m):
            raise ShapeError(f"{name} must be an ({m}, {m}) matrix, got shape {arr.shape}")
        if not np.all(np.isfinite(arr)):
            raise NonFiniteError(f"{name} must be finite")
        return arr
    if arr.ndim == 0:
        arr = np.full(m, float(arr))
    elif arr.shape != (m,):
        raise ShapeError(f"{name} must be a scalar or have shape ({m},), got {arr.shape}")
    if np.any(np.isnan(arr)) or np.any(arr < 0) or np.any(arr > 1):
        raise RestitutionError(f"{name} must lie in [0, 1] (and not be NaN), got {value!r}")
    return arr


def check_backend_name(backend: str) -> None:
    """Raise UnknownBackendError early for a bad name (before any solve)."""
    if backend not in ("auto",) + FAST_PATHS:
        parse_backend(backend)


def _fast_result(problem: ImpactProblem, law: str, coef, E, answer, path: str, *,
                 backend: str, eps: float | None, tol: float) -> ImpactResult | None:
    """A fast path's answer (u⁺, Λ, z) as a result when its certificate passes; None to go on
    to the QP backends under "auto"; an error when the fast path was named."""
    if answer is not None:
        u, lam, z = answer
        cert = certify(problem, u, lam, E, eps=eps, tol=tol)
        if cert.ok:
            form = "impulse" if path == "kernel" and law != "moreau" else path
            return ImpactResult(problem, law, coef, u, lam, path, cert, form=form, z=z)
    if backend != "auto":
        raise CertificateError(f"the {path!r} fast path gave no certified answer (for the "
                               "kernel: q is not in the range of G); use a QP backend")
    return None


def _check_problem(problem: Any) -> None:
    if not isinstance(problem, ImpactProblem):
        raise InputError(f"problem must be an ImpactProblem, got {type(problem).__name__}")


def _no_contact(problem: ImpactProblem, law: str, coef) -> ImpactResult:
    u = problem.u_minus.copy()
    lam = np.zeros(0)
    cert = certify(problem, u, lam, 0.0, eps=0.0 if law == "moreau" else None)
    return ImpactResult(problem, law, coef, u, lam, "none", cert, z=u.copy())


def impulse_program(problem: ImpactProblem, q: np.ndarray,
                    moreau_scale: float | None = None) -> QuadraticProgram:
    """Impulse form min ½ΛᵀGΛ + qᵀΛ, Λ ≥ 0 (§3), with the factor B = L⁻¹W when dense.

    For Moreau's law (q = (1+ε)γ⁻, ``moreau_scale`` = 1+ε) q = Bᵀd with d = (1+ε)Lᵀu⁻.
    """
    st = problem.structure
    if st.sparse:
        return QuadraticProgram(P=st.delassus, c=q, cache_owner=st, cache_tag="impulse")
    d = None if moreau_scale is None else moreau_scale * (st.cholesky_factor.T @ problem.u_minus)
    return QuadraticProgram(P=st.delassus, c=q, factor=st.scaled_W, factor_rhs=d,
                            cache_owner=st, cache_tag="impulse")


def velocity_program(problem: ImpactProblem) -> QuadraticProgram:
    """Velocity form min ½‖v − u⁻‖²_M s.t. Wᵀv ≥ 0 (§3): z = prox_{T_C}(u⁻)."""
    st = problem.structure
    A = sp.csc_matrix(st.W.T) if st.sparse else st.W.T
    return QuadraticProgram(P=st.M, c=-st.mass_rows(problem.u_minus),
                            A=A, b=np.zeros(st.m), cache_owner=st, cache_tag="velocity")


def moreau(problem: ImpactProblem, eps: float = 0.0, backend: str = "auto", *,
           form: str = "auto", tol: float = DEFAULT_TOL) -> ImpactResult:
    """Moreau's impact law with global restitution ε (§3).

    u⁺ = z − εz⊥ with z = prox_{T_C}(u⁻) in the metric M; equivalently
    ``0 ≤ Λ ⟂ GΛ + (1+ε)γ⁻ ≥ 0``.

    Parameters
    ----------
    problem : ImpactProblem
    eps : float
        Restitution ε ∈ [0, 1]; 0 dissipates the most, 1 conserves kinetic energy.
    backend : str
        ``"auto"`` or a backend name (see :mod:`impactqp.backends`).
    form : {"auto", "velocity", "impulse"}
        Which QP to solve. Both give the same u⁺; the velocity form stays well posed for any
        W, the impulse form is smaller when m < n.
    tol : float
        Tolerance of the recomputed certificate.

    Returns
    -------
    ImpactResult
        Only when the certificate passes.

    Raises
    ------
    RestitutionError, UnknownBackendError, CertificateError
    """
    _check_problem(problem)
    e = check_eps(eps)
    check_backend_name(backend)
    if form not in FORMS:
        raise InputError(f"form must be one of {FORMS}, got {form!r}")
    if problem.n_contacts == 0:
        return _no_contact(problem, "moreau", e)
    st = problem.structure
    u_m = problem.u_minus
    path = applies(st, backend) if form == "auto" else None
    if path is not None:
        result = _fast_result(problem, "moreau", e, e, moreau_fast(problem, e, path), path,
                              backend=backend, eps=e, tol=tol)
        if result is not None:
            return result
    if form == "auto":
        form = "velocity" if st.sparse else "impulse"

    if form == "velocity":
        qp = velocity_program(problem)

        def finish(sol: QPSolution):
            z, lam = sol.x, (1.0 + e) * sol.y
            u = (1.0 + e) * z - e * u_m
            return (u, lam, z), certify(problem, u, lam, e, eps=e, tol=tol)
    else:
        qp = impulse_program(problem, (1.0 + e) * problem.gamma_minus, 1.0 + e)

        def finish(sol: QPSolution):
            lam = sol.x
            u = u_m + st.impulse_velocity(lam)
            z = (u + e * u_m) / (1.0 + e)
            return (u, lam, z), certify(problem, u, lam, e, eps=e, tol=tol)

    (u, lam, z), cert, used, log = solve_certified(qp, backend, finish)
    return ImpactResult(problem, "moreau", e, u, lam, used, cert, form=form, z=z, attempts=log)


def _lcp_law(problem: ImpactProblem, law: str, E: np.ndarray, backend: str,
             tol: float) -> ImpactResult:
    check_backend_name(backend)
    if problem.n_contacts == 0:
        return _no_contact(problem, law, E)
    st = problem.structure
    g = problem.gamma_minus
    q = g + (E * g if E.ndim == 1 else E @ g)
    if applies(st, backend, law=law) == "kernel":
        lam = lcp_fast(problem, q)
        answer = None if lam is None else (problem.u_minus + st.impulse_velocity(lam), lam, None)
        result = _fast_result(problem, law, E, E, answer, "kernel", backend=backend, eps=None,
                              tol=tol)
        if result is not None:
            return result
    qp = impulse_program(problem, q)

    def finish(sol: QPSolution):
        lam = sol.x
        u = problem.u_minus + st.impulse_velocity(lam)
        return (u, lam), certify(problem, u, lam, E, tol=tol)

    (u, lam), cert, used, log = solve_certified(qp, backend, finish)
    return ImpactResult(problem, law, E, u, lam, used, cert, form="impulse", attempts=log)


def newton(problem: ImpactProblem, e: Any, backend: str = "auto", *,
           tol: float = DEFAULT_TOL) -> ImpactResult:
    """Local Newton law: ``0 ≤ Λᵢ ⟂ γ⁺ᵢ + eᵢγ⁻ᵢ ≥ 0`` for every closed contact (§3).

    Parameters
    ----------
    e : float or (m,) array_like
        One restitution coefficient per contact (a scalar applies to all), each in [0, 1].

    Notes
    -----
    Unlike Moreau's law, u⁺ may leave S (kinetic energy can grow); ``result.admissible``
    says so, the result is still returned when its certificate passes.
    """
    _check_problem(problem)
    coef = check_restitution("e", e, problem.n_contacts)
    return _lcp_law(problem, "newton", coef, backend, tol)


def fremond(problem: ImpactProblem, E: Any, backend: str = "auto", *,
            tol: float = DEFAULT_TOL) -> ImpactResult:
    """Frémond's law with an (m, m) matrix of impact coefficients (§3):
    ``0 ≤ Λᵢ ⟂ γ⁺ᵢ + Σⱼ Eᵢⱼ γ⁻ⱼ ≥ 0``, an LCP with q = (I + E)γ⁻.

    u⁺ may leave S; ``result.admissible`` reports it.
    """
    _check_problem(problem)
    coef = check_restitution("E", E, problem.n_contacts, matrix=True)
    return _lcp_law(problem, "fremond", coef, backend, tol)
