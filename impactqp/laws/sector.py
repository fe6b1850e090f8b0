"""The sector law as an impact law on a chain problem: ``u⁺ = sort(u⁻)`` (docs/theory.md §6).

The sector law is not a complementarity law ``0 ≤ Λ ⟂ γ⁺ + Eγ⁻``, so its certificate has
residuals of its own: the impact equation, Λ ≥ 0, γ⁺ ≥ 0, energy conservation and agreement
of γ⁺ with the closed-form γ-map of docs/theory.md §6.
"""

from __future__ import annotations

import numpy as np

from ..base.checks import DEFAULT_TOL
from ..base.rowwise import row_max, row_min
from ..derivatives.sort import SortMap
from ..errors import SectorLawError
from ..model.builders import require_chain
from ..model.problem import ImpactProblem
from ..model.residuals import impact_residuals, kinetic_norms, normalized_rows
from ..model.structure import ImpactStructure
from ..tables.coxeter import contact_angles, coxeter_labels
from ..tables.sector_table import sector_gamma_map, sector_velocity_map
from .base import Answer, ImpactLaw
from .certificate import Certificate

MASS_RTOL = 1e-12
"""Relative spread of the ball masses below which they count as equal."""

SECTOR_RESIDUALS = ("momentum", "impulse_sign", "energy_balance", "kinematic", "law_residual")
"""The residuals of :func:`sector_residuals` (the sector and reflection laws)."""


def sector_residuals(structure: ImpactStructure, U_minus: np.ndarray, U_plus: np.ndarray,
                     Lam: np.ndarray, expected: np.ndarray | None = None,
                     ) -> dict[str, np.ndarray]:
    """The sector law's residuals for one impact or for rows of impacts: momentum, Λ ≥ 0,
    ``kinematic`` (γ⁺ ≥ 0), ``energy_balance`` (|‖u⁺‖² − ‖u⁻‖²| / V²) and ``law_residual``
    (max |γ⁺ − S(γ⁻)| / V with S the closed-form map of docs/theory.md §6).

    ``expected`` is the γ⁺ the law must reproduce (default: the sector map of γ⁻,
    docs/theory.md §6).
    """
    st = structure
    if expected is None:
        expected = sector_gamma_map(st.Wt_times(U_minus)) if st.m else U_minus[..., :0]
    U_minus, U_plus, Lam, expected = normalized_rows(U_minus, U_plus, Lam, expected)
    V, out = impact_residuals(st, U_minus, U_plus, Lam)
    out["energy_balance"] = np.abs(kinetic_norms(st, U_plus) ** 2
                                   - kinetic_norms(st, U_minus) ** 2) / V**2
    if st.m == 0:  # a single ball: nothing to check at contacts
        out["kinematic"] = out["law_residual"] = np.zeros(U_minus.shape[:-1])
        return out
    gamma_plus = st.Wt_times(U_plus)
    out["kinematic"] = np.maximum(0.0, -row_min(gamma_plus / (st.contact_scale * V[..., None])))
    out["law_residual"] = row_max(np.abs(gamma_plus - expected)) / V
    return out


def certify_sector(problem: ImpactProblem, u_plus: np.ndarray, impulses: np.ndarray,
                   *, tol: float = DEFAULT_TOL) -> Certificate:
    """Recompute the checks of a sector-law answer (u⁺, Λ) on a chain problem."""
    return Certificate(sector_residuals(problem.structure, problem.u_minus, u_plus, impulses),
                       tol, names=SECTOR_RESIDUALS)



def wedge_angles(masses: np.ndarray) -> np.ndarray:
    """Angle (degrees) of T_C between neighbouring contacts i, i+1 in the kinetic metric:
    arccos(−G_{i,i+1}/√(G_ii G_{i+1,i+1})), 60° for equal masses (docs/theory.md §1, §5)."""
    inv = 1.0 / masses
    diag = inv[:-1] + inv[1:]
    cos = inv[1:-1] / np.sqrt(diag[:-1] * diag[1:])
    return np.degrees(np.arccos(cos))


