"""Single dense impacts in compiled code: the pipeline's first fast path (docs/theory.md §8, §9).

For a dense impact of a law of a compiled family (``law.family``: Moreau's law, local Newton,
Frémond's law, or a user's law that declares the family), the whole solve — γ⁻, the
impulse-form LCP by the compiled active-set search, u⁺ and every residual of the law's
certificate — runs in one call of :func:`impactqp.kernels.impact.solve_impact`, which says
whether every residual is within the tolerance. An answer that misses it is not returned:
the pipeline goes on to the general path (QP backends, polishing).
"""

from __future__ import annotations

import time
import weakref
from functools import partial

import numpy as np

from ..kernels.impact import solve_impact
from ..kernels.residuals import RESIDUALS
from ..model.problem import ImpactProblem
from ..model.residuals import restitution_matrix
from .base import FAMILIES, MOREAU_FAMILY, ImpactLaw
from .certificate import Certificate
from .result import ImpactResult

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


def applies(problem: ImpactProblem, law: ImpactLaw, backend: str, form: str) -> bool:
    """Whether the compiled path may answer (it may still decline after trying)."""
    st = problem.structure
    return (backend in ("auto", "kernel") and form in ("auto", "impulse") and not st.sparse
            and 0 < st.m <= (MAX_CONTACTS if st.chain is None else SHORT_CHAIN)
            and st.n <= MAX_DOF
            and law.family in FAMILIES)


def _certificate(names: tuple[str, ...], values: np.ndarray, tol: float) -> Certificate:
    """The certificate of residuals the kernel already checked, built when first read; it
    declares the compiled family's residuals (Moreau's two more read as None otherwise)."""
    return Certificate(dict(zip(names, values.tolist())), tol, names=RESIDUALS)


def solve_small(problem: ImpactProblem, law: ImpactLaw, tol: float,
                start: float) -> ImpactResult | None:
    """The certified result by the compiled path, or None to go on to the general path."""
    st = problem.structure
    moreau = law.family == MOREAU_FAMILY
    eps = law.eps if moreau else 0.0
    n, m = st.n, st.m
    out = np.empty(n + m + 6)
    if not solve_impact(st.kernel_pack, problem.u_minus, restitution_for(law, m), eps, moreau,
                        tol, st.warm_support, out):
        return None
    up = out[:n]
    names = RESIDUALS if moreau else RESIDUALS[:4]
    return ImpactResult(problem, law.name, law.coefficients_for(problem), up, out[n:n + m],
                        "kernel", partial(_certificate, names, out[n + m:], tol), form="impulse",
                        z=partial(law.projection, problem, up) if moreau else None,
                        attempts=["kernel (compiled): certified"], impact_law=law,
                        solve_time=time.perf_counter() - start)
