"""The two programs of an impact (docs/theory.md §3, §9), which the complementarity laws
emit and the projection onto T_C solves.

* velocity form: ``min ½‖v − u⁻‖²_M  s.t.  Wᵀv ≥ 0`` (z = prox_{T_C}(u⁻), Moreau's law);
* impulse form: ``min ½ΛᵀGΛ + qᵀΛ  s.t.  Λ ≥ 0`` (the LCP ``0 ≤ Λ ⟂ GΛ + q ≥ 0``).

Both take an ImpactProblem (anything with ``structure``, ``u_minus`` and ``chain``).
Programs of one structure share their owner and tag, so backends that prepare or compile
(the kernel, cvxpy) do it once per structure.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ..qp.program import ChainProgram, ChainShape, QuadraticProgram


def impulse_program(problem: Any, q: np.ndarray,
                    moreau_scale: float | None = None) -> QuadraticProgram:
    """Impulse form min ½ΛᵀGΛ + qᵀΛ, Λ ≥ 0, with the factor B = L⁻¹W when dense.

    For Moreau's law (q = (1+ε)γ⁻, ``moreau_scale`` = 1+ε) q = Bᵀd with d = (1+ε)Lᵀu⁻,
    which lets the NNLS backend work without refactorizing.
    """
    st = problem.structure
    if st.sparse:
        return QuadraticProgram(P=st.delassus, c=q, cache_owner=st, cache_tag="impulse")
    d = None if moreau_scale is None else moreau_scale * (st.cholesky_factor.T @ problem.u_minus)
    return QuadraticProgram(P=st.delassus, c=q, factor=st.scaled_W, factor_rhs=d,
                            cache_owner=st, cache_tag="impulse")


def velocity_program(problem: Any) -> QuadraticProgram:
    """Velocity form min ½‖v − u⁻‖²_M s.t. Wᵀv ≥ 0: its solution is z = prox_{T_C}(u⁻)
    and its multipliers are the impulses Λ_z of M(z − u⁻) = WΛ_z. A chain's program is a
    :class:`~impactqp.qp.program.ChainProgram`: its matrices are the structure's, formed only
    if a backend other than the isotonic one asks for them (docs/theory.md §5)."""
    st = problem.structure
    c = problem.chain
    if c is not None:
        shape = ChainShape(c.masses, c.left_wall, c.right_wall, center=problem.u_minus)
        return ChainProgram(shape, lambda: (st.M, st.contact_rows), sparse=st.sparse,
                            cache_owner=st, cache_tag="velocity")
    return QuadraticProgram(P=st.M, c=-st.mass_rows(problem.u_minus), A=st.contact_rows,
                            b=np.zeros(st.m), cache_owner=st, cache_tag="velocity")


SMALL_CHAIN = 10
"""Chains with at most this many contacts prefer the impulse form (the prepared kernel)."""


def preferred_forms(problem: Any) -> tuple[str, str]:
    """The two forms, best first: the velocity form for sparse problems and long chains
    (well posed for any W, and the isotonic path), the impulse form otherwise (smaller when
    m < n, and the kernel's and exact enumeration's shape: an impact that closes every
    contact is their first candidate there, their last in velocity form)."""
    st = problem.structure
    long_chain = problem.chain is not None and st.m > SMALL_CHAIN
    return ("velocity", "impulse") if st.sparse or long_chain else ("impulse", "velocity")
