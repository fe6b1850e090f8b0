"""The timed methods: impactqp's paths and the raw solvers on the same programs.

A method's ``prepare(case)`` does everything that is not the solve (building matrices,
cvxpy problems, closures) and returns ``(solve, finish)``: only ``solve()`` is timed,
``finish(raw)`` turns its output into u⁺ (or a batch's U⁺) for the accuracy check.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import clarabel
import cvxpy as cp
import numpy as np
import qpsolvers
import scipy.sparse as sp
from scipy.optimize import isotonic_regression

import impactqp as iq
from impactqp.qp.backends.exact import MAX_CONSTRAINTS
from impactqp.qp.backends.kernel import MAX_VARIABLES as KERNEL_MAX
from impactqp.qp.backends.nnls_ import MAX_VARIABLES

from .families import Case

Solve = Callable[[], Any]
Finish = Callable[[Any], np.ndarray]


@dataclass(frozen=True)
class Method:
    """A named way to compute Moreau's u⁺ (or a batch of them).

    Attributes
    ----------
    name, group
        e.g. ``"iq:auto"`` in group ``"impactqp"``; groups: impactqp, raw, peer, batch.
    prepare : callable
        ``prepare(case) -> (solve, finish)``; raises to record a failure.
    kinds : tuple of str
        Case kinds the method takes (see :class:`~benchmarks.families.Case`).
    max_size : float
        Largest case size run (bigger ones are recorded as skipped with the reason).
    fits : callable, optional
        Extra applicability test ``fits(case) -> reason or None``.
    note : str
        What the timer covers when it is more than the solve.
    law : {"moreau", "sector"}
        Which law's reference the answer is compared with.
    """

    name: str
    group: str
    prepare: Callable[[Case], tuple[Solve, Finish]]
    kinds: tuple[str, ...] = ("chain", "dense", "sparse")
    max_size: float = float("inf")
    fits: Callable[[Case], str | None] | None = None
    note: str = ""
    law: str = "moreau"

    def skip_reason(self, case: Case) -> str | None:
        """Why this method does not run on ``case`` (None when it does)."""
        if case.kind not in self.kinds:
            return f"not for {case.kind} problems"
        if case.work > self.max_size:
            return f"size cap {self.max_size:g} (too slow beyond)"
        return self.fits(case) if self.fits else None


# --- impactqp ------------------------------------------------------------------------------
def _iq(backend: str) -> Callable[[Case], tuple[Solve, Finish]]:
    def prepare(case: Case) -> tuple[Solve, Finish]:
        p, e = case.problem, case.eps
        return (lambda: iq.moreau(p, e, backend)), (lambda r: r.u_plus)
    return prepare


def _dense_up_to(limit: int) -> Callable[[Case], str | None]:
    def fits(case: Case) -> str | None:
        if case.problem.structure.sparse:
            return "dense problems only"
        return None if case.n_contacts <= limit else f"needs m ≤ {limit}"
    return fits


def _contacts_up_to(limit: int) -> Callable[[Case], str | None]:
    return lambda case: None if case.n_contacts <= limit else f"needs m ≤ {limit}"


# --- the same QP for the raw solvers ------------------------------------------------------
def standard_qp(case: Case) -> tuple[Any, np.ndarray, Any, np.ndarray, Finish]:
    """(P, q, G, h, finish) of min ½xᵀPx + qᵀx s.t. Gx ≤ h: the impulse form for dense
    problems, the velocity form for sparse ones; ``finish(x)`` returns u⁺."""
    p, e = case.problem, case.eps
    st, u = p.structure, p.u_minus
    if st.sparse:
        P = sp.csc_matrix(st.M)
        G = -sp.csc_matrix(st.W.T)
        return P, -(P @ u), G, np.zeros(st.m), lambda x: (1 + e) * np.asarray(x) - e * u
    G_del = st.delassus
    return (G_del, (1 + e) * p.gamma_minus, -np.eye(st.m), np.zeros(st.m),
            lambda x: u + st.Minv_W @ np.asarray(x))


def _raw_clarabel(case: Case) -> tuple[Solve, Finish]:
    P, q, G, h, finish = standard_qp(case)
    P = sp.triu(sp.csc_matrix(P), format="csc")
    G = sp.csc_matrix(G)
    settings = clarabel.DefaultSettings()
    settings.verbose = False
    cones = [clarabel.NonnegativeConeT(G.shape[0])]

    def solve() -> Any:
        return clarabel.DefaultSolver(P, q, G, h, cones, settings).solve()

    def done(sol: Any) -> np.ndarray:
        if "Solved" not in str(sol.status):
            raise RuntimeError(f"clarabel status {sol.status}")
        return finish(sol.x)
    return solve, done


def _raw_qpsolvers(name: str) -> Callable[[Case], tuple[Solve, Finish]]:
    def prepare(case: Case) -> tuple[Solve, Finish]:
        if name not in qpsolvers.available_solvers:
            raise RuntimeError(f"qpsolvers has no {name!r}")
        P, q, G, h, finish = standard_qp(case)
        if name not in qpsolvers.sparse_solvers:
            P, G = (a.toarray() if sp.issparse(a) else a for a in (P, G))
        else:
            P, G = sp.csc_matrix(P), sp.csc_matrix(G)

        def done(x: Any) -> np.ndarray:
            if x is None:
                raise RuntimeError(f"qpsolvers:{name} found no solution")
            return finish(x)
        return (lambda: qpsolvers.solve_qp(P, q, G, h, solver=name)), done
    return prepare


def _velocity_shift(case: Case, gamma: Any) -> tuple[cp.Problem, cp.Variable]:
    """min ½ΔᵀMΔ s.t. WᵀΔ + γ⁻ ≥ 0 (the parameter sits in the constraints, not the objective)."""
    st = case.problem.structure
    delta = cp.Variable(st.n)
    if st.sparse:
        root = sp.diags(np.sqrt(st.M.diagonal()))
        energy = cp.sum_squares(root @ delta)
    else:
        energy = cp.sum_squares(st.cholesky_factor.T @ delta)
    return cp.Problem(cp.Minimize(0.5 * energy), [st.W.T @ delta + gamma >= 0]), delta


def _cvxpy_finish(case: Case, delta: cp.Variable, prob: cp.Problem) -> Finish:
    u, e = case.problem.u_minus, case.eps

    def finish(_: Any) -> np.ndarray:
        if prob.status != "optimal" or delta.value is None:
            raise RuntimeError(f"cvxpy status {prob.status}")
        return u + (1 + e) * delta.value
    return finish


def _cvxpy_first(case: Case) -> tuple[Solve, Finish]:
    gamma = case.problem.gamma_minus
    holder: dict[str, Any] = {}

    def solve() -> Any:
        prob, delta = _velocity_shift(case, gamma)
        prob.solve(solver=cp.CLARABEL)
        holder.update(prob=prob, delta=delta)

    return solve, lambda _: _cvxpy_finish(case, holder["delta"], holder["prob"])(None)


def _cvxpy_dpp(case: Case) -> tuple[Solve, Finish]:
    gamma = cp.Parameter(case.n_contacts)
    gamma.value = case.problem.gamma_minus
    prob, delta = _velocity_shift(case, gamma)
    prob.solve(solver=cp.CLARABEL)  # the first solve compiles the DPP mapping

    def solve() -> Any:
        gamma.value = case.problem.gamma_minus
        prob.solve(solver=cp.CLARABEL)
    return solve, _cvxpy_finish(case, delta, prob)


# --- the floor for chains ----------------------------------------------------------------------
def _free_chain(case: Case) -> str | None:
    c = case.problem.chain
    if c is None or c.left_wall or c.right_wall:
        return "free chains only"
    return None


def _raw_isotonic(case: Case) -> tuple[Solve, Finish]:
    """scipy's weighted isotonic regression on the same data: the floor of a chain impact."""
    p, e = case.problem, case.eps
    masses, u = p.chain.masses, p.u_minus
    return ((lambda: isotonic_regression(u, weights=masses)),
            (lambda r: (1.0 + e) * r.x - e * u))


