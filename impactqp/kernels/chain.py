"""Moreau's projection on a 1-D chain in O(N): weighted isotonic regression and anchored
impulses in compiled code (docs/theory.md §3, §5).

For a chain of N balls (masses m, contacts [left wall, gaps 1..N−1, right wall]) the
M-projection z of u⁻ onto T_C is the weighted isotonic regression of u⁻ (z₁ ≤ … ≤ z_N),
clipped at 0 on a wall side (both walls: z = 0). :func:`project` computes it by pooling
adjacent violators on a stack of blocks (each block a run of equal z, its value the
weighted mean of u⁻ over the run), then the impulses: with dⱼ = mⱼ(zⱼ − u⁻ⱼ) and L_j the
impulse left of ball j, M(z − u⁻) = WΛ reads L_j − L_{j+1} = dⱼ. Over a block Σ d = 0, so
the contact before each block start carries none (L = 0 there, an anchor) and L is a running
sum from the anchor; clipped blocks hang from the first free block start. Running sums are
compensated (Neumaier), so their rounding does not grow with the length of a block.

:func:`solve_chain` is one impact of Moreau's law in one compiled call: the projection, u⁺
and Λ, then the chain certificate recomputed from them in a pass of its own
(:func:`impactqp.kernels.residuals.chain_residuals`, docs/theory.md §8).
"""

from __future__ import annotations

import numpy as np

from .jit import inline_kernel, kernel
from .residuals import RESIDUALS, chain_residuals


@kernel(internal=True)
def _add(total, compensation, x):
    """Neumaier's compensated sum: (total + x, updated compensation)."""
    t = total + x
    if abs(total) >= abs(x):
        compensation += (total - t) + x
    else:
        compensation += (x - t) + total
    return t, compensation


@kernel(internal=True)
def _pava(m, u, starts, weight, total):
    """Blocks of the weighted isotonic regression of u: returns their count nb, with
    ``starts[:nb + 1]`` (a last entry N), block weights and weighted sums.

    The top block of the stack and the one being pushed live in registers, the blocks
    below in the arrays: a long run of pooling (one block growing ball by ball) then costs
    a comparison and two additions per ball, without a store and a reload of the top."""
    n = u.size
    if n == 0:
        starts[0] = 0
        return 0
    nb = 0  # blocks below the top one
    ts, tw, tt = 0, m[0], m[0] * u[0]
    for j in range(1, n):
        cs, cw, ct = j, m[j], m[j] * u[j]
        while True:
            if not tt * cw > ct * tw:  # the top's mean is at most the new block's: push
                starts[nb] = ts
                weight[nb] = tw
                total[nb] = tt
                nb += 1
                break
            cs, cw, ct = ts, tw + cw, tt + ct  # pool the new block into the top
            if nb == 0:
                break
            nb -= 1
            ts, tw, tt = starts[nb], weight[nb], total[nb]
        ts, tw, tt = cs, cw, ct
    starts[nb] = ts
    weight[nb] = tw
    total[nb] = tt
    starts[nb + 1] = n
    return nb + 1


@inline_kernel
def _fill(m, u, z, L, a, b, mean, anchored):
    """z = mean on balls a … b − 1 and, when ``anchored``, L_{j+1} = L_j − dⱼ from L_a = 0
    (dⱼ = mⱼ(zⱼ − u⁻ⱼ), one pass over the block's balls)."""
    if not anchored:
        for j in range(a, b):
            z[j] = mean
        return
    s, c = 0.0, 0.0
    L[a] = 0.0
    for j in range(a, b):
        z[j] = mean
        s, c = _add(s, c, -m[j] * (mean - u[j]))
        L[j + 1] = s + c


@inline_kernel
def _forward(m, u, z, L, a, b):
    """L_{j+1} = L_j − dⱼ for j = a … b − 1, from L_a = 0 (anchored at a)."""
    s, c = 0.0, 0.0
    L[a] = 0.0
    for j in range(a, b):
        s, c = _add(s, c, -m[j] * (z[j] - u[j]))
        L[j + 1] = s + c


