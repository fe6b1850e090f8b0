"""The main job: Newton's cradle through Moreau's law, verified and classified (docs/theory.md
§5)."""

from __future__ import annotations

import numpy as np

from ..errors import InputError, OutOfRangeError
from ..laws.functions import moreau
from ..model.builders import newtons_cradle
from ..model.classify import classify

SPEEDS = (1e-150, 1e150)
"""Speeds the demo takes: its energies v²/2 (unit masses) and the squared norms behind the
classification stay normal floats, neither overflowing nor losing their digits below the
smallest normal float. The impact map is homogeneous in v (docs/theory.md §8), so any other
speed is this table scaled."""


def _num(x: float, sign: str = "") -> str:
    """Four decimals, or four significant digits and an exponent outside [1e-3, 1e6)."""
    return f"{x:{sign}.4f}" if x == 0 or 1e-3 <= abs(x) < 1e6 else f"{x:{sign}.3e}"


def _vec(a: np.ndarray) -> str:
    return "(" + ", ".join(_num(x, "+") for x in a) + ")"


def cradle_rows(n_balls: int = 3, v: float = 1.0, backend: str = "auto") -> list[dict]:
    """Solve the cradle with Moreau ε = 0 and ε = 1 and check the observed outcome (docs/theory.md
    §5).

    Raises :class:`~impactqp.errors.OutOfRangeError` for a speed outside :data:`SPEEDS`.
    Returns one row per post-impact velocity: the two Moreau points and the velocity of the
    real cradle (the last ball leaves at v), each with its classification and verdict.
    """
    p = newtons_cradle(n_balls=n_balls, v=v)
    if not v > 0:
        raise InputError(f"v must be positive: ball 1 moves at v towards the resting balls "
                         f"(v = {v:g} makes no impact to solve and classify)")
    low, high = SPEEDS
    if not low <= v <= high:
        raise OutOfRangeError(f"v = {v:g} is outside the demo's range [{low:g}, {high:g}]: "
                              f"its energies v²/2 would {'overflow' if v > high else 'underflow'}"
                              " the floats; the impact map is homogeneous in v, so run v = 1 "
                              "and scale u⁺ and the impulses by v (energies by v²)")
    S = p.admissible_set()
    rows = []
    for eps in (0.0, 1.0):
        r = moreau(p, eps=eps, backend=backend)
        rows.append({"case": f"Moreau eps={eps:g}", "u_plus": r.u_plus, "impulses": r.impulses,
                     "backend": r.backend, "certificate": r.certificate.summary()})
    observed = np.zeros(n_balls)
    observed[-1] = v
    rows.append({"case": "observed cradle", "u_plus": observed,
                 "impulses": S.contains(observed).impulses, "backend": "-",
                 "certificate": "-"})
    for row in rows:
        c = classify(p, row["u_plus"])
        exact, opt = S.contains(row["u_plus"]), S.contains(row["u_plus"], method="optimizer")
        row.update(energy_before=p.kinetic_energy(), energy_after=p.kinetic_energy(row["u_plus"]),
                   alpha_deg=c.alpha_deg, dissipation=c.dissipation, intensity=c.intensity,
                   in_S=bool(exact), in_S_optimizer=bool(opt))
    return rows


def format_rows(rows: list[dict]) -> str:
    """A plain-text table of :func:`cradle_rows`."""
    head = (f"{'case':<17} {'u_plus':<27} {'impulses':<19} {'T-':>6} {'T+':>6} "
            f"{'alpha':>6} {'diss':>5} {'in S':>5} {'(SOCP)':>6}  backend")
    lines = [head, "-" * len(head)]
    for r in rows:
        alpha = "nan" if np.isnan(r["alpha_deg"]) else f"{r['alpha_deg']:.2f}"
        lines.append(f"{r['case']:<17} {_vec(r['u_plus']):<27} {_vec(r['impulses']):<19} "
                     f"{_num(r['energy_before']):>6} {_num(r['energy_after']):>6} {alpha:>6} "
                     f"{r['dissipation']:5.2f} {str(r['in_S']):>5} {str(r['in_S_optimizer']):>6}"
                     f"  {r['backend']}")
    lines.append("")
    for r in rows:
        if r["certificate"] != "-":
            lines.append(f"certificate {r['case']}: {r['certificate']}")
    return "\n".join(lines)
