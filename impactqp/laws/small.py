"""Single impacts in compiled code: the pipeline's first fast path (docs/theory.md §8, §9).

For a dense impact of a law of a compiled family (``law.family``: Moreau's law, local Newton,
Frémond's law, or a user's law that declares the family), the whole solve — γ⁻, the
impulse-form LCP by the compiled active-set search, u⁺ and every residual of the law's
certificate — runs in one call of :func:`impactqp.kernels.impact.solve_impact`, which says
whether every residual is within the tolerance. An answer that misses it is not returned:
the pipeline goes on to the general path (QP backends, polishing).

Moreau's law on a chain of any length (``problem.chain``) takes the chain's own compiled call
instead, :func:`impactqp.kernels.chain.solve_chain`: the weighted isotonic regression and its
anchored impulses in O(N), then the chain certificate in a pass of its own (docs/theory.md
§5, §8); its answer is the ``"isotonic"`` backend's. Either call writes u⁺, Λ and the
residuals into one buffer, which the thin :class:`~impactqp.laws.result.CompiledImpactResult`
reads when asked.
"""

from __future__ import annotations

import time
import weakref
from typing import Any

import numpy as np

from ..base.checks import UNIT_RANGE
from ..kernels.chain import pack_chain, solve_chain, solve_short_chain
from ..kernels.impact import solve_impact
from ..kernels.residuals import RESIDUALS
from ..model.problem import ImpactProblem
from ..model.residuals import restitution_matrix
from ..qp.isotonic import scratch
from .base import FAMILIES, MOREAU_FAMILY, ImpactLaw
from .result import CompiledImpactResult, ImpactResult

MAX_CONTACTS = 400
"""Most contacts the compiled path takes (the dense LCP search costs O(m³) at most)."""

MAX_DOF = 2000
"""Most degrees of freedom the compiled path takes (its residuals cost O(n²) per impact)."""

SHORT_CHAIN = 10
"""Most contacts of a chain the compiled path takes; longer chains go to isotonic regression,
exact in O(N) where the Delassus matrix of a chain grows ill-conditioned (docs/theory.md §5)."""

_RESTITUTION: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()
"""The (m, m) restitution matrix of each law object, by m (laws are immutable)."""

_MOREAU_E = np.zeros((0, 0))
"""What the kernel takes as E for Moreau's law (it forms εI itself)."""


def restitution_for(law: ImpactLaw, m: int) -> np.ndarray:
    """The law's E as the kernel takes it, formed once per law object and contact count."""
    if law.family == MOREAU_FAMILY:
        return _MOREAU_E
    per_law = _RESTITUTION.setdefault(law, {})
    E = per_law.get(m)
    if E is None:
        E = per_law[m] = restitution_matrix(law.restitution(m), m)
    return E


def on_chain(problem: ImpactProblem, law: ImpactLaw, backend: str, form: str) -> bool:
    """Whether the chain's compiled call answers: Moreau's family (``law.family``) on a chain
    with at least one contact, asked with backend ``"auto"`` or ``"isotonic"`` (the call's
    answer is that backend's) and form ``"auto"`` or ``"velocity"``."""
    st = problem.structure
    return (backend in ("auto", "isotonic") and form in ("auto", "velocity")
            and st.chain is not None and st.m > 0 and law.family == MOREAU_FAMILY)


def dense(problem: ImpactProblem, law: ImpactLaw, backend: str, form: str) -> bool:
    """Whether the dense compiled call may answer: a dense structure within
    :data:`MAX_CONTACTS` (:data:`SHORT_CHAIN` for a chain) and :data:`MAX_DOF`, a law of a
    compiled family, backend ``"auto"`` or ``"kernel"``, form ``"auto"`` or ``"impulse"``
    (a batch runs it row by row)."""
    st = problem.structure
    return (backend in ("auto", "kernel") and form in ("auto", "impulse") and not st.sparse
            and 0 < st.m <= (MAX_CONTACTS if st.chain is None else SHORT_CHAIN)
            and st.n <= MAX_DOF
            and law.family in FAMILIES)


