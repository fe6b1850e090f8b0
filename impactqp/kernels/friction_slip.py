"""One 3-D contact's local problem solved sliding, by the root of its slip function
(docs/theory.md §15): the case the closed forms of
:func:`impactqp.kernels.friction_blocks.exact_contact` leave open, solved to round-off in the
sweeps of a problem of a few contacts (:func:`impactqp.kernels.friction_sweep.sweep_once`).
"""

from __future__ import annotations

import math

from .jit import inline_kernel, kernel

SLIP_SAMPLES = 16
"""Slip angles at which :func:`sliding_3d` looks for a sign change of its function (it has at
most four roots; two closer than 2π/16 are missed, and the sweeps then solve the contact)."""
SLIP_STEPS = 60
"""Most steps of the bracketing root search of :func:`sliding_3d`."""
SLIP_WARM = 6
"""Most Newton steps :func:`sliding_from` takes from a contact's last slip angle (from a
sweep to the next the angle moves little, and Newton's steps gain digits quadratically:
Rover4396's sweeps converge in 2 to 4)."""
SLIP_RESOLUTION = 1e-13
"""A Newton step of :func:`_root` shorter than this (radians) ends it, that step taken: at a
simple root the error after a step is about its square, far below the floats' resolution
(a shorter bound lets round-off in G push the steps out of the bracket, into bisections)."""


@inline_kernel
def _slip_terms(Wc, base, mu):
    """The coefficients of the slip function of :func:`sliding_3d` (docs/theory.md §15):
    with c = cos θ, s = sin θ, a·u_t = (t₁, t₂), t₁ = p₀ + p₁c + p₂s, t₂ = q₀ + q₁c + q₂s
    (a·u_t = a·b_t − b_n(W_tn − μW_tt e), a = W_nn − μ(W_n1 c + W_n2 s)), so that
    G = c t₂ − s t₁ = g₀ + g₁c + g₂s + g₃cos 2θ + g₄sin 2θ, with g₀ = (q₁ − p₂)/2, g₁ = q₀,
    g₂ = −p₀, g₃ = (q₁ + p₂)/2, g₄ = (q₂ − p₁)/2. Returns ((g₀, …, g₄), (p₀, p₁, p₂, q₀, q₁,
    q₂))."""
    p0 = Wc[0, 0] * base[1] - base[0] * Wc[1, 0]
    p1 = -mu * (Wc[0, 1] * base[1] - base[0] * Wc[1, 1])
    p2 = -mu * (Wc[0, 2] * base[1] - base[0] * Wc[1, 2])
    q0 = Wc[0, 0] * base[2] - base[0] * Wc[2, 0]
    q1 = -mu * (Wc[0, 1] * base[2] - base[0] * Wc[2, 1])
    q2 = -mu * (Wc[0, 2] * base[2] - base[0] * Wc[2, 2])
    g = (0.5 * (q1 - p2), q0, -p0, 0.5 * (q1 + p2), 0.5 * (q2 - p1))
    return g, (p0, p1, p2, q0, q1, q2)


@inline_kernel
def _slip_at(g, c, s):
    """G at the angle of cosine ``c`` and sine ``s``, and its derivative dG/dθ, from the
    coefficients ``g`` of :func:`_slip_terms`."""
    c2, s2 = c * c - s * s, 2.0 * c * s
    value = g[0] + g[1] * c + g[2] * s + g[3] * c2 + g[4] * s2
    slope = g[2] * c - g[1] * s + 2.0 * (g[4] * c2 - g[3] * s2)
    return value, slope


@inline_kernel
def _root(g, lo, hi, g_lo, g_hi):
    """A root of G in [lo, hi], where it changes sign (G = ``g_lo``, ``g_hi`` there), by
    Newton's method from the secant's root, kept inside the bracket (a step leaving it
    bisects), until a step is within :data:`SLIP_RESOLUTION`."""
    theta = lo + (hi - lo) * g_lo / (g_lo - g_hi)
    if not lo < theta < hi:
        theta = 0.5 * (lo + hi)
    for _ in range(SLIP_STEPS):
        value, slope = _slip_at(g, math.cos(theta), math.sin(theta))
        if value == 0.0:
            return theta
        if (value < 0.0) == (g_lo < 0.0):
            lo, g_lo = theta, value
        else:
            hi = theta
        step = value / slope if slope != 0.0 else math.inf
        new = theta - step
        if abs(step) <= SLIP_RESOLUTION:
            return new
        if not lo < new < hi:
            new = 0.5 * (lo + hi)
            if not lo < new < hi:
                return theta
        theta = new
    return theta


