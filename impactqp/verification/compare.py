"""Rigid laws and the dispersive LZB model side by side on one impact (docs/theory.md §3, §6,
§13): Moreau's law at ε = 0 and ε = 1, the sector law (equal masses), and LZB, each with its
post-impact velocities, kinetic energy ratio and the exact verdict whether u⁺ lies in S
(docs/theory.md §2).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..base.checks import DEFAULT_TOL
from ..errors import InputError, SectorLawError
from ..laws.lzb import DEFAULT_RTOL, LZB
from ..laws.moreau import Moreau
from ..laws.pipeline import solve
from ..laws.planner import check_law, check_problem
from ..laws.result import ImpactResult
from ..laws.sector import SectorLaw
from ..model.admissible import Membership
from ..model.physical_chains import PhysicalChain
from ..model.problem import ImpactProblem


@dataclass(frozen=True)
class LawOutcome:
    """One law's answer on the compared impact.

    Attributes
    ----------
    law : str
        Label, e.g. ``"Moreau ε = 0"``.
    result : ImpactResult or None
        The certified result; None when the law does not apply (``note`` says why).
    membership : Membership or None
        Exact test u⁺ ∈ S with its residuals.
    note : str
    """

    law: str
    result: ImpactResult | None
    membership: Membership | None
    note: str = ""

    @property
    def u_plus(self) -> np.ndarray | None:
        return None if self.result is None else self.result.u_plus

    @property
    def in_S(self) -> bool | None:
        """u⁺ ∈ S (None when the law does not apply)."""
        return None if self.membership is None else bool(self.membership)

    @property
    def energy_ratio(self) -> float:
        """T(u⁺)/T(u⁻) (NaN when the law does not apply or u⁻ = 0)."""
        if self.result is None or self.result.energy_before == 0:
            return float("nan")
        return self.result.energy_after / self.result.energy_before


@dataclass(frozen=True)
class LawComparison:
    """Moreau (ε = 0, 1), the sector law and LZB on one impact.

    Attributes
    ----------
    problem : ImpactProblem
    outcomes : tuple of LawOutcome
        In the order Moreau ε = 0, Moreau ε = 1, sector law, LZB.
    """

    problem: ImpactProblem
    outcomes: tuple[LawOutcome, ...] = field(default_factory=tuple)

    def __getitem__(self, law: str) -> LawOutcome:
        for outcome in self.outcomes:
            if outcome.law == law:
                return outcome
        raise KeyError(f"no outcome {law!r}; have {[o.law for o in self.outcomes]}")

    @property
    def lzb(self) -> LawOutcome:
        """The LZB outcome."""
        return self.outcomes[-1]

    def table(self, digits: int = 4) -> str:
        """The outcomes as a Markdown table: one row per law, u⁺ of every body, T⁺/T⁻ and
        whether u⁺ ∈ S."""
        n = self.problem.n_dof
        head = "| law | " + " | ".join(f"u⁺{_sub(i + 1)}" for i in range(n)) + \
            " | T⁺/T⁻ | in S |"
        rows = [head, "|" + "---|" * (n + 3)]
        for o in self.outcomes:
            if o.result is None:
                cells = ["–"] * n + ["–", f"– ({o.note})"]
            else:
                cells = [f"{x:.{digits}f}" for x in o.u_plus]
                cells += [f"{o.energy_ratio:.{digits}f}", "yes" if o.in_S else "no"]
            rows.append(f"| {o.law} | " + " | ".join(cells) + " |")
        return "\n".join(rows)


def _sub(i: int) -> str:
    return "".join("₀₁₂₃₄₅₆₇₈₉"[int(c)] for c in str(i))


def _outcome(problem: ImpactProblem, label: str, law: Any, tol: float) -> LawOutcome:
    try:
        result = solve(problem, law, tol=tol)
    except SectorLawError as exc:
        reason = "unequal masses" if "equal masses" in str(exc) else "not a free chain"
        return LawOutcome(label, None, None, reason)
    return LawOutcome(label, result, problem.admissible_set().contains(result.u_plus))


def compare_laws(problem: ImpactProblem, lzb: LZB, *, tol: float = DEFAULT_TOL
                 ) -> LawComparison:
    """Moreau ε = 0, Moreau ε = 1, the sector law and ``lzb`` on ``problem``.

    Parameters
    ----------
    problem : ImpactProblem
        Any impact; the sector law only answers on free chains of equal masses.
    lzb : LZB
        The LZB law with the contacts' stiffnesses, exponents and restitutions, or another
        compliant law (``law.compliant``, docs/theory.md §13).
    tol : float
        Certificate tolerance of every solve.

    Returns
    -------
    LawComparison
        Each outcome with its certified result and the exact test u⁺ ∈ S.

    Raises
    ------
    InputError
        Not a problem, not a compliant law, or coefficients that do not fit the contacts.
    CertificateError
        A law's answer fails its certificate.
    """
    check_problem(problem)
    if not check_law(lzb).compliant:
        raise InputError(f"lzb must be a compliant law such as iq.LZB(stiffness), got {lzb!r}")
    laws = [("Moreau ε = 0", Moreau(0.0)), ("Moreau ε = 1", Moreau(1.0)),
            ("sector law", SectorLaw()), ("LZB", lzb)]
    return LawComparison(problem, tuple(_outcome(problem, label, law, tol)
                                        for label, law in laws))


def compare_chain(chain: PhysicalChain, restitution: Any = 1.0, *, step: float | None = None,
                  rtol: float = DEFAULT_RTOL, tol: float = DEFAULT_TOL) -> LawComparison:
    """:func:`compare_laws` on a chain of spheres with its Hertz stiffnesses.

    Parameters
    ----------
    chain : PhysicalChain
        From :func:`~impactqp.chains.monodisperse_chain`,
        :func:`~impactqp.chains.tapered_chain` or
        :func:`~impactqp.chains.ball_chain`.
    restitution : float or array_like
        LZB's energetic restitution per contact (1: elastic).
    step, rtol : optional
        LZB's integration: fixed step (N·s) or adaptive tolerance.
    tol : float
        Certificate tolerance.

    Returns
    -------
    LawComparison

    Raises
    ------
    InputError
        ``chain`` is not a PhysicalChain, or bad LZB coefficients (named).
    """
    if not isinstance(chain, PhysicalChain):
        raise InputError(f"chain must be a PhysicalChain (from monodisperse_chain, "
                         f"tapered_chain or ball_chain), got {type(chain).__name__}")
    law = LZB(chain.stiffness, chain.exponent, restitution, step, rtol=rtol)
    return compare_laws(chain.problem, law, tol=tol)
