"""The derivative of a Moreau–Jean run, chained through its steps (docs/theory.md §21).

A step maps (q_k, v_k) and the law's parameters p to (q_{k+1}, v_{k+1}); its tangent is

    dv_free = F_q dq + F_v dv,
    dΛ = T (H_Cᵀ dv_free) + T E_CC (H_Cᵀ dv) + T R dp        (closed contacts C, T the
                                                               LCP tangent of the step),
    dv' = dv_free + Ŵ⁻¹H_C dΛ,    dq' = dq + h((1 − θ)dv + θ dv'),

with F_q = −hŴ⁻¹K, F_v = I − h²θŴ⁻¹K for a linear force c − Kq (F_q = 0, F_v = I for a
constant one). :func:`forward` carries k tangent directions through every step (the
sensitivities at every step); :func:`adjoint` runs the transposed chain backwards, the
cotangent of a loss on the states giving the cotangents of the initial state and of p.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from .jit import inline_kernel, kernel


class StepMaps(NamedTuple):
    """The parts of a step's tangent that every step shares.

    Attributes
    ----------
    Fq, Fv : (n, n) float arrays
        ∂v_free/∂q and ∂v_free/∂v (read only with ``linear``).
    linear : bool
        The force is c − Kq (else F_q = 0 and F_v = I).
    h, theta : float
    MinvH : (n, m) float array
        Ŵ⁻¹H on the normal columns.
    Ht : (m, n) float array
        H_nᵀ, dense.
    """

    Fq: np.ndarray
    Fv: np.ndarray
    linear: bool
    h: float
    theta: float
    MinvH: np.ndarray
    Ht: np.ndarray


class StepTangents(NamedTuple):
    """The steps whose LCP tangent is not zero, in order, each padded to the widest.

    Attributes
    ----------
    steps : (s,) int array
        Step numbers k (ascending).
    sizes : (s,) int array
        |C|, the closed contacts of each step.
    contacts : (s, c) int array
        C of each step in its first |C| entries.
    Ta, Tb : (s, c, c) float arrays
        T and T E_CC of each step (the leading |C| × |C| block).
    Tp : (s, c, p) float array
        T R of each step: the LCP's right-hand side's derivative in the law's parameters.
    pcols : (p,) int array
        The tangent columns of the law's parameters.
    """

    steps: np.ndarray
    sizes: np.ndarray
    contacts: np.ndarray
    Ta: np.ndarray
    Tb: np.ndarray
    Tp: np.ndarray
    pcols: np.ndarray


@inline_kernel
def _put(out, step, S):
    """``out[step] = S`` by loops: a slice copy compiles numba's shape errors."""
    for a in range(S.shape[0]):
        for c in range(S.shape[1]):
            out[step, a, c] = S[a, c]


@kernel
def forward(maps, tangents, S0, out):
    """The tangents after every step into ``out`` ((steps + 1, 2n, k), ``out[0] = S0``) for
    the run's :class:`StepMaps` and :class:`StepTangents`."""
    Fq, Fv, linear, h, theta, MinvH, Ht = maps
    steps, sizes, contacts, Ta, Tb, Tp, pcols = tangents
    n = Fq.shape[0]
    k = S0.shape[1]
    p = pcols.size
    S = S0.copy()
    _put(out, 0, S)
    dvf = np.empty((n, k))
    dvn = np.empty((n, k))
    width = contacts.shape[1]
    ga = np.empty((width, k))
    gb = np.empty((width, k))
    y = np.empty(k)
    j = 0
    for step in range(out.shape[0] - 1):
        for a in range(n):
            for c in range(k):
                if linear:
                    total = 0.0
                    for b in range(n):
                        total += Fq[a, b] * S[b, c] + Fv[a, b] * S[n + b, c]
                    dvf[a, c] = total
                else:
                    dvf[a, c] = S[n + a, c]
        for a in range(dvf.shape[0]):  # loops: a slice copy compiles numba's shape errors
            for c in range(dvf.shape[1]):
                dvn[a, c] = dvf[a, c]
        if j < steps.size and steps[j] == step:
            size = sizes[j]
            for x in range(size):
                i = contacts[j, x]
                for c in range(k):
                    sa = 0.0
                    sb = 0.0
                    for b in range(n):
                        sa += Ht[i, b] * dvf[b, c]
                        sb += Ht[i, b] * S[n + b, c]
                    ga[x, c] = sa
                    gb[x, c] = sb
            for x in range(size):
                for c in range(k):
                    y[c] = 0.0
                    for z in range(size):
                        y[c] += Ta[j, x, z] * ga[z, c] + Tb[j, x, z] * gb[z, c]
                for r in range(p):
                    y[pcols[r]] += Tp[j, x, r]
                i = contacts[j, x]
                for a in range(n):
                    for c in range(k):
                        dvn[a, c] += MinvH[a, i] * y[c]
            j += 1
        for a in range(n):
            for c in range(k):
                S[a, c] += h * ((1.0 - theta) * S[n + a, c] + theta * dvn[a, c])
                S[n + a, c] = dvn[a, c]
        _put(out, step + 1, S)
    return out


@kernel
def adjoint(maps, tangents, cotangents):
    """(∂L/∂x₀, ∂L/∂p) of L with ∂L/∂x_r = ``cotangents[r]`` ((steps + 1, 2n)) by the
    transposed chain of :func:`forward`, from the last step back (p: the law's parameters,
    in the order of ``tangents.pcols``)."""
    Fq, Fv, linear, h, theta, MinvH, Ht = maps
    steps, sizes, contacts, Ta, Tb, Tp, pcols = tangents
    n = Fq.shape[0]
    n_params = pcols.size
    total_steps = cotangents.shape[0] - 1
    lam = cotangents[total_steps].copy()
    ap = np.zeros(n_params)
    advn = np.empty(n)
    advf = np.empty(n)
    width = contacts.shape[1]
    al = np.empty(width)
    j = steps.size - 1
    for step in range(total_steps - 1, -1, -1):
        aq = lam[:n].copy()
        av = lam[n:].copy()
        for a in range(n):
            advn[a] = av[a] + h * theta * aq[a]
            lam[n + a] = h * (1.0 - theta) * aq[a]  # ∂/∂v_k through q_{k+1}
            advf[a] = advn[a]
        if j >= 0 and steps[j] == step:
            size = sizes[j]
            for x in range(size):
                i = contacts[j, x]
                al[x] = 0.0
                for a in range(n):
                    al[x] += MinvH[a, i] * advn[a]
            for z in range(size):
                ta = 0.0
                tb = 0.0
                for x in range(size):
                    ta += Ta[j, x, z] * al[x]
                    tb += Tb[j, x, z] * al[x]
                i = contacts[j, z]
                for a in range(n):
                    advf[a] += Ht[i, a] * ta
                    lam[n + a] += Ht[i, a] * tb
            for x in range(size):
                for r in range(n_params):
                    ap[r] += Tp[j, x, r] * al[x]
            j -= 1
        for a in range(n):
            if linear:
                sq = 0.0
                sv = 0.0
                for b in range(n):
                    sq += Fq[b, a] * advf[b]
                    sv += Fv[b, a] * advf[b]
                lam[a] = aq[a] + sq
                lam[n + a] += sv
            else:
                lam[a] = aq[a]
                lam[n + a] += advf[a]
        for a in range(2 * n):
            lam[a] += cotangents[step, a]
    return lam, ap
