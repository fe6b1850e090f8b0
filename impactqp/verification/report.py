"""What a verification reports: counts of violations and recheckable counterexamples."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

DEFAULT_TOL = 1e-7
"""Tolerance on the dimensionless residuals of :class:`~impactqp.problems.Membership`."""

ADMISSIBILITY = ("kinematic", "kinetic", "energetic")
CONDITIONS = ADMISSIBILITY + ("non_expansive", "law_error")



@dataclass(frozen=True)
class Counterexample:
    """One violation: the input, the law's answer, the condition and by how much.

    For ``"non_expansive"`` the offending pair is stacked: ``u_minus`` and ``u_plus`` have
    shape (2, n) and ``amount`` is ‖Δu⁺‖/‖Δu⁻‖ − 1; otherwise ``amount`` is the residual of
    :class:`~impactqp.problems.Membership` for that condition.

    Attributes
    ----------
    u_minus : (n,) or (2, n) ndarray
        The pre-impact velocity (the pair, for ``"non_expansive"``).
    u_plus : (n,) or (2, n) ndarray
        The law's answer to it (NaN where the law raised).
    condition : str
        ``"kinematic"``, ``"kinetic"``, ``"energetic"``, ``"non_expansive"``,
        ``"law_error"`` (or ``"continuity"`` for an exact certificate).
    amount : float
        By how much the condition is violated (dimensionless; ``inf`` for a law error).
    error : str or None
        For ``"law_error"``: the law's exception as ``"Type: message"`` (or why its answer
        was refused).
    """

    u_minus: np.ndarray
    u_plus: np.ndarray
    condition: str
    amount: float
    error: str | None = None


@dataclass(frozen=True)
class LawReport:
    """What :func:`verify_law` found.

    Attributes
    ----------
    ok : bool
        No condition was violated.
    violations : dict[str, int]
        Per condition, how many samples (pairs for ``"non_expansive"``, cones for an exact
        certificate) violate it. ``"law_error"`` counts samples where the law raised.
    counterexamples : dict[str, Counterexample]
        The worst violation of each violated condition.
    worst : Counterexample or None
        The worst of them all (largest amount).
    samples, pairs : int
        How many u⁻ and pairs were checked (0 for an exact certificate).
    method : str
        ``"sampled"`` or ``"exact"``.
    certificate : TableCertificate or None
        The docs/theory.md §7 certificate when ``method == "exact"``.
    """

    ok: bool
    violations: dict[str, int]
    counterexamples: dict[str, Counterexample]
    samples: int
    pairs: int
    method: str
    certificate: Any = field(default=None, repr=False)

    @property
    def worst(self) -> Counterexample | None:
        if not self.counterexamples:
            return None
        return max(self.counterexamples.values(), key=lambda c: c.amount)

    def summary(self) -> str:
        """One line: verdict, counts and the worst violation."""
        counts = ", ".join(f"{k}={v}" for k, v in self.violations.items())
        size = f"{self.samples} samples, {self.pairs} pairs" if self.method == "sampled" \
            else "exact"
        line = f"{'ok' if self.ok else 'VIOLATED'} ({size}): {counts}"
        if self.worst is not None:
            line += f"; worst {self.worst.condition} by {self.worst.amount:.3g}"
            if self.worst.error:
                line += f" ({self.worst.error})"
        return line