def applies(problem: ImpactProblem, law: ImpactLaw, backend: str, form: str) -> bool:
    """Whether the compiled path may answer one impact, by the chain's call or the dense one
    (it may still decline after trying)."""
    return on_chain(problem, law, backend, form) or dense(problem, law, backend, form)


def first_try(problem: Any, law: Any, tol: Any) -> ImpactResult | None:
    """The certified result of an impact that :func:`impactqp.solve` asked with
    ``backend="auto"`` and ``form="auto"``, by the compiled path, when the planner would route
    it there as it is; None otherwise, and when the compiled answer is not certified (the
    full route then decides, validates and raises).

    These are :func:`~impactqp.laws.planner.validate`'s and
    :func:`~impactqp.laws.planner.plan`'s decisions for the one case where they all pass,
    cheapest tests first: a problem and a law, a float tolerance in (0, 1), frictionless
    contacts of a law of a compiled family, u⁻ in the range worked in as given
    (:data:`!impactqp.base.checks.UNIT_RANGE`), no more contacts than degrees of freedom (so
    nothing to collapse), the law's own check of the problem, and :func:`applies`.
    """
    start = time.perf_counter()
    if type(problem) is not ImpactProblem or ImpactLaw not in type(law).__mro__:
        return None
    if type(tol) is not float or not 0.0 < tol < 1.0:
        return None
    st = problem.structure
    if st.m > st.n or not applies(problem, law, "auto", "auto") or st.contact_dim != 1:
        return None
    scale = problem.peak_minus
    if law.homogeneous and scale > 0 and not UNIT_RANGE[0] <= scale <= UNIT_RANGE[1]:
        return None
    law.check(problem)
    return solve_small(problem, law, tol, start)


def solve_small(problem: ImpactProblem, law: ImpactLaw, tol: float, start: float,
                backend: str = "auto", form: str = "auto") -> ImpactResult | None:
    """The certified result by the compiled path (the chain's call where :func:`on_chain`,
    else the dense one), or None to go on to the general path."""
    if on_chain(problem, law, backend, form):
        return _solve_chain(problem, law, tol, start)
    st = problem.structure
    n, m = st.n, st.m
    moreau = law.family == MOREAU_FAMILY
    eps = law.eps if moreau else 0.0
    out = np.empty(n + m + 6)
    if not solve_impact(st.kernel_pack, problem.u_minus, restitution_for(law, m), eps, moreau,
                        tol, st.warm_support, out):
        return None
    return CompiledImpactResult(problem, law, out, (n, n, n + m, n + m),
                                RESIDUALS if moreau else RESIDUALS[:4], tol, "kernel",
                                "impulse", time.perf_counter() - start)


SCRATCH_FROM = 256
"""Balls from which the chain's call reuses the thread's kept scratch (shorter chains have the
call allocate its own: :func:`impactqp.kernels.chain.solve_short_chain`)."""


def _solve_chain(problem: ImpactProblem, law: ImpactLaw, tol: float,
                 start: float) -> ImpactResult | None:
    """Moreau's law on a chain by :func:`impactqp.kernels.chain.solve_chain`."""
    st = problem.structure
    n = st.n
    chain = st.chain
    out = np.empty(2 * n + 1 + len(RESIDUALS))
    packed = getattr(st, "chain_pack", None)  # kept by a ChainStructure
    if packed is None:  # a structure marked as a chain by its builder
        packed = pack_chain(chain.masses, st.inverse_masses, st.contact_scale)
    if n < SCRATCH_FROM:
        done = solve_short_chain(packed, problem.u_minus, chain.left_wall, chain.right_wall,
                                 law.eps, tol, out)
    else:
        done = solve_chain(packed, problem.u_minus, chain.left_wall, chain.right_wall,
                           law.eps, tol, out, *scratch(n))
    if not done:
        return None
    first = n if chain.left_wall else n + 1  # Λ: L from the left wall's (or the first gap's)
    return CompiledImpactResult(problem, law, out, (n, first, first + st.m, 2 * n + 1),
                                RESIDUALS, tol, "isotonic", "velocity",
                                time.perf_counter() - start)
