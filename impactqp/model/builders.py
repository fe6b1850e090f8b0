"""Builders of impact problems: chains, Newton's cradle (docs/theory.md §5) and random
reference impacts."""

from __future__ import annotations

from typing import Any

import numpy as np
import scipy.sparse as sp

from ..base.arrays import as_array, as_count, as_flag, as_real
from ..errors import InputError, SectorLawError
from ..kernels.nnls import solve_nnls
from .chain_structure import ChainStructure, chain_directions
from .problem import ImpactProblem
from .structure import ChainInfo

__all__ = ["chain", "chain_directions", "newtons_cradle", "random_impact", "recognize_chain",
           "require_chain"]


def chain(masses: Any, u_minus: Any, *, left_wall: bool = False, right_wall: bool = False,
          sparse: bool | None = None) -> ImpactProblem:
    """A 1-D chain of balls with every neighbour contact closed.

    Parameters
    ----------
    masses : (N,) array_like
        Positive ball masses.
    u_minus : (N,) array_like
        Pre-impact velocities of the balls.
    left_wall, right_wall : bool
        Fixed walls touching the first / last ball.
    sparse : bool, optional
        Store M and W as scipy.sparse (default: when N > 200). Either way they are formed
        only when something asks for them: the chain's own operators, the isotonic backend
        and the chain certificate are O(N) without them (docs/theory.md §5).

    Returns
    -------
    ImpactProblem
        With ``problem.chain`` set, which the O(N) fast paths recognise.

    Raises
    ------
    ShapeError, NonFiniteError, InputError
        Masses that are not a non-empty 1-D array of positive finite numbers (a
        non-positive mass raises MassMatrixError, an InputError), u⁻ of another shape or
        not finite, walls that are not flags.
    """
    masses = as_array("masses", masses)
    left_wall, right_wall = as_flag("left_wall", left_wall), as_flag("right_wall", right_wall)
    sparse = masses.size > 200 if sparse is None else as_flag("sparse", sparse)
    info = ChainInfo(masses=masses, left_wall=left_wall, right_wall=right_wall)
    return ImpactProblem.from_structure(ChainStructure(info, sparse=sparse), u_minus)


def newtons_cradle(n_balls: int = 3, v: float = 1.0, mass: float = 1.0,
                   released: int = 1) -> ImpactProblem:
    """Newton's cradle: ``released`` balls moving at ``v`` hit the resting others
    (docs/theory.md §5).

    Parameters
    ----------
    n_balls : int
        Number of equal balls, at least 2.
    v : float
        Speed of the released balls.
    mass : float
        Mass of every ball, positive.
    released : int
        How many balls (from the left) move at ``v``; 1 ≤ released < n_balls.

    Returns
    -------
    ImpactProblem
        A chain of equal masses without walls (``problem.chain`` set).

    Raises
    ------
    InputError
        For counts that are not whole numbers in range, or a non-finite ``v`` or ``mass``.
    """
    n_balls = as_count("n_balls", n_balls, minimum=2)
    released = as_count("released", released, minimum=1)
    if released >= n_balls:
        raise InputError(f"released must be an integer in [1, n_balls - 1] = [1, {n_balls - 1}], "
                         f"got {released!r}")
    v = as_real("v", v)
    mass = as_real("mass", mass, positive=True)
    u = np.zeros(n_balls)
    u[:released] = v
    return chain(np.full(n_balls, float(mass)), u)


