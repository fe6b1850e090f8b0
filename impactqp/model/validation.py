"""Checks of an impact's M and W that come before any solve (docs/theory.md §1): the contact
dimension, a symmetric M, and that floats can hold the Delassus matrix G = WᵀM⁻¹W every law
is posed on.

Floats hold G when its entries lie among the normal floats [:data:`TINY`, :data:`HUGE`]: M in
a unit so small that M⁻¹ overflows (M = 10⁻³²⁰·I, a subnormal, keeps three digits at most),
or W so large against M that G does (M = 10⁻³⁰⁰·I with W = 10⁵), or so small that G falls
among the subnormals and Λ = G⁻¹(…) overflows, cannot be posed; such a problem is refused by
name (:class:`~impactqp.errors.OutOfRangeError`) rather than handed to solvers that would
fail in their own words. u⁺ does not change when M is multiplied by a constant, so a user
restates M (or W) in another unit.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import scipy.sparse as sp

from ..base.arrays import Matrix, as_count
from ..errors import InputError, MassMatrixError, OutOfRangeError

TINY = float(np.finfo(float).tiny)
"""The smallest normal float (2.2e-308): below it a number keeps fewer than 53 bits."""

HUGE = float(np.finfo(float).max)
"""The largest float (1.8e308)."""

RESTATE = "state M and W in units nearer one (u⁺ does not change when M is multiplied by a " \
          "constant)"


def check_contact_dim(value: object, chain: object | None) -> int:
    """``contact_dim`` as an int in {1, 2, 3}, or InputError (also for a frictional chain)."""
    d = as_count("contact_dim", value)
    if d not in (1, 2, 3):
        raise InputError(f"contact_dim must be 1 (frictionless), 2 (planar friction) or 3 "
                         f"(spatial friction), got {d}")
    if chain is not None and d != 1:
        raise InputError("a chain's contacts are frictionless: contact_dim must be 1")
    return d


def check_mass(M: Matrix, sparse: bool) -> None:
    """M symmetric (to 10⁻¹² of its largest entry) with no diagonal entry among the
    subnormals.

    Raises
    ------
    MassMatrixError
        M is not symmetric.
    OutOfRangeError
        A positive diagonal entry below :data:`TINY`: M⁻¹ and G are beyond the floats.
    """
    scale = abs(M).max() if sparse else np.abs(M).max()
    asym = abs(M - M.T).max() if sparse else np.abs(M - M.T).max()
    if asym > 1e-12 * max(scale, 1e-300):
        raise MassMatrixError(f"M must be symmetric; max |M - Mᵀ| = {asym:.3g} "
                              f"(largest entry {scale:.3g})")
    diagonal = np.asarray(M.diagonal() if sp.issparse(M) else np.diagonal(M), dtype=float)
    if diagonal.min(initial=TINY) >= TINY:  # the common case, decided in one reduction
        return
    small = diagonal[(diagonal > 0) & (diagonal < TINY)]
    if small.size:
        raise OutOfRangeError(f"M's diagonal reaches {small.min():.3g}, below the normal floats "
                              f"({TINY:.3g}): M⁻¹ and the Delassus matrix G = WᵀM⁻¹W are "
                              f"beyond them; {RESTATE}")


def _refuse(what: str) -> OutOfRangeError:
    return OutOfRangeError(f"the Delassus matrix G = WᵀM⁻¹W is beyond the floats ({what}; "
                           f"normal floats lie in [{TINY:.3g}, {HUGE:.3g}]): {RESTATE}")


def check_delassus_diagonal(diagonal: Callable[[], np.ndarray]) -> None:
    """G's diagonal (computed by ``diagonal()``, under-/overflow allowed) finite and at
    least :data:`TINY` (each column of W is non-zero, so each Gⱼⱼ > 0 in exact arithmetic).

    Raises
    ------
    OutOfRangeError
        An entry that overflows or falls below the normal floats.
    """
    with np.errstate(over="ignore", under="ignore", invalid="ignore"):
        g = diagonal()
    if g.size and not (g.min() >= TINY and g.max() <= HUGE):  # NaN fails both
        raise _refuse(f"its diagonal spans [{g.min():.3g}, {g.max():.3g}]")


def check_pivots(pivots: np.ndarray) -> None:
    """The pivots of a sparse M's LDLᵀ (positive) within [:data:`TINY`, :data:`HUGE`], so that
    M⁻¹ can be applied without leaving the floats (a sparse non-diagonal M, whose G is not
    formed before a solve needs it).

    Raises
    ------
    OutOfRangeError
        A pivot among the subnormals (M⁻¹ overflows).
    """
    low = float(np.min(pivots, initial=1.0))
    if not low >= TINY:
        raise _refuse(f"M's pivots reach {low:.3g}")


def check_chain_masses(lo: float, hi: float) -> None:
    """A chain's masses (with at least one contact) within [:data:`TINY`, 1/:data:`TINY`]:
    its G holds 1/mᵢ + 1/mᵢ₊₁ (1/m at a wall), which leaves the normal floats outside.

    Raises
    ------
    OutOfRangeError
        A mass outside that range.
    """
    if not TINY <= lo <= hi <= 1.0 / TINY:
        raise OutOfRangeError(f"masses span [{lo:.3g}, {hi:.3g}]: beyond [{TINY:.3g}, "
                              f"{1.0 / TINY:.3g}] the Delassus matrix G (1/mᵢ + 1/mᵢ₊₁) leaves "
                              "the normal floats; state the masses in another unit (u⁺ does "
                              "not change when every mass is multiplied by a constant)")