def _iq_cold(case: Case) -> tuple[Solve, Finish]:
    """Build the chain problem from masses and u⁻, then solve (nothing cached)."""
    p, e = case.problem, case.eps
    masses, u = p.chain.masses.copy(), p.u_minus.copy()
    return (lambda: iq.moreau(iq.chain(masses, u), e)), (lambda r: r.u_plus)


def _iq_fresh(case: Case) -> tuple[Solve, Finish]:
    """Build ``ImpactProblem(M, W, u⁻)`` from the arrays, then solve (nothing cached)."""
    st, e = case.problem.structure, case.eps
    M, W, u = np.array(st.M), np.array(st.W), case.problem.u_minus.copy()
    return (lambda: iq.moreau(iq.ImpactProblem(M, W, u), e)), (lambda r: r.u_plus)


# --- batches ---------------------------------------------------------------------------------
def _moreau_batch(case: Case) -> tuple[Solve, Finish]:
    return (lambda: iq.moreau_batch(case.problem, case.U, case.eps)), (lambda r: r.u_plus)


def _moreau_batch_out(case: Case) -> tuple[Solve, Finish]:
    """A stream of batches: each call writes into the previous call's result (``out=``),
    whose pages are already touched (the first result is made here, untimed)."""
    last = [iq.moreau_batch(case.problem, case.U, case.eps)]

    def solve() -> Any:
        last[0] = iq.moreau_batch(case.problem, case.U, case.eps, out=last[0])
        return last[0]
    return solve, (lambda r: r.u_plus)


