"""LCPs with a symmetric positive semidefinite matrix, solved as convex QPs (§3).

``0 ≤ z ⟂ Gz + q ≥ 0`` with G symmetric PSD is the KKT system of
``min ½zᵀGz + qᵀz, z ≥ 0``: the same program as the impulse form of an impact law. A
non-symmetric or indefinite G is refused: such an LCP is not this QP, and answering it
through the QP would be wrong.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from .backends import parse_backend
from .certificate import DEFAULT_TOL, ResidualChecks
from .dispatch import solve_certified
from .errors import NonConvexLCPError, NonFiniteError, NonSymmetricLCPError, ShapeError
from .problem import as_dense
from .program import QPSolution, QuadraticProgram


@dataclass(frozen=True)
class LCPResult:
    """A certified solution of ``0 ≤ z ⟂ w = Gz + q ≥ 0``.

    Attributes
    ----------
    z, w : ndarray
    error : float
        ‖z − max(0, z − w)‖ / (1 + ‖q‖) (the natural-map residual).
    residuals : dict
        Largest violations of z ≥ 0, w ≥ 0 and |zᵢwᵢ|, scaled.
    backend : str
    """

    z: np.ndarray
    w: np.ndarray
    error: float
    residuals: dict
    backend: str
    tol: float

    @property
    def ok(self) -> bool:
        return self.error <= self.tol and all(v <= self.tol for v in self.residuals.values())


@dataclass(frozen=True)
class _LCPCertificate(ResidualChecks):
    values: dict
    tol: float

    @property
    def residuals(self) -> dict[str, float]:
        return self.values


def _residuals(G: Any, q: np.ndarray, z: np.ndarray) -> tuple[np.ndarray, dict]:
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
    """Validate an LCP (G symmetric PSD, q matching) and return float arrays."""
    G = as_dense(G)
    q = np.asarray(q, dtype=float)
    if G.ndim != 2 or G.shape[0] != G.shape[1]:
        raise ShapeError(f"G must be a square matrix, got shape {G.shape}")
    if q.shape != (G.shape[0],):
        raise ShapeError(f"q must have shape ({G.shape[0]},), got {q.shape}")
    if not (np.all(np.isfinite(G)) and np.all(np.isfinite(q))):
        raise NonFiniteError("G and q must be finite")
    scale = max(np.abs(G).max(initial=0.0), 1e-300)
    asym = np.abs(G - G.T).max(initial=0.0)
    if asym > 1e-12 * scale:
        raise NonSymmetricLCPError(
            f"G is not symmetric (max |G − Gᵀ| = {asym:.3g}): a non-symmetric LCP is not a "
            "convex QP, and impactqp does not answer it")
    G = 0.5 * (G + G.T)
    eig = np.linalg.eigvalsh(G).min(initial=0.0) if G.size else 0.0
    if eig < -1e-10 * scale:
        raise NonConvexLCPError(f"G is not positive semidefinite (smallest eigenvalue {eig:.3g}): "
                                "the LCP is not a convex QP")
    return G, q


def solve_lcp(G: Any, q: Any, backend: str = "auto", *, tol: float = DEFAULT_TOL) -> LCPResult:
    """Solve ``0 ≤ z ⟂ Gz + q ≥ 0`` for symmetric positive semidefinite G.

    Parameters
    ----------
    G : (k, k) array_like
        Symmetric positive semidefinite (singular allowed: then the solution set may be a
        whole face; the certificate checks the returned point, not uniqueness).
    q : (k,) array_like
    backend : str
        ``"auto"`` or any backend name.
    tol : float
        Tolerance of the recomputed residuals.

    Raises
    ------
    NonSymmetricLCPError, NonConvexLCPError
        G is not symmetric / not PSD.
    NoSolutionError
        The LCP is infeasible.
    CertificateError
        No backend reached ``tol``.
    """
    G, q = check_lcp(G, q)
    if backend != "auto":
        parse_backend(backend)
    return solve_psd_lcp(G, q, backend, tol=tol)


def solve_psd_lcp(G: Any, q: np.ndarray, backend: str = "auto", *,
                  tol: float = DEFAULT_TOL) -> LCPResult:
    """:func:`solve_lcp` without the input checks, for a G (dense or scipy.sparse) already
    known to be symmetric positive semidefinite, such as a Delassus matrix."""
    if q.size == 0:
        return LCPResult(np.zeros(0), np.zeros(0), 0.0, {}, "none", tol)
    qp = QuadraticProgram(P=G, c=q)

    def finish(sol: QPSolution):
        z = np.maximum(sol.x, 0.0)
        w, res = _residuals(G, q, z)
        return (z, w, res), _LCPCertificate(res, tol)

    (z, w, res), _, used, _ = solve_certified(qp, backend, finish)
    return LCPResult(z=z, w=w, error=res["natural_map"], residuals=res, backend=used, tol=tol)