@kernel(interpretable=True)
def project(m, u, left, right, z, L, starts, weight):
    """z = prox_{T_C}(u⁻) and the impulses L (N + 1 entries: L_j left of ball j, L_0 and L_N
    the walls' impulses, 0 where there is no wall) of one chain, into ``z`` and ``L``.

    ``starts`` (N + 1 integers) and ``weight`` (N floats) are scratch for the blocks (a long
    chain's caller keeps them between solves: fresh pages cost more than the regression);
    the blocks' weighted sums live in ``L`` until the impulses are written. Each free block
    is filled and given its impulses in one pass."""
    n = u.size
    total = L[:n]
    nb = _pava(m, u, starts, weight, total)
    free = 0  # blocks whose mean is at most 0 (a wall clips them or the others)
    for b in range(nb):  # the means replace the weights: the impulses overwrite the sums
        weight[b] = total[b] / weight[b]
        if weight[b] <= 0.0:
            free = b + 1
    first = free if left else 0
    last = free if right else nb
    for b in range(nb):  # each block filled, the free ones anchored at their own start
        mean = weight[b]
        if left and right:
            mean = 0.0
        elif left:
            mean = max(mean, 0.0)
        elif right:
            mean = min(mean, 0.0)
        _fill(m, u, z, L, starts[b], starts[b + 1], mean,
              first <= b < last and not (left and right))
    if left and right:  # z = 0: the least impulses, L = max_j E_j − E_j with E_0 = 0
        s, c, top = 0.0, 0.0, 0.0
        L[0] = 0.0
        for j in range(n):
            s, c = _add(s, c, m[j] * (z[j] - u[j]))
            L[j + 1] = s + c
            top = max(top, L[j + 1])
        for j in range(n + 1):
            L[j] = top - L[j]
        return
    L[0] = 0.0
    if left:  # the wall and the clipped blocks hang from the first free block start k
        k = starts[free]
        s, c = 0.0, 0.0
        L[k] = 0.0
        for j in range(k - 1, -1, -1):
            s, c = _add(s, c, m[j] * (z[j] - u[j]))
            L[j] = s + c
    if right:  # the clipped blocks and the wall hang from the first clipped block start
        _forward(m, u, z, L, starts[free], n)
    else:
        L[n] = 0.0


@kernel
def project_rows(m, U, left, right):
    """:func:`project` for every row of U: (Z (k × N), L (k × (N + 1)))."""
    k, n = U.shape
    Z = np.empty((k, n))
    L = np.empty((k, n + 1))
    starts = np.empty(n + 1, dtype=np.int64)
    weight = np.empty(n)
    for r in range(k):
        project(m, U[r], left, right, Z[r], L[r], starts, weight)
    return Z, L


def pack_chain(masses: np.ndarray, inverse: np.ndarray, scale: np.ndarray) -> np.ndarray:
    """The masses mⱼ, their inverses 1/mⱼ and the contact scales sᵢ of a chain in one flat
    array: the one operand of :func:`solve_chain` that describes the structure."""
    return np.concatenate((masses, inverse, scale)).astype(float)


@kernel(interpretable=True)
def solve_chain(packed, um, left, right, eps, tol, out, starts, weight):
    """Moreau's impact with restitution ε on one chain (docs/theory.md §3, §5), certified.

    Parameters
    ----------
    packed : float array
        :func:`pack_chain` of the chain (N masses, N inverses, m contact scales).
    um : (N,) float array
        u⁻.
    left, right : bool
        Walls.
    eps, tol : float
        Restitution and the certificate's tolerance.
    out : (2N + 7,) float array
        Receives u⁺ (N), the impulses L_j left of each ball j (N + 1: Λ is
        ``L[0 if left else 1:][:m]``) and the residuals (order of
        :data:`impactqp.kernels.residuals.RESIDUALS`).
    starts, weight : int (N + 1,) and float (N,) arrays
        Scratch of :func:`project` (a long chain's caller keeps them between solves).

    Returns
    -------
    bool
        Whether every residual is within ``tol`` (NaN fails).

    u⁺ = z − εz⊥ and Λ = (1 + ε)Λ_z as the velocity program's recovery forms them; the
    certificate then reads u⁺ and Λ back from memory in a pass of its own.
    """
    return _solve_chain_into(packed, um, left, right, eps, tol, out, starts, weight)


@kernel(interpretable=True)
def solve_short_chain(packed, um, left, right, eps, tol, out):
    """:func:`solve_chain` with its scratch allocated by the call: for short chains, whose
    scratch costs less to allocate than to pass (each array argument adds to the call)."""
    n = um.size
    return _solve_chain_into(packed, um, left, right, eps, tol, out,
                             np.empty(n + 1, dtype=np.int64), np.empty(n))


@inline_kernel
def _solve_chain_into(packed, um, left, right, eps, tol, out, starts, weight):
    """The body of :func:`solve_chain`."""
    n = um.size
    m = packed.size - 2 * n
    masses = packed[:n]
    up = out[:n]
    L = out[n:2 * n + 1]
    project(masses, um, left, right, up, L, starts, weight)
    if eps != 0.0:
        for j in range(n):  # u⁺ = z − ε(u⁻ − z)
            up[j] = (up[j] - um[j]) * eps + up[j]
        for j in range(n + 1):
            L[j] = (1.0 + eps) * L[j]
    lo = 0 if left else 1
    res = out[2 * n + 1:2 * n + 1 + len(RESIDUALS)]
    chain_residuals(um, up, L[lo:lo + m], masses, packed[n:2 * n], packed[2 * n:], left, right,
                    eps, eps, np.bool_(True), res)  # a run-time flag: one signature
    for i in range(res.size):
        if not res[i] <= tol:
            return False
    return True
