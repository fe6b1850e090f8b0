"""The ``"nsgs-short"`` and ``"nsgs"`` backends: the compiled projected Gauss–Seidel over the
contacts of a frictional contact problem, on the compressed rows of W (docs/theory.md §15;
:func:`impactqp.qp.friction.methods.gauss_seidel`)."""

from __future__ import annotations

import numpy as np

from ..friction import FrictionSolution
from ..friction.methods import gauss_seidel
from ..friction.newton import FrictionData


def solve_friction(data: FrictionData, start: np.ndarray | None, *, tol: float,
                   method: str) -> FrictionSolution:
    return gauss_seidel(data, start, tol, method)