def _wedge_note(problem: ImpactProblem) -> str:
    """Why: a simultaneous impact is a billiard in the wedge T_C, whose corner outcome is
    continuous in u⁻ only when the wedge angle is π/k; when it is, name reflection_law."""
    if problem.n_contacts < 2:
        return " impactqp.reflection_law gives the elastic law of any two balls."
    radians = contact_angles(problem.delassus)
    angles = ", ".join(f"{a:.4g}°" for a in np.degrees(radians)[:5])
    if None not in coxeter_labels(radians):
        return (f" Every angle of T_C here is 180°/k ({angles}): impactqp.reflection_law "
                "gives the continuous elastic law of these masses by reflections.")
    return (f" A simultaneous impact is a billiard in the wedge T_C; its outcome at the corner "
            f"is continuous only if every wedge angle is 180°/k (here {angles}); "
            "impactqp.reflection_law reports the masses that would make it so.")


def check_sector_problem(problem: ImpactProblem) -> float:
    """Return the common ball mass of ``problem`` or raise :class:`SectorLawError` saying why
    the sector law does not apply."""
    info = require_chain(problem, "sector law")
    if info.left_wall or info.right_wall:
        raise SectorLawError("the sector law is defined for free chains; walls are not "
                             "supported (a wall is a ball of infinite mass, see unequal masses;"
                             " impactqp.reflection_law handles one wall)")
    masses = info.masses
    if np.ptp(masses) > MASS_RTOL * masses.max():
        raise SectorLawError(
            f"the sector law needs equal masses, got {masses[:6].tolist()}"
            f"{' …' if masses.size > 6 else ''}: only for equal masses does an elastic "
            "collision swap velocities, so there is no continuous sorting law for unequal "
            f"masses.{_wedge_note(problem)}")
    return float(masses[0])


def sector_answer(mass: float, U_minus: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(u⁺, Λ) of the sector law for one u⁻ or every row: u⁺ = sort(u⁻) and
    Λ_k = m Σ_{j≤k} (u⁻_j − u⁺_j), the impulses of M(u⁺ − u⁻) = WΛ for the chain's W."""
    u_plus = sector_velocity_map(U_minus)
    return u_plus, mass * np.cumsum(U_minus - u_plus, axis=-1)[..., :-1]


class SectorLaw(ImpactLaw):
    """The maximal-monotone sector law of Winandy and Leine for a free chain of equal balls
    (docs/theory.md §6).

    .. math::

        u^+ = \\operatorname{sort}(u^-), \\qquad
        \\Lambda_k = m \\sum_{j \\le k} (u^-_j - u^+_j)

    (the impulses solve M(u⁺ − u⁻) = WΛ for the chain's W). Any number of balls, any u⁻
    (also kinematically inconsistent ones: u⁺ ∈ S always); O(n log n), no program.
    """

    name = "sector"
    by_name = True
    title = "the sector law"
    closed_form_backend = "sort"
    always_solvable = True
    homogeneous = True
    residual_names = SECTOR_RESIDUALS

    def check(self, problem: ImpactProblem) -> None:
        check_sector_problem(problem)

    def closed_form(self, problem: ImpactProblem) -> Answer:
        return Answer(*sector_answer(check_sector_problem(problem), problem.u_minus))

    def closed_form_rows(self, problem: ImpactProblem,
                         U_minus: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        return sector_answer(check_sector_problem(problem), U_minus)

    def derivative(self, problem: ImpactProblem, answer: object, *,
                   kink_tol: float) -> SortMap:
        """The sorting permutation, and at ties the sorts of the tied blocks
        (docs/theory.md §19); differentiable in u⁻ only (the law is defined on chains of
        equal masses)."""
        return SortMap(check_sector_problem(problem), problem.u_minus, kink_tol=kink_tol)

    def residuals(self, structure: ImpactStructure, U_minus: np.ndarray, U_plus: np.ndarray,
                  impulses: np.ndarray) -> dict[str, np.ndarray]:
        return sector_residuals(structure, U_minus, U_plus, impulses)

