"""The one certificate type of impactqp: named residuals, each within its tolerance
(docs/theory.md §8).

Every answer impactqp returns carries a :class:`Certificate` (the impact laws, Coulomb
friction and :func:`impactqp.solve_friction`, LZB, the sector tables, the frictional steps
of a simulation, cone programs and LCPs); what a maker adds beside the verdict goes into
``reported`` (figures shown, not judged) and ``extras`` (anything else, e.g. an
integration's record). A residual that is NaN or infinite fails: a check that cannot be
evaluated never passes.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

DEFAULT_TOL = 1e-9
"""Default tolerance of the dimensionless residuals of a certificate (docs/theory.md §8)."""

FRICTION_TOL = 1e-8
"""Default tolerance of a frictional contact problem's certificate: ABH's ‖F‖/‖q‖ among the
others (docs/theory.md §15), the accuracy FCLib's benchmarks ask for."""

UNIT_RANGE = (1e-100, 1e100)
"""Velocity scales (largest |u⁻ᵢ|) worked with as given; beyond them, scale-free answers are
computed in order-one units and scaled back (docs/theory.md §8): norms and products of
1e±160 velocities leave the float range."""


def as_residual(value) -> float:
    """A residual as a float; NaN becomes +inf so that it fails every comparison."""
    v = float(value)
    return v if v == v else math.inf


def _size(value: float) -> float:
    """A residual's size for ranking: a non-finite one counts as the largest."""
    return value if math.isfinite(value) else math.inf


@dataclass(frozen=True, eq=False, repr=False, init=False)
class Certificate:
    """The recomputed residuals of one answer and the one verdict on them
    (docs/theory.md §8): accepted (``ok``, ``bool(cert)``) when every residual is finite
    and within its tolerance.

    Each name the certificate holds (a residual, a reported figure or an extra) reads as
    an attribute: ``cert.momentum``, ``cert.record``; a residual its maker declares in
    ``names`` but has not got (e.g. Moreau's ``duality_gap`` on a Newton certificate) reads
    as None.

    Parameters
    ----------
    values : mapping of str to float
        The residuals by name (NaN is stored as +inf, so it fails).
    tol : float
        Tolerance every residual must meet.
    reported : mapping of str to float, optional
        Figures shown beside the residuals (``summary``), not part of the verdict.
    extras : mapping, optional
        Anything else its maker reports (an integration's record, a table's per-cone
        checks).
    tols : mapping of str to float, optional
        A residual's own tolerance where it is not ``tol`` (LZB's integration-decided
        residuals, docs/theory.md §13).
    names : tuple of str, optional
        The residuals its maker declares (the law's ``residual_names``).
    """

    values: Mapping[str, float]
    tol: float
    reported: Mapping[str, float]
    extras: Mapping[str, Any]
    tols: Mapping[str, float]
    names: tuple[str, ...]

    def __init__(self, values: Mapping[str, Any], tol: float, *,
                 reported: Mapping[str, float] | None = None,
                 extras: Mapping[str, Any] | None = None,
                 tols: Mapping[str, float] | None = None, names: tuple[str, ...] = ()) -> None:
        # written out (not the dataclass's): a certificate is made for every answer, and the
        # generated one with its default factories and a __post_init__ costs more
        self.__dict__.update(values=self.stored(values), tol=tol,
                             reported={} if reported is None else reported,
                             extras={} if extras is None else extras,
                             tols={} if tols is None else tols, names=names)

    @staticmethod
    def stored(values: Mapping[str, Any]) -> dict:
        """The residuals as stored: floats, NaN as +inf (:func:`!as_residual`, inlined)."""
        return {k: f if (f := float(v)) == f else math.inf for k, v in values.items()}

    def __getattr__(self, name: str) -> Any:
        state = self.__dict__
        for table in ("values", "reported", "extras"):
            held = state.get(table)
            if held is not None and name in held:
                return held[name]
        if name in state.get("names", ()):
            return None
        raise AttributeError(f"{type(self).__name__} has no attribute {name!r}")

    @property
    def residuals(self) -> dict[str, float]:
        """The named residuals (a copy of ``values``)."""
        return dict(self.values)

    def tol_of(self, name: str) -> float:
        """The tolerance residual ``name`` must meet."""
        return self.tols.get(name, self.tol)

    @property
    def ok(self) -> bool:
        """True when every residual is finite and within its tolerance."""
        if self.tols:
            return all(math.isfinite(v) and v <= self.tol_of(k) for k, v in self.values.items())
        for v in self.values.values():  # a loop: read for every answer, all() costs twice
            if not (math.isfinite(v) and v <= self.tol):
                return False
        return True

    def peaks(self) -> dict[str, float]:
        """Each residual's value as ``worst`` and ``summary`` rank it."""
        return dict(self.values)

    @property
    def worst(self) -> tuple[str, float]:
        """The largest residual and its name (a non-finite one counts as the largest)."""
        res = self.peaks()
        if not res:
            return "none", 0.0
        name = max(res, key=lambda k: _size(res[k]))
        return name, res[name]

    @property
    def velocity_error_bound(self) -> float | None:
        """Bound on ‖u⁺ − u⁺_exact‖ / ‖u⁻‖ from a duality gap (Moreau's law), None without
        one: the error is at most ‖r‖ + √(Σ Λᵢ|wᵢ|) (r the momentum residual,
        docs/theory.md §3), and (x + y)² ≤ 2(x² + y²) turns the gap into √(2 · duality_gap)."""
        gap = self.values.get("duality_gap")
        return None if gap is None else float(np.sqrt(2.0 * gap))

    def __bool__(self) -> bool:
        return bool(self.ok)

    def summary(self) -> str:
        """One line: the verdict, the tolerances, every residual and the reported figures."""
        parts = ", ".join(f"{k}={v:.1e}" for k, v in self.peaks().items())
        own = "".join(f", {k} {t:.0e}" for k, t in self.tols.items() if t != self.tol)
        line = f"{'ok' if self.ok else 'FAILED'} (tol {self.tol:.0e}{own}): {parts}"
        if self.reported:
            line += "; reported: " + ", ".join(f"{k}={v:.1e}" for k, v in self.reported.items())
        return line

    def __repr__(self) -> str:
        return f"{type(self).__name__}({self.summary()})"



