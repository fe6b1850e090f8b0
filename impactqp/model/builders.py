"""Builders of impact problems: chains, Newton's cradle (docs/theory.md §5) and random
reference impacts."""

from __future__ import annotations

from typing import Any

import numpy as np
import scipy.sparse as sp
from scipy.optimize import nnls

from ..base.arrays import as_array, as_count, as_flag, as_real
from ..errors import InputError, SectorLawError, ShapeError
from .problem import ImpactProblem
from .structure import ChainInfo, ImpactStructure


def chain_directions(n_balls: int, *, left_wall: bool = False, right_wall: bool = False,
                     sparse: bool = False):
    """W of a 1-D chain: column order [left wall, gaps q₂−q₁ … q_N−q_{N−1}, right wall].

    A neighbour gap gᵢ = q_{i+1} − q_i has direction e_{i+1} − e_i; a left wall at rest
    (gap q₁ − wall) has e₁, a right wall (gap wall − q_N) has −e_N.
    """
    n = n_balls
    gaps = np.arange(n - 1)
    first = 1 if left_wall else 0
    m = first + n - 1 + (1 if right_wall else 0)
    rows = [gaps, gaps + 1]
    cols = [gaps + first, gaps + first]
    vals = [np.full(n - 1, -1.0), np.ones(n - 1)]
    for present, row, col, val in ((left_wall, 0, 0, 1.0), (right_wall, n - 1, m - 1, -1.0)):
        if present:
            rows.append(np.array([row]))
            cols.append(np.array([col]))
            vals.append(np.array([val]))
    rows, cols, vals = np.concatenate(rows), np.concatenate(cols), np.concatenate(vals)
    if sparse:
        return sp.csc_matrix((vals, (rows, cols)), shape=(n, m))
    W = np.zeros((n, m))
    W[rows, cols] = vals
    return W


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
        Store M and W as scipy.sparse (default: when N > 200).

    Returns
    -------
    ImpactProblem
        With ``problem.chain`` set, which the O(N) fast paths recognise.
    """
    masses = as_array("masses", masses)
    if masses.ndim != 1 or masses.size == 0:
        raise ShapeError(f"masses must be a non-empty 1-D array, got shape {masses.shape}")
    left_wall, right_wall = as_flag("left_wall", left_wall), as_flag("right_wall", right_wall)
    if sparse is not None:
        sparse = as_flag("sparse", sparse)
    if np.any(masses <= 0):
        raise InputError(f"masses must be positive; got {masses[masses <= 0][:5].tolist()}")
    n = masses.size
    if n == 1 and not (left_wall or right_wall):
        W = np.zeros((1, 0))
    else:
        W = None
    sparse = n > 200 if sparse is None else sparse
    if W is None:
        W = chain_directions(n, left_wall=left_wall, right_wall=right_wall, sparse=sparse)
    M = sp.diags(masses, format="csc") if sparse else np.diag(masses)
    info = ChainInfo(masses=masses.copy(), left_wall=left_wall, right_wall=right_wall)
    return ImpactProblem.from_structure(ImpactStructure(M, W, chain=info), u_minus)


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
        lam, _ = nnls(W, -x)
        u = -(x + W @ lam)
        if np.linalg.norm(u) < 1e-12 * np.linalg.norm(x):  # T_C = {0}: no motion is consistent
            u = np.zeros(n_dof)
    return ImpactProblem(M, W, u)


def require_chain(problem: ImpactProblem, law: str) -> ChainInfo:
    """The ChainInfo of ``problem``, or an error saying that ``law`` needs a 1-D chain."""
    if not isinstance(problem, ImpactProblem):
        raise InputError(f"problem must be an ImpactProblem, got {type(problem).__name__}")
    if problem.chain is None:
        raise SectorLawError(f"the {law} is defined for 1-D chains of balls; build the "
                             "problem with impactqp.chain or impactqp.newtons_cradle")
    return problem.chain
