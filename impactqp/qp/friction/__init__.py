"""Local frictional contact problems as the solver layer sees them (docs/theory.md §9, §15).

A friction program is any object with the arrays of u = W r + q, r_c ∈ K_μc ⟂ ũ_c ∈ K*_μc —
``W``, ``q``, ``mu``, ``contact_dim`` and ``n_contacts`` (:class:`FrictionProgram`; the
model's :class:`~impactqp.FrictionContactProblem` is one). The registry's entries of form
``"friction"`` solve it (:mod:`impactqp.qp.backends`) and return a :class:`FrictionSolution`;
the caller's certificate decides, as for every other program.
"""

from __future__ import annotations

from typing import NamedTuple, Protocol

import numpy as np


class FrictionProgram(Protocol):
    """What a friction backend reads of a local frictional contact problem."""

    W: object
    q: np.ndarray
    mu: np.ndarray
    contact_dim: int
    n_contacts: int


class FrictionSolution(NamedTuple):
    """A friction backend's answer.

    Attributes
    ----------
    r : ndarray
        The reaction, projected onto the friction cones.
    iterations : int
        Sweeps, cone programs and Newton steps done.
    backend : str
        The registry name of the method (a name :func:`impactqp.solve_friction` accepts).
    polish_steps : int
        Most Newton steps that may finish this answer when it is not yet within the
        tolerance (0: the method ran Newton itself, or is Newton).
    """

    r: np.ndarray
    iterations: int
    backend: str
    polish_steps: int = 0
