"""Frictional impacts of a few contacts: seconds per impact, beside the frictionless one.

Spheres (radius R, mass m, inertia 2/5·mR², 6 DOF each) in a row on the plane z = 0, each
touching the ground and its neighbours: n spheres have 2n − 1 contacts. Per contact the
local velocity (normal from the first body to the second, then two tangents) is
u_c = H_cᵀ v: for sphere a below sphere b along n, the contact point sits at +R n from a's
centre and −R n from b's, so e·u = e·(v_b − v_a) + ω_b·(−R n × e) − ω_a·(R n × e) for each
direction e of the contact frame. The impact's local problem (docs/theory.md §15, plastic
in the normal: restitution 0) is W = Hᵀ M⁻¹ H, q = Hᵀ v⁻.

Rows: family ``friction-impact`` (size: contacts), one per method of :data:`METHODS`, each
a ``prepare(case)`` returning the call that is timed (built untimed). The frictionless
method solves the same impact with the normals only (``iq.moreau``, compiled kernel).
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass
from functools import partial
from typing import Any

import numpy as np

import impactqp as iq

from .measure import quiet_stdout, row

MU = 0.3
RADIUS, MASS = 0.1, 1.0
#: per suite: spheres per case (contacts 2n − 1), and (most repeats, seconds)
SIZES: dict[str, tuple[list[int], tuple[int, float]]] = {
    "quick": ([1, 3], (200, 0.05)),
    "full": ([1, 3, 10], (2000, 0.3)),
    "friction": ([1, 3, 10], (2000, 0.3)),
}


@dataclass
class SphereImpact:
    """An impact of spheres in a row on a plane, in both forms.

    Attributes
    ----------
    M : (6n, 6n) ndarray
        Masses and inertias.
    H : (6n, 3m) ndarray
        Contact directions: u = Hᵀ v, 3 columns per contact (normal, two tangents).
    v_minus : (6n,) ndarray
        Velocities before the impact.
    mu : float
        Friction coefficient of every contact.
    local : FrictionContactProblem
        W = Hᵀ M⁻¹ H, q = Hᵀ v⁻, μ.
    normal : ImpactProblem
        The frictionless impact: M, the normal columns of H, v⁻.
    """

    M: np.ndarray
    H: np.ndarray
    v_minus: np.ndarray
    mu: float
    local: iq.FrictionContactProblem
    normal: iq.ImpactProblem

    @property
    def n_contacts(self) -> int:
        return self.H.shape[1] // 3


def _frame(n: np.ndarray) -> np.ndarray:
    """(n, t1, t2): an orthonormal frame whose first vector is n."""
    helper = np.array([1.0, 0.0, 0.0]) if abs(n[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    t1 = np.cross(n, helper)
    t1 /= np.linalg.norm(t1)
    return np.array([n, t1, np.cross(n, t1)])


def spheres_in_a_row(n: int, *, seed: int = 0, mu: float = MU) -> SphereImpact:
    """``n`` spheres side by side along x on the ground, falling (v_z ∈ [−2, −1]) with
    seeded horizontal velocities and spins; 2n − 1 contacts."""
    rng = np.random.default_rng(seed)
    inertia = 0.4 * MASS * RADIUS**2
    M = np.diag(np.tile([MASS] * 3 + [inertia] * 3, n))
    up = np.array([0.0, 0.0, 1.0])
    contacts = [(None, i, up) for i in range(n)]  # (below, above, normal): ground first
    contacts += [(i, i + 1, np.array([1.0, 0.0, 0.0])) for i in range(n - 1)]
    H = np.zeros((6 * n, 3 * len(contacts)))
    for c, (a, b, normal) in enumerate(contacts):
        for k, e in enumerate(_frame(normal)):
            col = 3 * c + k
            H[6 * b:6 * b + 3, col] = e
            H[6 * b + 3:6 * b + 6, col] = np.cross(-RADIUS * normal, e)
            if a is not None:
                H[6 * a:6 * a + 3, col] = -e
                H[6 * a + 3:6 * a + 6, col] = -np.cross(RADIUS * normal, e)
    v = np.zeros(6 * n)
    for i in range(n):
        v[6 * i:6 * i + 3] = [rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-2, -1)]
        v[6 * i + 3:6 * i + 6] = rng.uniform(-5, 5, 3)
    W = H.T @ np.linalg.solve(M, H)
    local = iq.FrictionContactProblem(W, H.T @ v, mu)
    normal = iq.ImpactProblem(M, H[:, 0::3], v)
    return SphereImpact(M, H, v, mu, local, normal)


Prepare = Callable[[SphereImpact], Callable[[], Any]]
METHODS: dict[str, Prepare] = {
    "iq:solve_friction": lambda c: lambda: iq.solve_friction(c.local),
    "iq:solve(Coulomb)": lambda c: partial(iq.solve, iq.ImpactProblem(
        c.M, c.H, c.v_minus, contact_dim=3), iq.Coulomb(c.mu)),
    "iq:moreau (frictionless)": lambda c: lambda: iq.moreau(c.normal, 0.0),
}
"""Per method, ``prepare(case)`` → the timed call (its result: an error attribute, if any,
is the row's error). ``iq:solve(Coulomb)`` is the whole impact law through the pipeline
(local problem, solve, u⁺ and the law's certificate), the problem built untimed."""
REFERENCE = "each answer's own certificate (error: ABH of solve_friction's)"
NOTE = ("spheres in a row on a plane (2n − 1 contacts, μ = 0.3, restitution 0): the call "
        "alone, problem built before; iq:solve_friction on W = HᵀM⁻¹H, q = Hᵀv⁻; "
        "frictionless: the normals only")


def run_friction_impacts(suite: str) -> list[dict]:
    """Rows of :data:`METHODS` on the suite's sphere rows: seconds per impact."""
    if suite not in SIZES:
        return []
    sizes, (repeats, budget) = SIZES[suite]
    rows = []
    for n in sizes:
        case = spheres_in_a_row(n)
        for name, prepare in METHODS.items():
            try:
                with quiet_stdout():
                    call = prepare(case)
                    result = call()  # warm-up: compiles, fills caches
                    times: list[float] = []
                    start = time.perf_counter()
                    while len(times) < repeats and (not times or
                                                    time.perf_counter() - start < budget):
                        t0 = time.perf_counter()
                        call()
                        times.append(time.perf_counter() - t0)
            except Exception as exc:  # a failing method is a result
                rows.append(row("friction-impact", case.n_contacts, name, "impactqp",
                                status="failed", message=f"{type(exc).__name__}: {exc}",
                                note=NOTE, reference=REFERENCE))
                continue
            error = getattr(result, "error", None)
            rows.append(row("friction-impact", case.n_contacts, name, "impactqp",
                            status="ok", times=times, note=NOTE,
                            error=float(error) if error is not None else None,
                            reference=REFERENCE))
    return rows
