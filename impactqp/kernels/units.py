"""The unit of each contact: the one definition every frictional problem is posed in
(docs/theory.md §16).

A contact's unit is s_c = √W_nn, the normal velocity one unit of its normal impulse makes.
Rows of contact c scaled by 1/s_c (W̃ = D W D, q̃ = D q, r̃ = D⁻¹ r with D = diag(1/s)) give
an equivalent problem — the friction cones are invariant under a positive scaling of a whole
contact — whose normal diagonal is one whatever the unit of mass or the length of W's columns.
"""

from __future__ import annotations

import numpy as np

from .jit import kernel


@kernel(interpretable=True)
def contact_units(diagonal: np.ndarray, d: int) -> np.ndarray:
    """Per-entry units sᵢ = s_c of the contact c of entry i, from W's diagonal.

    s_c = √W_nn where W_nn > 0 is finite. A contact whose W_nn is not (its normal impulse
    moves nothing, or W is corrupt) takes the largest √W_ii of its own block, and where that
    is not positive either the geometric mean of the other contacts' units (1 when no
    contact has one): a unit of the problem's own scale, never an absolute 1 that would
    depend on the unit of mass.

    Parameters
    ----------
    diagonal : (d·m,) ndarray
        The diagonal of W.
    d : int
        Entries per contact (1, 2 or 3).

    Returns
    -------
    (d·m,) ndarray
        s_c repeated over the d entries of each contact.
    """
    m = diagonal.size // d
    unit = np.zeros(m)
    log_sum = 0.0
    count = 0
    for c in range(m):
        w = diagonal[c * d]
        if not (w > 0.0 and w < np.inf):
            w = 0.0
            for k in range(1, d):
                x = diagonal[c * d + k]
                if x > w and x < np.inf:
                    w = x
        if w > 0.0:
            unit[c] = np.sqrt(w)
            log_sum += np.log(unit[c])
            count += 1
    fallback = np.exp(log_sum / count) if count > 0 else 1.0
    out = np.empty(m * d)
    for c in range(m):
        s = unit[c] if unit[c] > 0.0 else fallback
        for k in range(d):
            out[c * d + k] = s
    return out
