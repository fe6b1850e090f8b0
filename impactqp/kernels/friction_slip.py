"""One 3-D contact's local problem solved sliding, by the root of its slip function
(docs/theory.md §15): the case the closed forms of
:func:`impactqp.kernels.friction_blocks.exact_contact` leave to the projected fixed point,
solved to round-off for a problem of a single contact.
"""

from __future__ import annotations

import math

import numpy as np

from .friction import natural_map
from .jit import inline_kernel, kernel

SLIP_SAMPLES = 16
"""Slip angles at which :func:`sliding_3d` looks for a sign change of its function (it has at
most four roots; two closer than 2π/16 are missed, and the sweeps then solve the contact)."""
SLIP_STEPS = 60
"""Most steps of the bracketing root search of :func:`sliding_3d`."""


@kernel(internal=True)
def _slip(Wc, base, mu, theta):
    """The slip function of :func:`sliding_3d` at the angle ``theta``: (G, a, e·u_t·a) with
    a = W_nn − μ(W_n1 cos θ + W_n2 sin θ) and a·u_t = a·b_t − b_n(W_tn − μW_tt e)."""
    c, s = math.cos(theta), math.sin(theta)
    a = Wc[0, 0] - mu * (Wc[0, 1] * c + Wc[0, 2] * s)
    v1 = Wc[1, 0] - mu * (Wc[1, 1] * c + Wc[1, 2] * s)
    v2 = Wc[2, 0] - mu * (Wc[2, 1] * c + Wc[2, 2] * s)
    t1 = a * base[1] - base[0] * v1
    t2 = a * base[2] - base[0] * v2
    return c * t2 - s * t1, a, c * t1 + s * t2


@kernel(internal=True)
def _root(Wc, base, mu, a, b, g_a, g_b):
    """A root of the slip function in [a, b], where it changes sign, by regula falsi with
    the Illinois rule (the retained end's value halved), to the floats' resolution."""
    side = 0
    for _ in range(SLIP_STEPS):
        mid = (a * g_b - b * g_a) / (g_b - g_a)
        if not a < mid < b:
            mid = 0.5 * (a + b)
            if not a < mid < b:
                break
        g_mid, _, _ = _slip(Wc, base, mu, mid)
        if g_mid == 0.0:
            return mid
        if (g_mid < 0.0) == (g_a < 0.0):
            a, g_a = mid, g_mid
            if side == -1:
                g_b *= 0.5
            side = -1
        else:
            b, g_b = mid, g_mid
            if side == 1:
                g_a *= 0.5
            side = 1
    return a if abs(g_a) < abs(g_b) else b


@inline_kernel
def sliding_3d(Wc, base, mu, out):
    """A 3-D contact's local problem u = W_cc r + b solved sliding, where it slides
    (docs/theory.md §15): r = r_n(1, −μ cos θ, −μ sin θ) with u_n = 0, so
    r_n = −b_n/a(θ), a(θ) = W_nn − μ(W_n1 cos θ + W_n2 sin θ), and u_t parallel to
    e = (cos θ, sin θ) with e·u_t > 0: a root of G(θ) = e × (a·u_t), a trigonometric
    polynomial of degree 2 (at most four roots), bracketed by a sign change among
    :data:`SLIP_SAMPLES` angles (:func:`_root`). The first root with a > 0 and e·u_t > 0 is
    written into ``out[0:3]``. Returns False (``out`` untouched) where b_n ≥ 0 or no such
    root is found (a double root, or no sliding solution)."""
    if not base[0] < 0.0 or not mu > 0.0:
        return False
    step = 2.0 * math.pi / SLIP_SAMPLES
    lo = 0.0
    g_lo, _, _ = _slip(Wc, base, mu, lo)
    for k in range(1, SLIP_SAMPLES + 1):
        hi = k * step
        g_hi, _, _ = _slip(Wc, base, mu, hi)
        if g_lo == 0.0 or (g_lo < 0.0) != (g_hi < 0.0):
            theta = lo if g_lo == 0.0 else _root(Wc, base, mu, lo, hi, g_lo, g_hi)
            _, slope, along = _slip(Wc, base, mu, theta)
            if slope > 0.0 and along > 0.0:
                rn = -base[0] / slope
                out[0] = rn
                out[1] = -mu * rn * math.cos(theta)
                out[2] = -mu * rn * math.sin(theta)
                return True
        lo, g_lo = hi, g_hi
    return False


@inline_kernel(interpretable=True)
def sliding_alone(indptr, indices, data, q, mu, r, err):
    """A problem of one 3-D contact, W by its compressed rows, solved sliding
    (:func:`sliding_3d`, b = q) into ``r`` where that answer's ‖F‖/‖q‖ is below ``err``
    (that of the answer in ``r``, otherwise kept). Returns the ‖F‖/‖q‖ of ``r``."""
    Wc = np.zeros((3, 3))
    for i in range(3):
        for p in range(indptr[i], indptr[i + 1]):
            Wc[i, indices[p]] += data[p]
    rc = np.empty(3)
    if not sliding_3d(Wc, q, mu[0], rc):
        return err
    uc = np.empty(3)
    for i in range(3):
        uc[i] = q[i] + Wc[i, 0] * rc[0] + Wc[i, 1] * rc[1] + Wc[i, 2] * rc[2]
    F = natural_map(rc, uc, mu, rc.size)  # a size, not the literal 3: one signature
    qn = np.sqrt(np.sum(q * q))
    found = np.sqrt(np.sum(F * F)) / (qn if qn > 0.0 else 1.0)
    if not found < err:
        return err
    for i in range(3):
        r[i] = rc[i]
    return found


__all__ = ["SLIP_SAMPLES", "SLIP_STEPS", "sliding_3d", "sliding_alone"]