@inline_kernel
def _valid_at(Wc, mu, terms, c, s):
    """(a, e·u_t·a) at the angle of cosine ``c`` and sine ``s`` (``terms`` the (p, q) of
    :func:`_slip_terms`): where both are positive at a root of G, that root is the slip."""
    p0, p1, p2, q0, q1, q2 = terms
    slope = Wc[0, 0] - mu * (Wc[0, 1] * c + Wc[0, 2] * s)
    return slope, c * (p0 + p1 * c + p2 * s) + s * (q0 + q1 * c + q2 * s)


@kernel
def sliding_3d(Wc, base, mu, out):
    """A 3-D contact's local problem u = W_cc r + b solved sliding, where it slides
    (docs/theory.md §15): r = r_n(1, −μ cos θ, −μ sin θ) with u_n = 0, so
    r_n = −b_n/a(θ), a(θ) = W_nn − μ(W_n1 cos θ + W_n2 sin θ), and u_t parallel to
    e = (cos θ, sin θ) with e·u_t > 0: a root of G(θ) = e × (a·u_t), a trigonometric
    polynomial of degree 2 (at most four roots, its coefficients by :func:`_slip_terms`),
    bracketed by a sign change among :data:`SLIP_SAMPLES` angles (their cosines and sines by
    rotation, no sine computed) and refined by :func:`_root`, the brackets where a and
    e·u_t·a are positive at an end first, then the others. The first root found with a > 0
    and e·u_t > 0 is written into ``out[0:3]``. Returns False (``out`` untouched) where
    b_n ≥ 0 or no such root is found (a double root, or no sliding solution)."""
    if not base[0] < 0.0 or not mu > 0.0:
        return False
    g, terms = _slip_terms(Wc, base, mu)
    step = 2.0 * math.pi / SLIP_SAMPLES
    turn_c, turn_s = math.cos(step), math.sin(step)
    for likely in (True, False):
        c, s = 1.0, 0.0
        g_lo, _ = _slip_at(g, c, s)
        slope_lo, along_lo = _valid_at(Wc, mu, terms, c, s)
        for k in range(1, SLIP_SAMPLES + 1):
            c, s = c * turn_c - s * turn_s, s * turn_c + c * turn_s
            g_hi, _ = _slip_at(g, c, s)
            slope_hi, along_hi = _valid_at(Wc, mu, terms, c, s)
            signs = g_lo == 0.0 or (g_lo < 0.0) != (g_hi < 0.0)
            if signs and likely == ((slope_lo > 0.0 or slope_hi > 0.0)
                                    and (along_lo > 0.0 or along_hi > 0.0)):
                lo = (k - 1) * step
                theta = lo if g_lo == 0.0 else _root(g, lo, k * step, g_lo, g_hi)
                if _slip_answer(Wc, base, mu, terms, theta, out):
                    return True
            g_lo, slope_lo, along_lo = g_hi, slope_hi, along_hi
    return False


@inline_kernel
def _slip_answer(Wc, base, mu, terms, theta, out):
    """Where a > 0 and e·u_t·a > 0 at the root ``theta`` of G (:func:`_valid_at`), the
    sliding answer r = r_n(1, −μ cos θ, −μ sin θ), r_n = −b_n/a, into ``out[0:3]``.
    Returns whether it was written."""
    ct, st = math.cos(theta), math.sin(theta)
    slope, along = _valid_at(Wc, mu, terms, ct, st)
    if not (slope > 0.0 and along > 0.0):
        return False
    rn = -base[0] / slope
    out[0] = rn
    out[1] = -mu * rn * ct
    out[2] = -mu * rn * st
    return True


@inline_kernel
def sliding_from(Wc, base, mu, last_1, last_2, out):
    """The sliding answer of :func:`sliding_3d` sought first from the contact's last
    tangential reaction (``last_1``, ``last_2``), as the sweeps hold it: Newton's method on
    G from the angle of −r_t, at most :data:`SLIP_WARM` steps, kept where a step falls within
    :data:`SLIP_RESOLUTION` and the root is the slip (a > 0, e·u_t > 0; the local problem's
    solution where W_cc is definite). Returns False (``out`` untouched) otherwise, and where
    b_n ≥ 0 or r_t = 0: :func:`sliding_3d` then searches all angles."""
    if not base[0] < 0.0 or not mu > 0.0 or (last_1 == 0.0 and last_2 == 0.0):
        return False
    g, terms = _slip_terms(Wc, base, mu)
    theta = math.atan2(-last_2, -last_1)
    for _ in range(SLIP_WARM):
        value, slope = _slip_at(g, math.cos(theta), math.sin(theta))
        if value == 0.0:
            return _slip_answer(Wc, base, mu, terms, theta, out)
        if slope == 0.0:
            return False
        step = value / slope
        theta -= step
        if abs(step) <= SLIP_RESOLUTION:
            return _slip_answer(Wc, base, mu, terms, theta, out)
    return False


__all__ = ["SLIP_RESOLUTION", "SLIP_SAMPLES", "SLIP_STEPS", "SLIP_WARM", "sliding_3d",
           "sliding_from"]
