"""Derivatives of many impacts of one structure: :func:`derivative_batch`
(docs/theory.md §18–§20).

Dense impacts of a compiled complementarity family (Moreau, local Newton, Frémond; where the
compiled single impact applies) are solved and certified in the chunks of
:func:`impactqp.solve_batch` by its compiled rows
(:func:`impactqp.kernels.impact.solve_impact_rows`; short chains by its column path), then
differentiated by :func:`impactqp.kernels.derivative.derivative_rows`, each row on its
active set with one factor of G_AA. Other laws, and rows the kernel does not certify, go one
by one through :func:`impactqp.solve` and ``result.derivative()``.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from ..base.arrays import as_array, as_count
from ..base.checks import DEFAULT_TOL
from ..errors import DerivativeUnsupportedError, ShapeError
from ..kernels import derivative as compiled
from ..kernels.impact import solve_impact_rows
from ..kernels.jit import read_only
from ..laws import small
from ..laws.base import MOREAU_FAMILY
from ..laws.batch import _in_chunks, as_rows, solve_batch
from ..laws.pipeline import solve
from ..laws.planner import plan, validate
from .impact import KINK_TOL

STATUS = ("smooth", "kink", "unsupported")
"""Names of the row status codes (the kernel's SMOOTH, KINK; a law without derivative)."""


@dataclass(frozen=True)
class DerivativeBatch:
    """k impacts of one structure with their derivatives in u⁻.

    Attributes
    ----------
    u_plus, impulses : (k, n), (k, m) ndarray
    jvp : (k, n) ndarray or None
        du⁺ = (∂u⁺/∂u⁻) du⁻ per row (the default element at kinks).
    vjp : (k, n) ndarray or None
        ū⁻ = (∂u⁺/∂u⁻)ᵀ ū per row.
    status : (k,) ndarray of str
        ``"smooth"`` or ``"kink"`` per row.
    margin : (k,) ndarray
        The cell's radius relative to ‖u⁻‖ per row (0 at a kink).
    backend : str
        ``"kernel"`` (compiled) or ``"rows"`` (one by one).
    """

    u_plus: np.ndarray
    impulses: np.ndarray
    jvp: np.ndarray | None
    vjp: np.ndarray | None
    status: np.ndarray
    margin: np.ndarray
    backend: str


def _directions(name: str, value: Any, shape: tuple[int, int]) -> np.ndarray | None:
    if value is None:
        return None
    arr = as_array(name, value, copy=False)  # read only
    if arr.shape != shape:
        raise ShapeError(f"{name} must have shape {shape} (one row per impact), got "
                         f"{arr.shape}")
    return np.ascontiguousarray(arr)


def _compiled(problem, law, U, dU, Ubar, tol, kink_tol, n_jobs):
    """The kernel's rows; the indices of rows it did not certify."""
    st = problem.structure
    k, n, m = U.shape[0], st.n, st.m
    moreau = law.family == MOREAU_FAMILY
    E = small.restitution_for(law, m)
    eps = law.eps if moreau else 0.0
    IE = np.eye(m) + (law.eps * np.eye(m) if moreau else E)
    settings = compiled.Settings(tol, kink_tol, dU is not None, Ubar is not None)
    dUp, Uout = np.empty((k, n)) if dU is not None else None, \
        np.empty((k, n)) if Ubar is not None else None
    chain = plan(problem, law, "auto", mode="batch").path == "chain"
    if chain:  # a short chain: its columns solve faster than rows; differentiate after
        done = solve_batch(problem, law, U, tol=tol, n_jobs=n_jobs)
        Up, Lam, solved = done.u_plus, done.impulses, np.ones(k, dtype=bool)
    else:
        Up, Lam, solved = np.empty((k, n)), np.empty((k, m)), np.empty(k, dtype=bool)
    out = compiled.Rows(Up, Lam, dUp, Uout, np.empty(k, dtype=np.int64), np.empty(k))
    placeholder = np.zeros((1, n))

    def work(a: int, b: int) -> np.ndarray:
        Ua = read_only(np.ascontiguousarray(U[a:b]))
        if not chain:  # the batch's compiled rows, each chunk from its own cold support
            Up[a:b], Lam[a:b], _, solved[a:b] = solve_impact_rows(
                st.kernel_pack, Ua, E, eps, moreau, tol, np.zeros(m, dtype=bool))
        rows = compiled.Rows(Up[a:b], Lam[a:b],
                             placeholder.copy() if dUp is None else dUp[a:b],
                             placeholder.copy() if Uout is None else Uout[a:b],
                             out.status[a:b], out.margin[a:b])
        compiled.derivative_rows(st.kernel_pack, Ua, placeholder if dU is None else dU[a:b],
                                 placeholder if Ubar is None else Ubar[a:b], IE, settings,
                                 solved[a:b], rows)
        return a + np.flatnonzero(rows.status == compiled.UNCERTIFIED)

    return out, _in_chunks(k, work, n_jobs)


def derivative_batch(problem: Any, law: Any, U_minus: Any, *, jvp: Any = None,
                     vjp: Any = None, tol: float = DEFAULT_TOL, kink_tol: float = KINK_TOL,
                     n_jobs: int = 1) -> DerivativeBatch:
    """``law`` and its derivative in u⁻ for every row of ``U_minus`` (docs/theory.md §18).

    Parameters
    ----------
    problem : ImpactProblem
        Supplies M and W (its own u⁻ is not used).
    law : ImpactLaw
    U_minus : (k, n) array_like
    jvp : (k, n) array_like, optional
        A tangent of u⁻ per row: the answer's ``jvp`` holds du⁺ per row.
    vjp : (k, n) array_like, optional
        A cotangent of u⁺ per row: the answer's ``vjp`` holds ū⁻ per row.
    tol, kink_tol : float
        The certificate's tolerance and the degeneracy tolerance (docs/theory.md §19).
    n_jobs : int
        Threads working on chunks at once.

    Returns
    -------
    DerivativeBatch
        Certified rows with their derivatives, status and margins.

    Raises
    ------
    DerivativeUnsupportedError
        The law has no derivative (named).
    ShapeError, InputError
        Bad input (named).
    """
    tol = validate(problem, law, "auto", "auto", tol)
    U = as_rows(problem, U_minus)
    n_jobs = as_count("n_jobs", n_jobs, minimum=1)
    k, n = U.shape
    dU, Ubar = _directions("jvp", jvp, (k, n)), _directions("vjp", vjp, (k, n))
    kink_tol = float(kink_tol)
    if small.applies(problem, law, "auto", "auto"):
        out, rows = _compiled(problem, law, U, dU, Ubar, tol, kink_tol, n_jobs)
        Up, Lam, dUp, Uout, codes, margin = out.Up, out.Lam, out.dUp, out.Ubar, \
            out.status, out.margin
        backend = "kernel"
    else:
        Up, Lam = np.empty((k, n)), np.empty((k, problem.n_impulses))
        dUp = None if dU is None else np.empty((k, n))
        Uout = None if Ubar is None else np.empty((k, n))
        codes, margin, rows, backend = np.empty(k, dtype=np.int64), np.empty(k), \
            np.arange(k), "rows"
    for i in rows:
        r = solve(problem.with_u_minus(U[i]), law, tol=tol)
        d = r.derivative(kink_tol=kink_tol)
        if d.status == "unsupported":
            raise DerivativeUnsupportedError(d.reason)
        Up[i], Lam[i] = r.u_plus, r.impulses
        codes[i], margin[i] = STATUS.index(d.status), d.local.margin
        if dUp is not None:
            dUp[i] = d.jvp(u_minus=dU[i]).u_plus
        if Uout is not None:
            Uout[i] = d.vjp(u_plus=Ubar[i])["u_minus"]
    return DerivativeBatch(Up, Lam, dUp, Uout, np.asarray(STATUS)[codes], margin, backend)
