"""The ``"newton-lstsq"`` backend: the least-squares Newton on the natural map of a
frictional contact problem, dense, for rank-deficient W (docs/theory.md §15;
:func:`impactqp.qp.friction.newton.lstsq_newton`)."""

from __future__ import annotations

import numpy as np

from ..friction import FrictionProgram, FrictionSolution
from ..friction.methods import newton_method
from ..friction.newton import LSTSQ_MAX, FrictionData


def unsuitable_friction(program: FrictionProgram) -> str | None:
    n = program.q.size
    if n > LSTSQ_MAX:
        return (f"'newton-lstsq' takes at most {LSTSQ_MAX} unknowns d·m (a dense QR per step), "
                f"got {n}; 'newton' and 'newton-damped' take any size")
    return None


def solve_friction(data: FrictionData, start: np.ndarray | None, *, tol: float,
                   method: str) -> FrictionSolution:
    return newton_method(data, start, tol, method)
