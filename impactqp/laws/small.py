"""Single small impacts on Python floats: the pipeline's first fast path (docs/theory.md §8, §9).

For a dense impact with a few contacts, numpy's per-call overhead dwarfs the arithmetic. This
path runs a program compiled once per structure (:mod:`impactqp.laws.unrolled`): the
prepared active-set kernel's supports and every residual of the law's certificate
(docs/theory.md §8: momentum, Λ ≥ 0, law feasibility, complementarity and, for Moreau's law,
the energy balance and the duality gap) spelled out on Python floats, with the same formulas
as :func:`impactqp.model.residuals.law_residuals`, in the same units. An answer whose
residuals miss the tolerance is not returned: the pipeline goes on to the general path.
"""

from __future__ import annotations

import time
from functools import partial

import numpy as np

from ..model.problem import ImpactProblem
from ..model.structure import ImpactStructure
from ..qp.active_set import ActiveSetKernel
from ..qp.backends.kernel import prepared_for
from .base import ImpactLaw
from .certificate import Certificate
from .complementarity import Fremond, Newton
from .moreau import Moreau
from .result import ImpactResult
from .unrolled import program_for

SMALL_CONTACTS = 4
"""Most contacts the float path takes (its program spells out all 2^m − 1 supports: beyond,
compiling costs more than most structures are ever solved)."""

SMALL_DOF = 12
"""Most degrees of freedom the float path takes."""


_KINDS = {Moreau: "moreau", Newton: "newton", Fremond: "fremond"}
"""The laws the float path takes, by exact type (a subclass may change the law)."""


def applies(problem: ImpactProblem, law: ImpactLaw, backend: str, form: str) -> bool:
    """Whether the float path may answer (it may still decline after trying)."""
    st = problem.structure
    return (backend in ("auto", "kernel") and form in ("auto", "impulse") and not st.sparse
            and 0 < st.m <= SMALL_CONTACTS and st.n <= SMALL_DOF
            and type(law) in _KINDS)


def _coefficients(law: ImpactLaw, m: int) -> tuple[float, ...]:
    """The law's E as the compiled program takes it: (ε,), the eᵢ, or E row by row."""
    if type(law) is Moreau:
        return (law.eps,)
    if type(law) is Newton:
        return tuple(law.coefficients_for_size(m))
    return tuple(law.E.ravel().tolist())


def _kernel(st: ImpactStructure) -> ActiveSetKernel:
    return prepared_for(st, "impulse", st.delassus)


def solve_small(problem: ImpactProblem, law: ImpactLaw, tol: float,
                start: float) -> ImpactResult | None:
    """The certified result by the float path, or None to go on to the general path.

    The compiled program (:mod:`impactqp.laws.unrolled`) accepts only when every residual of
    the law's certificate is within ``tol``; the Certificate object itself is built from
    those residuals when it is first read.
    """
    st = problem.structure
    program = program_for(st, _KINDS[type(law)], _kernel)
    if program is None:  # not compiled yet for this structure
        return None
    out = program(problem.u_minus.tolist(), _coefficients(law, st.m), tol)
    if out is None:
        return None
    up, lam, z, res = out
    return ImpactResult(problem, law.name, law.coefficients_for(problem), np.array(up),
                        np.array(lam), "kernel", partial(Certificate, *res[:5], tol, res[5]),
                        form="impulse", z=z,
                        attempts=["kernel (impulse, on floats): certified"], impact_law=law,
                        solve_time=time.perf_counter() - start)