def _sector_batch(case: Case) -> tuple[Solve, Finish]:
    return (lambda: iq.sector_law_batch(case.problem, case.U)), (lambda r: r.u_plus)


BIG = 100_000
METHODS: list[Method] = [
    Method("iq:auto", "impactqp", _iq("auto")),
    Method("iq:isotonic", "impactqp", _iq("isotonic"), kinds=("chain",)),
    Method("iq:kernel", "impactqp", _iq("kernel"), fits=_dense_up_to(KERNEL_MAX)),
    Method("iq:nnls", "impactqp", _iq("nnls"), fits=_dense_up_to(MAX_VARIABLES)),
    Method("iq:exact", "impactqp", _iq("exact"), fits=_contacts_up_to(MAX_CONSTRAINTS - 2)),
    Method("iq:clarabel", "impactqp", _iq("clarabel"), max_size=BIG),
    Method("iq:osqp", "impactqp", _iq("osqp"), max_size=200),
    Method("iq:cvxpy", "impactqp", _iq("cvxpy"), max_size=10_000),
    Method("iq:qpsolvers:daqp", "impactqp", _iq("qpsolvers:daqp"), max_size=1000),
    Method("iq:qpsolvers:piqp", "impactqp", _iq("qpsolvers:piqp"), max_size=BIG),
    Method("raw:clarabel", "raw", _raw_clarabel, max_size=BIG,
           note="DefaultSolver construction + solve; matrices built before"),
    Method("raw:cvxpy-first", "raw", _cvxpy_first, max_size=BIG,
           note="includes building the cvxpy problem (its definition)"),
    Method("raw:cvxpy-dpp", "raw", _cvxpy_dpp, max_size=BIG,
           note="re-solve after setting the Parameter γ⁻ (in the constraints)"),
    Method("raw:qpsolvers:daqp", "raw", _raw_qpsolvers("daqp"), max_size=1000),
    Method("raw:qpsolvers:piqp", "raw", _raw_qpsolvers("piqp"), max_size=BIG),
    Method("raw:qpsolvers:highs", "raw", _raw_qpsolvers("highs"), max_size=1000),
    Method("iq:cold", "impactqp", _iq_cold, kinds=("chain",), fits=_free_chain,
           note="builds the chain problem (validation, structure), then solves"),
    Method("iq:fresh", "impactqp", _iq_fresh, kinds=("dense",), fits=_dense_up_to(KERNEL_MAX),
           note="builds ImpactProblem(M, W, u⁻) from arrays, then solves"),
    Method("raw:isotonic_regression", "raw", _raw_isotonic, kinds=("chain",),
           fits=_free_chain, note="scipy.optimize.isotonic_regression alone, no certificate"),
    Method("iq:moreau_batch", "batch", _moreau_batch, kinds=("batch",)),
    Method("iq:moreau_batch:out", "batch", _moreau_batch_out, kinds=("batch",),
           note="each call writes into the previous call's result (out=)"),
    Method("iq:sector_law_batch", "batch", _sector_batch, kinds=("batch",),
           law="sector"),
]
