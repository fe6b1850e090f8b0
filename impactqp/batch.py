"""Many impacts of one problem structure at once (k pre-impact velocities, rows of a matrix).

The fast paths run vectorised over the rows (isotonic regression for chains, the prepared
active-set kernel for small dense impacts); rows they cannot settle, and every row of other
structures, go through the single-impact law. Every row's certificate is recomputed
(:func:`impactqp.certificate.law_residuals`); a row that fails it is solved again on its
own, which raises if no backend certifies it, so a returned batch is certified row by row.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from .certificate import DEFAULT_TOL, law_residuals
from .errors import CertificateError, ShapeError
from .fastpaths import applies, moreau_batch_fast
from .laws import check_backend_name, check_eps, moreau
from .problem import ImpactProblem, _finite
from .sector_law import check_sector_problem, sector_answer, sector_residuals


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


def certified_rows(residuals: dict, tol: float) -> np.ndarray:
    """Rows whose every residual is within ``tol`` (NaN fails)."""
    return np.all([v <= tol for v in residuals.values()], axis=0)


def as_rows(problem: ImpactProblem, U_minus: Any) -> np.ndarray:
    """Validate a (k, n) matrix of pre-impact velocities."""
    U = np.asarray(U_minus, dtype=float)
    if U.ndim != 2 or U.shape[1] != problem.n_dof:
        raise ShapeError(f"U_minus must have shape (k, {problem.n_dof}), got {U.shape}")
    _finite("U_minus", U)
    return U


def moreau_batch(problem: ImpactProblem, U_minus: Any, eps: float = 0.0,
                 backend: str = "auto", *, tol: float = DEFAULT_TOL) -> BatchResult:
    """Moreau's law (§3) for every row of ``U_minus`` on the structure of ``problem``.

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
    """
    U = as_rows(problem, U_minus)
    e = check_eps(eps)
    check_backend_name(backend)
    st = problem.structure
    k = U.shape[0]
    path = applies(st, backend) if st.m else None
    if path is not None:
        Up, Lam, done = moreau_batch_fast(st, U, e, path)
        res = law_residuals(st, U, Up, Lam, e, eps=e)
        rows = np.flatnonzero(~done | ~certified_rows(res, tol))
        used = path
    else:  # every row goes through the single-impact law
        Up, Lam = np.empty_like(U), np.zeros((k, st.m))
        rows, used = np.arange(k), backend
    for i in rows:
        r = moreau(problem.with_u_minus(U[i]), e, "auto" if backend in ("isotonic", "kernel")
                   else backend, tol=tol)
        Up[i], Lam[i] = r.u_plus, r.impulses
        used = used if path is not None else r.backend
    if path is None:
        res = law_residuals(st, U, Up, Lam, e, eps=e)
    elif rows.size:
        fixed = law_residuals(st, U[rows], Up[rows], Lam[rows], e, eps=e)
        for key in res:
            res[key][rows] = fixed[key]
    return BatchResult(u_plus=Up, impulses=Lam, residuals=res, backend=used,
                       resolved=int(rows.size if path is not None else 0), tol=tol)


def sector_law_batch(problem: ImpactProblem, U_minus: Any, *,
                     tol: float = DEFAULT_TOL) -> BatchResult:
    """The sector law u⁺ = sort(u⁻) (§6) for every row of ``U_minus`` on an equal-mass chain.

    Raises
    ------
    SectorLawError
        When the problem is not a free chain of equal masses.
    CertificateError
        When a row fails its recomputed certificate (rounding with wildly mixed magnitudes).
    """
    mass = check_sector_problem(problem)
    U = as_rows(problem, U_minus)
    Up, Lam = sector_answer(mass, U)
    res = sector_residuals(problem.structure, U, Up, Lam)
    out = BatchResult(u_plus=Up, impulses=Lam, residuals=res, backend="sort", resolved=0, tol=tol)
    if not out.ok.all():
        i = int(np.flatnonzero(~out.ok)[0])
        raise CertificateError(f"sector law: row {i} fails its certificate: "
                               + ", ".join(f"{k}={v[i]:.1e}" for k, v in res.items()))
    return out
