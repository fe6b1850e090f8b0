"""A sweep of the public entry points over units: velocity scales 1e-300…1e300, masses
1e-12…1e12, lengths 1e-9…1e9. Every call has its expected outcome: a correct answer (its
certificate passes and it equals the order-one answer scaled), or, for the cases listed in
:data:`REFUSALS`, the named error that says why (OutOfRangeError where the answer is beyond
the floats). A bare exception, a wrong answer returned as success, another refusal or a
correct answer turned into a refusal all fail. ``python tests/test_entry_sweep.py`` prints
the counts."""

from __future__ import annotations

from collections import Counter

import numpy as np
import pytest

import impactqp as iq

VELOCITIES = [1e-300, 1e-200, 1e-150, 1e-50, 1.0, 1e50, 1e150, 1e200, 1e300]
MASSES = [1e-12, 1.0, 1e12]
LAWS = [iq.Moreau(0.5), iq.Newton(0.7), iq.Fremond([[0.5, 0.1], [0.0, 0.5]]), iq.SectorLaw()]


REFUSALS = {**{f"solve {law} v=1e+300 m=1e+12": "OutOfRangeError"
               for law in ("moreau", "newton", "fremond", "sector")},
            "classify v=1e+300 m=1e+12": "OutOfRangeError",
            "solve_batch v=1e+300 m=1e+12": "OutOfRangeError"}
"""The cases refused, by name, and the named error each must raise: at v = 1e300 and
m = 1e12 the impulses (m·v = 1e312) and the kinetic energies are beyond the floats. Every
other case must be answered correctly."""


def _problem(v: float, m: float) -> iq.ImpactProblem:
    return iq.chain([m, m, m], [v, 0.0, 0.0])


def _outcome(call, check) -> str:
    """"correct", "WRONG" or the name of the impactqp error raised."""
    try:
        value = call()
    except iq.ImpactError as exc:
        return type(exc).__name__
    return "correct" if check(value) else "WRONG"


def solve_cases():
    for law in LAWS:
        ref = iq.solve(_problem(1.0, 1.0), law)
        for v in VELOCITIES:
            for m in MASSES:
                def check(r, v=v, m=m, ref=ref):
                    rtol = 1e-9 if v >= 1e-300 * 1e10 else 1e-5
                    return (r.certificate.ok and np.allclose(r.u_plus / v, ref.u_plus,
                                                             rtol=rtol, atol=rtol)
                            and np.allclose(r.impulses / (v * m), ref.impulses, rtol=rtol,
                                            atol=rtol))
                yield (f"solve {law.name} v={v:g} m={m:g}",
                       lambda law=law, v=v, m=m: iq.solve(_problem(v, m), law), check)


def geometry_cases():
    ref_c = iq.classify(_problem(1.0, 1.0), [0, 0, 1.0])
    for v in VELOCITIES:
        for m in MASSES:
            p = _problem(v, m)
            yield (f"contains v={v:g} m={m:g}", lambda p=p, v=v: p.admissible_set().contains(
                [0, 0, v]), lambda r: bool(r))
            yield (f"contains optimizer v={v:g} m={m:g}",
                   lambda p=p, v=v: p.admissible_set().contains([0, 0, v], method="optimizer"),
                   lambda r: bool(r))
            yield (f"classify v={v:g} m={m:g}", lambda p=p, v=v: iq.classify(p, [0, 0, v]),
                   lambda c: abs(c.alpha_deg - ref_c.alpha_deg) < 1e-6
                   and abs(c.dissipation - ref_c.dissipation) < 1e-6)
            yield (f"verify_law v={v:g} m={m:g}",
                   lambda p=p: iq.verify_law(iq.Moreau(0.5), p, samples=4),
                   lambda report: report.ok)
            yield (f"solve_batch v={v:g} m={m:g}",
                   lambda p=p, v=v: iq.solve_batch(p, iq.Moreau(1.0), [[v, 0, 0], [0, v, 0]]),
                   lambda b, v=v: bool(np.all(b.ok)) and np.allclose(
                       b.u_plus[0] / v, [-1 / 3, 2 / 3, 2 / 3], atol=1e-9))


def simulation_cases():
    unit = iq.simulate(iq.simulation.bouncing_ball(q0=1.0), iq.Newton(0.9), 10.0,
                       scheme="event-driven")
    for length in [1e-9, 1e-3, 1.0, 1e3, 1e9]:
        for mass in [1e-12, 1.0, 1e12]:
            ball = iq.simulation.bouncing_ball(mass=mass, q0=length)
            t_end = 10.0 * np.sqrt(length)
            yield (f"event-driven L={length:g} m={mass:g}",
                   lambda ball=ball, t_end=t_end: iq.simulate(ball, iq.Newton(0.9), t_end,
                                                              scheme="event-driven"),
                   lambda tr, length=length: tr.certified and np.allclose(
                       tr.impact_times / np.sqrt(length), unit.impact_times, rtol=1e-9))
            yield (f"moreau-jean L={length:g} m={mass:g}",
                   lambda ball=ball, t_end=t_end, length=length: iq.simulate(
                       ball, iq.Newton(0.9), t_end, h=t_end / 2000),
                   lambda tr, length=length: tr.certified and np.isfinite(tr.q).all()
                   and abs(tr.q[-1, 0]) < 1e-2 * length)


CASES = list(solve_cases()) + list(geometry_cases()) + list(simulation_cases())


@pytest.mark.parametrize("name, call, check", CASES, ids=[c[0] for c in CASES])
def test_every_call_has_its_expected_outcome(name, call, check):
    assert _outcome(call, check) == REFUSALS.get(name, "correct")


def test_refusals_name_real_cases():
    assert set(REFUSALS) <= {c[0] for c in CASES}


if __name__ == "__main__":
    counts: dict[str, Counter] = {}
    for name, call, check in CASES:
        counts.setdefault(name.split(" v=")[0].split(" L=")[0], Counter())[
            _outcome(call, check)] += 1
    for entry, c in counts.items():
        print(f"{entry}: {sum(c.values())} cases, " + ", ".join(f"{k} {n}" for k, n in
                                                                sorted(c.items())))
