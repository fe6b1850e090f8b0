"""LCPs with a symmetric positive semidefinite matrix, solved as convex QPs (docs/theory.md §3).

``0 ≤ z ⟂ Gz + q ≥ 0`` with G symmetric PSD is the KKT system of
``min ½zᵀGz + qᵀz, z ≥ 0``: the same program as the impulse form of an impact law. A
non-symmetric or indefinite G is refused: such an LCP is not this QP, and answering it
through the QP would be wrong.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..base.arrays import as_array, check_tol
from ..base.checks import DEFAULT_TOL, Certificate
from ..errors import (
    NonConvexLCPError,
    NonSymmetricLCPError,
    NoSolutionError,
    OutOfRangeError,
    ShapeError,
)
from . import backends
from .certified import solve_in_forms
from .program import QPSolution, QuadraticProgram


@dataclass(frozen=True)
class LCPResult:
    """A certified solution of ``0 ≤ z ⟂ w = Gz + q ≥ 0``.

    Attributes
    ----------
    z, w : ndarray
    error : float
        ‖z − max(0, z − w)‖ / ‖(G, q)‖ (the natural-map residual, dimensionless).
    residuals : dict
        Largest violations of z ≥ 0, w ≥ 0 and abs(zᵢwᵢ), scaled.
    backend : str
        What produced z (``"kernel"``, ``"nnls"``, ``"clarabel"``, ...): a name ``backend=`` takes.
    tol : float
    attempts : list of str
        What was tried, in order.
    solve_time : float
        Seconds spent in the solve (validation excluded).
    """

    z: np.ndarray
    w: np.ndarray
    error: float
    residuals: dict
    backend: str
    tol: float
    attempts: list = field(default_factory=list)
    solve_time: float = 0.0

    @property
    def certificate(self) -> Certificate:
        """The recomputed residuals as a certificate (the same idiom as impact results)."""
        return Certificate(self.residuals, self.tol)

    @property
    def ok(self) -> bool:
        """True when every recomputed residual is within ``tol`` (always, when returned)."""
        return self.certificate.ok

    success = ok
    status = "solved"

    @property
    def message(self) -> str:
        return f"solved by {self.backend}; certificate {self.certificate.summary()}"


def _residuals(G: Any, q: np.ndarray, z: np.ndarray) -> tuple[np.ndarray, dict]:
    """w = Gz + q and the residuals, for an LCP already normalized (max |Gᵢⱼ| = 1, max |qᵢ| = 1)."""
    w = np.asarray(G @ z).ravel() + q
    scale = 1.0 + np.linalg.norm(q)
    zs = max(np.abs(z).max(initial=0.0), 1.0)
    return w, {
        "natural_map": float(np.linalg.norm(z - np.maximum(0.0, z - w)) / scale),
        "z_sign": float(max(0.0, -z.min(initial=0.0)) / zs),
        "w_sign": float(max(0.0, -w.min(initial=0.0)) / scale),
        "complementarity": float(np.abs(z * w).max(initial=0.0) / (scale * zs)),
    }


def check_lcp(G: Any, q: Any) -> tuple[np.ndarray, np.ndarray]:
    """Validate an LCP (G symmetric PSD, q matching) and return float arrays.

    Raises
    ------
    ShapeError, NonFiniteError, InputError
        Malformed G or q (named).
    NonSymmetricLCPError, NonConvexLCPError
        G is not symmetric / not positive semidefinite.
    """
    G = as_array("G", G.toarray() if hasattr(G, "toarray") else G, ndim=2)
    q = as_array("q", q, ndim=1)
    if G.shape[0] != G.shape[1]:
        raise ShapeError(f"G must be a square matrix, got shape {G.shape}")
    if q.shape != (G.shape[0],):
        raise ShapeError(f"q must have shape ({G.shape[0]},), got {q.shape}")
    scale = np.abs(G).max(initial=0.0)
    if scale == 0.0:
        return G, q
    asym = np.abs(G - G.T).max(initial=0.0)
    if asym > 1e-12 * scale:
        raise NonSymmetricLCPError(
            f"G is not symmetric (max |G − Gᵀ| = {asym:.3g}): a non-symmetric LCP is not a "
            "convex QP, and impactqp does not answer it")
    G = 0.5 * (G + G.T)
    eig = np.linalg.eigvalsh(G / scale).min(initial=0.0) if G.size else 0.0
    if eig < -1e-10:
        raise NonConvexLCPError(f"G is not positive semidefinite (smallest eigenvalue "
                                f"{eig * scale:.3g}): the LCP is not a convex QP")
    return G, q


def solve_lcp(G: Any, q: Any, backend: str = "auto", *, tol: float = DEFAULT_TOL) -> LCPResult:
    """Solve ``0 ≤ z ⟂ Gz + q ≥ 0`` for symmetric positive semidefinite G.

    .. math:: \\min_{z \\ge 0} \\tfrac12 z^T G z + q^T z

    The problem is normalized (G and q each by its largest entry) before it is solved and
    certified, so the answer does not depend on the units of G and q, down to the smallest
    and up to the largest floats.

    Parameters
    ----------
    G : (k, k) array_like
        Symmetric positive semidefinite (singular allowed: then the solution set may be a
        whole face; the certificate checks the returned point, not uniqueness).
    q : (k,) array_like
    backend : str
        ``"auto"`` or any registered backend (:func:`impactqp.available_backends`).
    tol : float
        Tolerance of the recomputed residuals, in (0, 1).

    Returns
    -------
    LCPResult
        Only when its recomputed residuals pass.

    Raises
    ------
    NonSymmetricLCPError, NonConvexLCPError
        G is not symmetric / not PSD.
    UnknownBackendError, BackendUnsuitableError
        Unknown backend, or one that cannot take this LCP.
    NoSolutionError
        The LCP is infeasible.
    OutOfRangeError
        The solution's scale max|q|/max|G| is beyond what floats represent.
    CertificateError
        No backend reached ``tol``.
    """
    G, q = check_lcp(G, q)
    tol = check_tol(tol)
    if backend != "auto":
        backends.parse_backend(backend)
    return solve_psd_lcp(G, q, backend, tol=tol)


def solve_psd_lcp(G: Any, q: np.ndarray, backend: str = "auto", *,
                  tol: float = DEFAULT_TOL) -> LCPResult:
    """:func:`solve_lcp` without the input checks, for a G (dense or scipy.sparse) already
    known to be symmetric positive semidefinite, such as a Delassus matrix."""
    start = time.perf_counter()
    g_scale = float(abs(G).max()) if G.shape[0] else 0.0
    q_scale = float(np.abs(q).max(initial=0.0))  # max |qᵢ|: a norm would overflow first
    if q_scale == 0.0 or np.all(q >= 0):
        # z = 0 solves it exactly (w = q ≥ 0)
        z = np.zeros(q.size)
        _, res = _residuals(G, q / max(q_scale, 1.0), z)
        return LCPResult(z, q.copy(), 0.0, res, "none", tol, ["q ≥ 0: z = 0"],
                         time.perf_counter() - start)
    if g_scale == 0.0:
        raise NoSolutionError("G = 0 and q has a negative entry: the LCP has no solution")
    z_scale = q_scale / g_scale
    if not np.isfinite(z_scale) or z_scale == 0.0:
        raise OutOfRangeError(f"the solution z scales as max|q|/max|G| = {q_scale:.3g}/"
                              f"{g_scale:.3g}, which floats cannot represent; rescale G or q")
    Gn, qn = G / g_scale, q / q_scale
    qp = QuadraticProgram(P=Gn, c=qn)

    def finish(sol: QPSolution):
        z = np.maximum(sol.x, 0.0)
        w, res = _residuals(Gn, qn, z)
        return (z, w, res), Certificate(res, tol)

    out = solve_in_forms([("impulse", lambda: qp, finish)], backend)
    z, w, res = out.answer
    with np.errstate(over="ignore"):
        z, w = z * z_scale, w * q_scale
    if not (np.isfinite(z).all() and np.isfinite(w).all()):
        raise OutOfRangeError(f"the solution z (scale {z_scale:.3g}) or w = Gz + q (scale "
                              f"{q_scale:.3g}) overflows floats; rescale G or q")
    return LCPResult(z=z, w=w, error=res["natural_map"],
                     residuals=res, backend=out.backend, tol=tol, attempts=out.attempts,
                     solve_time=time.perf_counter() - start)
