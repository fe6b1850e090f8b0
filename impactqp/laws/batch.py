"""Many impacts of one problem structure at once (k pre-impact velocities, rows of a matrix),
through the same law objects as single impacts.

Closed-form laws run on all rows at once; program laws run vectorised on a fast-path backend
that solves many linear terms at once (isotonic regression for chains, the prepared
active-set kernel for small dense impacts); rows they cannot settle, and every row of other
structures, go through :func:`impactqp.solve`. Every row's certificate is recomputed by the
law; a row that fails it is solved again on its own, which raises if no backend certifies
it, so a returned batch is certified row by row.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from ..base.arrays import as_array, check_tol
from ..base.checks import DEFAULT_TOL
from ..errors import BackendUnsuitableError, CertificateError, ShapeError
from ..model.problem import ImpactProblem
from ..qp import backends
from ..qp.certified import FAST_PATHS
from .base import ImpactLaw
from .moreau import Moreau
from .pipeline import check_backend, check_law, check_problem, solve
from .sector import SectorLaw


@dataclass(frozen=True)
class BatchResult:
    """k impacts of one structure.

    Attributes
    ----------
    u_plus : (k, n) ndarray
    impulses : (k, m) ndarray
    residuals : dict of (k,) ndarrays
        The certificate's residuals per row (keys as :attr:`Certificate.residuals`).
    backend : str
        The path used for most rows (``"isotonic"``, ``"kernel"`` or a QP backend).
    resolved : int
        How many rows the vectorised path left to the single-impact law.
    tol : float
    """

    u_plus: np.ndarray
    impulses: np.ndarray
    residuals: dict
    backend: str
    resolved: int
    tol: float

    @property
    def ok(self) -> np.ndarray:
        """Per-row verdict of the certificate (all True in a returned batch)."""
        return certified_rows(self.residuals, self.tol)

    @property
    def certificate(self) -> BatchCertificate:
        """The per-row residuals as a certificate (``.ok`` per row, ``.worst``)."""
        return BatchCertificate(self.residuals, self.tol)

    status = "solved"

    @property
    def message(self) -> str:
        return (f"{len(self.u_plus)} impacts by {self.backend} ({self.resolved} re-solved one "
                f"by one); worst {self.certificate.worst[0]} = {self.certificate.worst[1]:.1e}")


@dataclass(frozen=True)
class BatchCertificate:
    """Residuals of k impacts: each a (k,) array; ``ok`` is the per-row verdict."""

    residuals: dict
    tol: float

    @property
    def ok(self) -> np.ndarray:
        return certified_rows(self.residuals, self.tol)

    @property
    def worst(self) -> tuple[str, float]:
        """The largest residual over all rows and its name."""
        if not self.residuals or not len(next(iter(self.residuals.values()))):
            return "none", 0.0
        peaks = {k: float(np.max(np.where(np.isfinite(v), v, np.inf))) for k, v in
                 self.residuals.items()}
        name = max(peaks, key=peaks.get)
        return name, peaks[name]


def certified_rows(residuals: dict, tol: float) -> np.ndarray:
    """Rows whose every residual is within ``tol`` (NaN fails)."""
    return np.all([v <= tol for v in residuals.values()], axis=0)


def as_rows(problem: ImpactProblem, U_minus: Any) -> np.ndarray:
    """Validate a (k, n) matrix of pre-impact velocities."""
    U = as_array("U_minus", U_minus)
    if U.ndim != 2 or U.shape[1] != problem.n_dof:
        raise ShapeError(f"U_minus must have shape (k, {problem.n_dof}), got {U.shape}")
    return U


def _fast_path(problem: ImpactProblem, law: ImpactLaw, backend: str):
    """(backend name, form, program) of a vectorised fast path for ``law``, or None."""
    if problem.n_contacts == 0:
        return None
    names = FAST_PATHS if backend == "auto" else (backend,) if backend in FAST_PATHS else ()
    reasons = []
    for name in names:
        entry = backends.REGISTRY[name]
        for form in law.preferred_forms(problem):
            qp = law.program(problem, form)
            reason = backends.unsuitable(entry, qp, form)
            if reason is None:
                return name, form, qp
            reasons.append(reason)
    if backend in FAST_PATHS:
        raise BackendUnsuitableError("; ".join(reasons) or
                                     f"{law.title} has no program for {backend!r}")
    return None


def solve_batch(problem: ImpactProblem, law: ImpactLaw, U_minus: Any, backend: str = "auto",
                *, tol: float = DEFAULT_TOL) -> BatchResult:
    """``law`` for every row of ``U_minus`` on the structure of ``problem``.

    Parameters
    ----------
    problem : ImpactProblem
        Supplies M and W (its own u⁻ is not used).
    law : ImpactLaw
        Any law object (``iq.Moreau(eps)``, ``iq.SectorLaw()``, ...).
    U_minus : (k, n) array_like
        Pre-impact velocities, one per row.
    backend : str
        ``"auto"``, a fast path (``"isotonic"``, ``"kernel"``) or any backend (rows one by one).
    tol : float
        Certificate tolerance per row.

    Returns
    -------
    BatchResult
        Certified row by row.

    Raises
    ------
    ShapeError, InputError, UnknownBackendError, BackendUnsuitableError
        Bad input (named).
    CertificateError
        A closed-form law's row fails its certificate, or no backend certifies a row.
    """
    check_problem(problem)
    check_law(law)
    U = as_rows(problem, U_minus)
    tol = check_tol(tol)
    if law.forms or backend != law.closed_form_backend:
        check_backend(backend)
    law.check(problem)
    st = problem.structure
    k = U.shape[0]
    if not law.forms:
        Up, Lam = law.closed_form_rows(problem, U)
        res = law.residuals(st, U, Up, Lam)
        out = BatchResult(u_plus=Up, impulses=Lam, residuals=res,
                          backend=law.closed_form_backend, resolved=0, tol=tol)
        if not out.ok.all():
            i = int(np.flatnonzero(~out.ok)[0])
            raise CertificateError(f"{law.title}: row {i} fails its certificate: "
                                   + ", ".join(f"{key}={v[i]:.1e}" for key, v in res.items()))
        return out
    fast = _fast_path(problem, law, backend)
    if fast is not None:
        name, form, qp = fast
        module = backends.load(backends.REGISTRY[name])
        X, Y, done = module.solve_many(qp, law.linear_terms(problem, U, form))
        Up, Lam = law.recover_rows(problem, form, U, X, Y)
        res = law.residuals(st, U, Up, Lam)
        rows = np.flatnonzero(~done | ~certified_rows(res, tol))
        used = name
    else:  # every row goes through the single-impact pipeline
        Up, Lam = np.empty_like(U), np.zeros((k, st.m))
        rows, used = np.arange(k), backend
    for i in rows:
        r = solve(problem.with_u_minus(U[i]), law, "auto" if fast is not None else backend,
                  tol=tol)
        Up[i], Lam[i] = r.u_plus, r.impulses
        used = used if fast is not None else r.backend
    if fast is None:
        res = law.residuals(st, U, Up, Lam)
    elif rows.size:
        fixed = law.residuals(st, U[rows], Up[rows], Lam[rows])
        for key in res:
            res[key][rows] = fixed[key]
    return BatchResult(u_plus=Up, impulses=Lam, residuals=res, backend=used,
                       resolved=int(rows.size if fast is not None else 0), tol=tol)


def moreau_batch(problem: ImpactProblem, U_minus: Any, eps: float = 0.0,
                 backend: str = "auto", *, tol: float = DEFAULT_TOL) -> BatchResult:
    """Moreau's law (docs/theory.md §3) for every row of ``U_minus``:
    ``solve_batch(problem, Moreau(eps), U_minus, backend, tol=tol)``.

    Parameters
    ----------
    problem : ImpactProblem
        Supplies M and W (its own u⁻ is not used).
    U_minus : (k, n) array_like
        Pre-impact velocities, one per row.
    eps : float
        Restitution ε ∈ [0, 1].
    backend : str
        ``"auto"``, a fast path (``"isotonic"``, ``"kernel"``) or a QP backend (rows one by one).
    tol : float
        Certificate tolerance per row.

    Returns
    -------
    BatchResult

    Raises
    ------
    RestitutionError, ShapeError, UnknownBackendError, BackendUnsuitableError, CertificateError
    """
    check_problem(problem)
    return solve_batch(problem, Moreau(eps), U_minus, backend, tol=tol)


def sector_law_batch(problem: ImpactProblem, U_minus: Any, *,
                     tol: float = DEFAULT_TOL) -> BatchResult:
    """The sector law u⁺ = sort(u⁻) (docs/theory.md §6) for every row of ``U_minus`` on an
    equal-mass chain: ``solve_batch(problem, SectorLaw(), U_minus, tol=tol)``.

    Returns
    -------
    BatchResult

    Raises
    ------
    SectorLawError
        When the problem is not a free chain of equal masses.
    CertificateError
        When a row fails its recomputed certificate (rounding with wildly mixed magnitudes).
    """
    return solve_batch(problem, SectorLaw(), U_minus, tol=tol)
