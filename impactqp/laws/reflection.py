"""The reflection law: the elastic impact law of a chain whose contact angles are all π/k
(docs/theory.md §10).

Elastic collisions at violated contacts, one at a time, in any order, end at the same u⁺
when the angles of T_C are π/k (:mod:`impactqp.tables.reflection_group`); the law is
continuous, energy conserving and non-expansive, u⁺ ∈ S for every u⁻, and equals sort(u⁻)
for equal masses (the sector law).
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np

from ..model.builders import require_chain
from ..model.problem import ImpactProblem
from ..model.structure import ImpactStructure
from ..tables.reflection_group import (
    MAX_TABLE_ORDER,
    ReflectionGroup,
    check_reflection_problem,
    elastic_collisions,
)
from ..tables.reflection_table import reflection_law_table
from .base import Answer, ImpactLaw
from .certificate import Certificate
from .sector import SECTOR_RESIDUALS, sector_residuals


@lru_cache(maxsize=32)
def _table(masses: tuple[float, ...], left_wall: bool, right_wall: bool):
    return reflection_law_table(np.array(masses), left_wall=left_wall, right_wall=right_wall)


def _reference_gamma(problem: ImpactProblem, group: ReflectionGroup) -> np.ndarray:
    """γ⁺ by an independent route: the table map when the group is small, else the
    opposite collision order."""
    info = require_chain(problem, "reflection law")
    if group.order <= MAX_TABLE_ORDER:
        table = _table(tuple(info.masses.tolist()), info.left_wall, info.right_wall)
        return table.apply(problem.gamma_minus)
    return problem.structure.Wt_times(elastic_collisions(problem, "right")[0])


class ReflectionLaw(ImpactLaw):
    """The elastic impact law of a chain with contact angles π/k, by reflections.

    Applies to chains (``impactqp.chain``) with any masses whose every angle of T_C is π/k
    (see :func:`impactqp.tables.continuous_mass_ratios`), free or with one wall. Kinematically
    inconsistent u⁻ are fine: u⁺ ∈ S for every u⁻. The certificate's ``law_residual``
    compares γ⁺ with the table map (group order ≤ MAX_TABLE_ORDER) or, for larger groups,
    with the opposite collision order.
    """

    name = "reflection"
    by_name = True
    title = "the reflection law"
    closed_form_backend = "reflections"
    always_solvable = True
    homogeneous = True
    residual_names = SECTOR_RESIDUALS

    def check(self, problem: ImpactProblem) -> None:
        check_reflection_problem(problem)

    def closed_form(self, problem: ImpactProblem) -> Answer:
        check_reflection_problem(problem)
        u_plus, impulses, _ = elastic_collisions(problem, "left")
        return Answer(u_plus, impulses)

    def residuals(self, structure: ImpactStructure, U_minus: np.ndarray, U_plus: np.ndarray,
                  impulses: np.ndarray) -> dict[str, np.ndarray]:
        return sector_residuals(structure, U_minus, U_plus, impulses)

    def certificate(self, problem: ImpactProblem, answer: Answer, tol: float) -> Certificate:
        group = check_reflection_problem(problem)
        expected = _reference_gamma(problem, group) if problem.n_contacts else None
        res = sector_residuals(problem.structure, problem.u_minus, answer.u_plus,
                               answer.impulses, expected=expected)
        return Certificate(res, tol, names=self.residual_names)
