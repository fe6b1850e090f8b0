"""Local Newton and Frémond's matrix law: ``0 ≤ Λ ⟂ γ⁺ + Eγ⁻ ≥ 0`` with E = diag(eᵢ) or a full
matrix, the LCP with q = (I + E)γ⁻ (docs/theory.md §3).

Unlike Moreau's law their u⁺ may leave S (kinetic energy can grow) and, for some E, the LCP
has no solution; the result's certificate checks the law, ``result.admissible`` the physics.
"""

from __future__ import annotations

from abc import abstractmethod
from typing import Any

import numpy as np

from ..base.arrays import as_array
from ..derivatives.complementarity import (
    ComplementarityMap,
    Parameter,
    diagonal,
    full_matrix,
    scalar_times_identity,
)
from ..errors import RestitutionError, ShapeError
from ..kernels.residuals import RESIDUALS
from ..model.problem import ImpactProblem
from ..model.programs import impulse_program
from ..model.structure import ImpactStructure
from ..qp.program import QPSolution, QuadraticProgram
from .base import COMPLEMENTARITY_FAMILY, Answer, ImpactLaw
from .certificate import law_residuals


def check_restitution(name: str, value: Any, m: int, *, matrix: bool = False) -> np.ndarray:
    """Validate local coefficients eᵢ (a scalar for all, or an m-vector, each in [0, 1]) or
    Frémond's E (a finite (m, m) matrix)."""
    arr = as_array(name, value, allow_nonfinite=not matrix)
    if matrix:
        if arr.shape != (m, m):
            raise ShapeError(f"{name} must be an ({m}, {m}) matrix, got shape {arr.shape}")
        return arr
    if arr.ndim == 0:
        arr = np.full(m, float(arr))
    elif arr.shape != (m,):
        raise ShapeError(f"{name} must be a scalar or have shape ({m},), got {arr.shape}")
    if not np.all((arr >= 0) & (arr <= 1)):  # NaN fails too
        raise RestitutionError(f"{name} must lie in [0, 1] (and not be NaN), got {value!r}")
    return arr


