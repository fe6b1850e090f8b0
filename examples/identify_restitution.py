"""Identifying restitution with derivatives through time
=====================================================

Identify restitution coefficients from measurements with impactqp's derivatives.

    python examples/identify_restitution.py              # prints the fits, writes nothing
    python examples/identify_restitution.py --out DIR    # also writes fit.json into DIR

1. A bouncing ball (q₀ = 1 m, g = 9.81 m/s²) filmed at 100 Hz for 2 s with the true Newton
   coefficient e* = 0.73: starting from e = 0.5, Gauss–Newton on the sampled heights finds e*
   with the derivative of the motion (event-driven, ``sensitivity_kind == "flow"``): the
   residuals' Jacobian from ``trajectory.sensitivity("e")``, their gradient from the adjoint
   ``trajectory.vjp`` (checked against each other), then the same with Moreau–Jean's discrete
   map at h = 1 ms sampled every 10th step.
2. A three-ball cradle struck in several ways, its post-impact velocities measured, with
   Moreau's coefficient ε* = 0.6: u⁺ = z + ε(z − u⁻) is affine in ε, so one Gauss–Newton step
   from ε = 0 finds ε*, with ∂u⁺/∂ε from each impact's ``r.derivative().jacobian("eps")``
   (equal to z − u⁻, z = prox_{T_C}(u⁻), checked).

The measurements are synthetic (impactqp's own runs at the true coefficients) and exact, so
the fits must land on the true values to 1e-6; docs/theory.md §21 explains the two
derivatives through time.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np

import impactqp as iq

E_TRUE, EPS_TRUE = 0.73, 0.6
RATE, DURATION = 100.0, 2.0


def samples(tr: iq.Trajectory, period: float) -> np.ndarray:
    """Rows of the records at the sampling instants k·period (an event-driven run also
    records both sides of each impact; those rows are not samples)."""
    k = np.round(tr.t / period)
    on_grid = np.abs(tr.t - k * period) <= 1e-9 * period
    first = np.concatenate([[True], np.diff(tr.t) > 0])  # one row per instant
    return np.flatnonzero(on_grid & first)


def fit_ball(scheme: str, measured: np.ndarray, e: float) -> tuple[float, list[str]]:
    """Gauss–Newton on e from the sampled heights ``measured``."""
    h = 1.0 / RATE if scheme == "event-driven" else 1e-3
    ball, log = iq.simulation.bouncing_ball(q0=1.0), []
    for it in range(20):
        tr = iq.simulate(ball, iq.Newton(e), DURATION, scheme=scheme, h=h,
                         sensitivities=("e",))
        rows = samples(tr, 1.0 / RATE)
        r = tr.q[rows, 0] - measured
        J = tr.sensitivity("e")[rows, 0, 0]  # ∂q(tᵢ)/∂e
        cot = np.zeros_like(tr.q)
        cot[rows, 0] = r  # ∂L/∂q of L = ½Σrᵢ² on the samples
        grad = tr.vjp(q=cot)["e"]  # the adjoint: Jᵀr without forming J
        assert abs(grad - J @ r) <= 1e-9 * max(1.0, abs(grad)), (grad, J @ r)
        step = -grad / (J @ J)
        log.append(f"  {it:2d}  e = {e:.9f}  ½‖r‖² = {0.5 * r @ r:.3e}  "
                   f"({tr.sensitivity_kind}, {len(tr.kinks)} kinks)")
        e += step
        if abs(step) < 1e-12:
            break
    return e, log


def fit_cradle(eps: float) -> tuple[float, list[str]]:
    """One Gauss–Newton step on Moreau's ε from the cradle's measured post-impact velocities."""
    strikes = [(1.0, 0.0, 0.0), (1.0, 0.0, -0.5), (2.0, 0.5, 0.0), (1.0, 0.2, -1.0)]
    truth = [iq.solve(iq.chain([1.0, 1.0, 1.0], u), iq.Moreau(EPS_TRUE)).u_plus for u in strikes]
    log = []
    for it in range(2):
        res, jac = [], []
        for u, measured in zip(strikes, truth):
            r = iq.solve(iq.chain([1.0, 1.0, 1.0], u), iq.Moreau(eps))
            d = r.derivative()  # the certified derivative of this impact
            dude = d.jacobian("eps")  # ∂u⁺/∂ε
            assert np.allclose(dude, r.z - r.problem.u_minus)  # = z − u⁻ for Moreau's law
            res.append(r.u_plus - measured)
            jac.append(dude)
        r, J = np.concatenate(res), np.concatenate(jac)
        log.append(f"  {it:2d}  ε = {eps:.9f}  ½‖r‖² = {0.5 * r @ r:.3e}")
        eps -= (J @ r) / (J @ J)
    return eps, log


def main(out: Path | None) -> None:
    truth = iq.simulate(iq.simulation.bouncing_ball(q0=1.0), iq.Newton(E_TRUE), DURATION,
                        scheme="event-driven", h=1.0 / RATE)
    measured = truth.q[samples(truth, 1.0 / RATE), 0]
    print(f"bouncing ball: {measured.size} heights at {RATE:.0f} Hz, e* = {E_TRUE}")
    fits = {}
    for scheme in ("event-driven", "moreau-jean"):
        data = measured
        if scheme == "moreau-jean":  # its own discrete map's measurements
            tr = iq.simulate(iq.simulation.bouncing_ball(q0=1.0), iq.Newton(E_TRUE),
                             DURATION, h=1e-3)
            data = tr.q[samples(tr, 1.0 / RATE), 0]
        e, log = fit_ball(scheme, data, 0.5)
        print(f"{scheme}, Gauss–Newton from e = 0.5:")
        print("\n".join(log))
        print(f"  e = {e:.9f}, |e - e*| = {abs(e - E_TRUE):.1e}")
        assert abs(e - E_TRUE) <= 1e-6
        fits[scheme] = e
    eps, log = fit_cradle(0.0)
    print(f"3-ball cradle, 4 strikes, ε* = {EPS_TRUE}, Gauss–Newton from ε = 0:")
    print("\n".join(log))
    print(f"  ε = {eps:.9f}, |ε - ε*| = {abs(eps - EPS_TRUE):.1e}")
    assert abs(eps - EPS_TRUE) <= 1e-6
    fits["cradle eps"] = eps
    if out is not None:
        out.mkdir(parents=True, exist_ok=True)
        (out / "fit.json").write_text(json.dumps(fits, indent=2), encoding="utf-8")
        print(f"results written to {out}")


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, help="write fit.json into this folder")
    main(parser.parse_args().out)