@dataclass(frozen=True, eq=False, repr=False, init=False)
class BatchCertificate(Certificate):
    """The residuals of k impacts, each a (k,) array, with a verdict per row.

    A :class:`~impactqp.results.Certificate` whose ``ok`` is the (k,) boolean array of the rows'
    verdicts (:func:`certified_rows`) instead of one boolean: a batch is certified row by
    row, and a row that fails is solved again on its own, so the per-row verdict is what
    :func:`impactqp.solve_batch` acts on. That is all it adds; ``bool(cert)`` is True when
    every row passes, ``worst`` and ``summary`` read each residual's largest value over
    the rows.
    """

    @staticmethod
    def stored(values: Mapping[str, Any]) -> dict:
        """The residuals as stored: one float array per residual."""
        return {k: np.asarray(v, dtype=float) for k, v in values.items()}

    @property
    def ok(self) -> np.ndarray:
        """Per-row verdict: every residual of the row within ``tol`` (NaN fails)."""
        return certified_rows(self.values, self.tol)

    def __bool__(self) -> bool:
        return bool(np.all(self.ok))

    def peaks(self) -> dict[str, float]:
        """Each residual's largest value over the rows (a non-finite one as +inf); none
        without rows."""
        if not self.values or not len(next(iter(self.values.values()))):
            return {}
        return {k: float(np.max(np.where(np.isfinite(v), v, np.inf)))
                for k, v in self.values.items()}


def certified_rows(residuals: dict, tol: float) -> np.ndarray:
    """Rows whose every residual is within ``tol`` (NaN fails)."""
    return np.all([v <= tol for v in residuals.values()], axis=0)


ResidualChecks = Certificate
"""Another name of :class:`Certificate` (the verdict's name before there was one type)."""

NamedChecks = Certificate
"""Another name of :class:`Certificate` (a certificate given by its residuals)."""