class _ComplementarityLaw(ImpactLaw):
    """``0 ≤ Λ ⟂ GΛ + (I + E)γ⁻ ≥ 0``, solved in impulse form."""

    forms = ("impulse",)
    homogeneous = True
    residual_names = RESIDUALS[:4]

    @abstractmethod
    def restitution(self, m: int) -> np.ndarray:
        """The law's E for m contacts: an (m,) diagonal or an (m, m) matrix
        (docs/theory.md §3)."""

    def program(self, problem: ImpactProblem, form: str) -> QuadraticProgram:
        E, g = self.restitution(problem.n_contacts), problem.gamma_minus
        return impulse_program(problem, g + (E * g if E.ndim == 1 else E @ g))

    def recover(self, problem: ImpactProblem, form: str, solution: QPSolution) -> Answer:
        lam = solution.x
        return Answer(problem.u_minus + problem.structure.impulse_velocity(lam), lam)

    @abstractmethod
    def parameter(self, m: int) -> Parameter:
        """The law's coefficients as the differentiable parameter of its E (docs/theory.md
        §18)."""

    def derivative(self, problem: ImpactProblem, answer: Any, *,
                   kink_tol: float) -> ComplementarityMap:
        """The LCP's local map, differentiable in u⁻, M, W and the law's coefficients
        (docs/theory.md §18–§19)."""
        return ComplementarityMap.at(problem, answer.impulses,
                                     self.parameter(problem.n_contacts), kink_tol=kink_tol)

    def linear_terms(self, problem: ImpactProblem, U_minus: np.ndarray,
                     form: str) -> np.ndarray:
        E, G = self.restitution(problem.n_contacts), problem.structure.Wt_times(U_minus)
        return G + (E * G if E.ndim == 1 else G @ E.T)

    def recover_rows(self, problem: ImpactProblem, form: str, U_minus: np.ndarray,
                     X: np.ndarray, Y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        return U_minus + problem.structure.impulse_velocity(X), X

    def residuals(self, structure: ImpactStructure, U_minus: np.ndarray, U_plus: np.ndarray,
                  impulses: np.ndarray) -> dict[str, np.ndarray]:
        return law_residuals(structure, U_minus, U_plus, impulses, self.restitution(structure.m))



class Newton(_ComplementarityLaw):
    """Local Newton law: ``0 ≤ Λᵢ ⟂ γ⁺ᵢ + eᵢγ⁻ᵢ ≥ 0`` for every closed contact.

    Parameters
    ----------
    e : float or (m,) array_like
        One restitution coefficient per contact (a scalar applies to all), each in [0, 1].

    Raises
    ------
    RestitutionError, ShapeError
        A coefficient outside [0, 1], or a vector whose length is not the number of
        contacts of the problem it is applied to.
    """

    name = "newton"
    title = "the local Newton law"
    by_name = True
    coefficient_key = "e"
    coefficient_symbol = "e"
    needs_coefficients = True
    family = COMPLEMENTARITY_FAMILY
    restitution_per_contact = True

    def __init__(self, e: Any = 1.0) -> None:
        arr = as_array("e", e, allow_nonfinite=True)
        if arr.ndim > 1:
            raise ShapeError(f"e must be a scalar or a vector, got shape {arr.shape}")
        self.e = check_restitution("e", arr, arr.size if arr.ndim else 1)
        self._scalar = arr.ndim == 0

    @property
    def coefficients(self) -> np.ndarray:
        return self.e

    def restitution(self, m: int) -> np.ndarray:
        return np.full(m, self.e[0]) if self._scalar else self.e

    def parameter(self, m: int) -> Parameter:
        return scalar_times_identity("e", self.e[0], m) if self._scalar else \
            diagonal("e", self.e)

    def coefficients_for(self, problem: ImpactProblem) -> np.ndarray:
        return self.restitution(problem.n_contacts)

    def check(self, problem: ImpactProblem) -> None:
        if not self._scalar:
            check_restitution("e", self.e, problem.n_contacts)

    def restrict(self, contacts: np.ndarray) -> Newton:
        return self if self._scalar else Newton(self.e[contacts])

    def step_restitution(self, contacts: np.ndarray) -> float | np.ndarray:
        e = self.e if self._scalar else self.e[contacts]
        return float(e[0]) if np.all(e == e[0]) else e


class Fremond(_ComplementarityLaw):
    """Frémond's law with an (m, m) matrix of impact coefficients:
    ``0 ≤ Λᵢ ⟂ γ⁺ᵢ + Σⱼ Eᵢⱼ γ⁻ⱼ ≥ 0``.

    Parameters
    ----------
    E : (m, m) array_like
        Finite matrix of impact coefficients.

    Raises
    ------
    ShapeError, NonFiniteError
        E is not a finite square matrix, or its size is not the problem's number of contacts.
    """

    name = "fremond"
    title = "Frémond's law"
    by_name = True
    coefficient_key = "E"
    coefficient_symbol = "E"
    needs_coefficients = True
    family = COMPLEMENTARITY_FAMILY

    def __init__(self, E: Any) -> None:
        arr = as_array("E", E)
        if arr.ndim != 2 or arr.shape[0] != arr.shape[1]:
            raise ShapeError(f"E must be a square (m, m) matrix, got shape {arr.shape}")
        self.E = arr

    @property
    def coefficients(self) -> np.ndarray:
        return self.E

    def restitution(self, m: int) -> np.ndarray:
        return self.E

    def parameter(self, m: int) -> Parameter:
        return full_matrix("E", self.E)

    def check(self, problem: ImpactProblem) -> None:
        check_restitution("E", self.E, problem.n_contacts, matrix=True)

    def restrict(self, contacts: np.ndarray) -> Fremond:
        return Fremond(self.E[np.ix_(contacts, contacts)])

    def step_restitution(self, contacts: np.ndarray) -> np.ndarray:
        return self.E[np.ix_(contacts, contacts)]
