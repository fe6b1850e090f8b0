"""The ``"newton-repair"`` backend: Alart–Curnier's Newton with local repairs of the
contacts where it stalls, from the best answer so far (docs/theory.md §22;
:func:`impactqp.qp.friction.repair.repaired_newton`)."""

from __future__ import annotations

import numpy as np

from ..friction import FrictionSolution
from ..friction.newton import FrictionData
from ..friction.repair import repaired_newton


def solve_friction(data: FrictionData, start: np.ndarray | None, *, tol: float,
                   method: str) -> FrictionSolution:
    return repaired_newton(data, start, tol)
