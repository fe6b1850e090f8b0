"""The state of every contact at every record of a run (docs/theory.md §14, §17): open,
or closed — and, with friction, sticking or sliding — read from the recorded impulses and
velocities.

A contact is closed at a record when its normal impulse Λₙ of the step (or impact) ending
there is positive; with friction (``contact_dim`` > 1) a closed contact sticks when its
tangential velocity Hₜᵀv at that record vanishes and slides otherwise. "Positive" and
"vanishes" are decided relative to the run's own scales: the largest normal impulse and the
largest contact velocity of the whole run, times ``tol``.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ..base.arrays import check_tol

FRICTIONLESS_STATES = ("open", "closed")
"""State names of frictionless contacts, by code."""

FRICTION_STATES = ("open", "stick", "slide")
"""State names of frictional contacts, by code."""

STATE_TOL = 1e-6
"""Default relative threshold of :func:`contact_states`."""


def contact_states(trajectory: Any, tol: float = STATE_TOL) -> tuple[np.ndarray, tuple[str, ...]]:
    """The state code of each contact at each record, and the names of the codes.

    Parameters
    ----------
    trajectory : Trajectory
    tol : float
        Relative threshold: a normal impulse counts as positive above ``tol`` times the
        run's largest normal impulse, a tangential velocity as non-zero above ``tol`` times
        the run's largest contact velocity.

    Returns
    -------
    codes : (k, m) ndarray of int
        Index into ``names`` per record and contact.
    names : tuple of str
        ``FRICTIONLESS_STATES`` or ``FRICTION_STATES``.
    """
    tol = check_tol(tol)
    system = trajectory.system
    d, m = system.contact_dim, system.n_contacts
    impulses = np.asarray(trajectory.impulses, dtype=float).reshape(len(trajectory.t), d * m)
    normal = impulses[:, ::d]
    closed = normal > tol * max(float(np.abs(normal).max(initial=0.0)), 1e-300)
    if d == 1:
        return closed.astype(int), FRICTIONLESS_STATES
    contact_v = np.asarray(system.H.T @ np.asarray(trajectory.v).T).T  # (k, d·m)
    scale = max(float(np.abs(contact_v).max(initial=0.0)), 1e-300)
    tangential = np.linalg.norm(contact_v.reshape(-1, m, d)[:, :, 1:], axis=2)
    sliding = tangential > tol * scale
    return np.where(closed, np.where(sliding, 2, 1), 0), FRICTION_STATES