def random_impact(n_dof: int, n_contacts: int, *, seed: int | np.random.Generator = 0,
                  redundant: int = 0, consistent: bool = True,
                  condition: float = 10.0) -> ImpactProblem:
    """A random dense impact for tests and benchmarks.

    Parameters
    ----------
    n_dof, n_contacts : int
        Sizes n and m.
    seed : int or numpy.random.Generator
        Reproducibility.
    redundant : int
        How many of the m columns of W are copies or non-negative combinations of the others
        (a singular Delassus matrix).
    consistent : bool
        When True, u⁻ approaches every contact (γ⁻ ≤ 0); otherwise γ⁻ has both signs.
    condition : float
        Condition number of the random SPD mass matrix, ≥ 1.

    Returns
    -------
    ImpactProblem

    Raises
    ------
    InputError
        Sizes that are not whole numbers, ``redundant`` not below ``n_contacts``, a
        condition number below 1, a seed numpy cannot use.
    """
    n_dof = as_count("n_dof", n_dof, minimum=1)
    n_contacts = as_count("n_contacts", n_contacts)
    redundant = as_count("redundant", redundant)
    if n_contacts and redundant >= n_contacts:
        raise InputError(f"redundant must be below n_contacts = {n_contacts}, got {redundant}")
    condition = as_real("condition", condition, low=1.0)
    consistent = as_flag("consistent", consistent)
    try:
        rng = np.random.default_rng(seed)
    except (TypeError, ValueError) as exc:
        raise InputError(f"seed must be an integer or a numpy Generator: {exc}") from None
    Q, _ = np.linalg.qr(rng.standard_normal((n_dof, n_dof)))
    M = Q @ np.diag(np.geomspace(1.0, condition, n_dof)) @ Q.T
    M = 0.5 * (M + M.T)
    base = n_contacts - redundant
    W = rng.standard_normal((n_dof, n_contacts))
    for j in range(base, n_contacts):
        if rng.random() < 0.5:
            W[:, j] = W[:, rng.integers(base)]
        else:
            W[:, j] = W[:, :base] @ rng.random(base)
    u = rng.standard_normal(n_dof)
    if consistent:
        # −(Euclidean projection of a random point onto T_C) satisfies γ⁻ = Wᵀu ≤ 0; the
        # projection is x + Wλ with λ = argmin_{λ≥0} ‖Wλ + x‖ (non-negative least squares).
        x = u
        lam, _ = solve_nnls(W, -x)
        u = -(x + W @ lam)
        if np.linalg.norm(u) < 1e-12 * np.linalg.norm(x):  # T_C = {0}: no motion is consistent
            u = np.zeros(n_dof)
    return ImpactProblem(M, W, u)


def recognize_chain(problem: ImpactProblem) -> ChainInfo | None:
    """The ChainInfo of a problem that is a 1-D chain by its M and W however it was built
    (docs/theory.md §5): M diagonal and W exactly the chain's columns for some walls; None
    otherwise."""
    if problem.chain is not None:
        return problem.chain
    st = problem.structure
    n, m = st.n, st.m
    M = sp.csr_matrix(st.M)
    masses = M.diagonal()
    if (M - sp.diags(masses)).count_nonzero() or not np.all(masses > 0):
        return None
    W = sp.csc_matrix(st.W)
    for left in (False, True):
        right = m - (n - 1) - left
        if right in (0, 1) and n >= 1 and \
                not (W - chain_directions(n, left_wall=left, right_wall=bool(right),
                                          sparse=True)).count_nonzero():
            return ChainInfo(masses=np.array(masses, dtype=float), left_wall=left,
                             right_wall=bool(right))
    return None


def require_chain(problem: ImpactProblem, law: str) -> ChainInfo:
    """The ChainInfo of ``problem`` (built as a chain, or recognized as one from its M and
    W), or an error saying that ``law`` needs a 1-D chain."""
    if not isinstance(problem, ImpactProblem):
        raise InputError(f"problem must be an ImpactProblem, got {type(problem).__name__}")
    info = recognize_chain(problem)
    if info is None:
        raise SectorLawError(f"the {law} is defined for 1-D chains of balls: M diagonal and W "
                             "the chain's contact directions [left wall e₁, neighbour gaps "
                             "e_{i+1} − e_i, right wall −e_N] (impactqp.chain builds one)")
    return info
