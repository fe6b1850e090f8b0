"""The ``"newton"`` and ``"newton-damped"`` backends: Alart–Curnier's semismooth Newton on
frictional contact problems from r = 0, with two shifts of its Jacobian (docs/theory.md §15;
:func:`impactqp.qp.friction.methods.newton_method`)."""

from __future__ import annotations

import numpy as np

from ..friction import FrictionSolution
from ..friction.methods import newton_method
from ..friction.newton import FrictionData


def solve_friction(data: FrictionData, start: np.ndarray | None, *, tol: float,
                   method: str) -> FrictionSolution:
    return newton_method(data, start, tol, method)
