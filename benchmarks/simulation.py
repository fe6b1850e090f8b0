"""Simulation benchmark: Moreau–Jean steps per second on a column of N beads, N = 3 … 10⁴.

    python -m benchmarks.simulation [--sizes 3,10,100,1000,10000] [--steps 200] [--repeats 3]

The column (``impactqp.bead_chain``): equal beads (m = 1, R = 0.1) stacked 1 mm apart, the
lowest 1 mm above the ground, falling under gravity; Newton's law e = 0.9 in the Moreau–Jean
step form, θ = 1/2, h = 1 ms, ``steps`` steps. Every step solves the impacts of the closed
contacts through ``impactqp.solve`` (certified); the run keeps no events, as a long
simulation would. Printed: the median steps per second over ``repeats`` runs.

Siconos' MoreauJeanOSI time-stepping on the same column (its ``LCP`` one-step problem, Lemke
by default) is timed where siconos can be imported: in this Python, or else in
``--siconos-python`` (Debian's ``/usr/bin/python3`` with ``python3-siconos``), where this
file runs itself as a worker (its top-level imports are the standard library only). Without
siconos the comparison is skipped with a notice. Siconos runs are capped at
``--siconos-max`` beads (its Lemke solver works on dense matrices). The final positions of
both are compared, as a check that the two integrators agree.
"""

from __future__ import annotations

import argparse
import json
import statistics
import subprocess
import sys
import time
from pathlib import Path

H, E, RADIUS, GAP, GRAVITY = 1e-3, 0.9, 0.1, 1e-3, 9.81
SICONOS_PYTHON = "/usr/bin/python3"


def column(n: int) -> dict:
    """The beads' initial heights and the contact offsets (shared by both integrators)."""
    return {"q0": [RADIUS + GAP + i * (2 * RADIUS + GAP) for i in range(n)]}


def impactqp_run(n: int, steps: int) -> tuple[float, list[float]]:
    """Seconds for ``steps`` Moreau–Jean steps of the n-bead column, and the final heights."""
    from impactqp.laws.complementarity import Newton
    from impactqp.simulation.builders import bead_chain
    from impactqp.simulation.simulate import simulate

    system = bead_chain(n, radius=RADIUS, height=RADIUS + GAP, spacing=2 * RADIUS + GAP,
                        gravity=GRAVITY)
    start = time.perf_counter()
    trajectory = simulate(system, Newton(E), steps * H, h=H, theta=0.5, keep_events=False,
                          record_every=steps)
    return time.perf_counter() - start, trajectory.q[-1].tolist()


def siconos_run(n: int, steps: int) -> tuple[float, list[float]]:
    """The same column with Siconos' kernel (runs where ``siconos.kernel`` imports)."""
    import siconos.kernel as sk

    nsds = sk.NonSmoothDynamicalSystem(0.0, steps * H)
    beads = []
    for q in column(n)["q0"]:
        ds = sk.LagrangianLinearTIDS([q], [0.0], [[1.0]])
        ds.setFExtPtr([-GRAVITY])
        nsds.insertDynamicalSystem(ds)
        beads.append(ds)
    law = sk.NewtonImpactNSL(E)
    ground = sk.Interaction(law, sk.LagrangianLinearTIR([[1.0]], [-RADIUS]))
    nsds.link(ground, beads[0])
    for i in range(n - 1):
        pair = sk.Interaction(law, sk.LagrangianLinearTIR([[-1.0, 1.0]], [-2 * RADIUS]))
        nsds.link(pair, beads[i], beads[i + 1])
    sim = sk.TimeStepping(nsds, sk.TimeDiscretisation(0.0, H), sk.MoreauJeanOSI(0.5),
                          sk.LCP())
    start = time.perf_counter()
    for _ in range(steps):
        sim.computeOneStep()
        sim.nextStep()
    return time.perf_counter() - start, [float(ds.q()[0]) for ds in beads]


def _median_rate(run, n: int, steps: int, repeats: int) -> tuple[float, list[float]]:
    rates, final = [], []
    for _ in range(repeats):
        seconds, final = run(n, steps)
        rates.append(steps / seconds)
    return statistics.median(rates), final


def _siconos_in(python: str, n: int, steps: int, repeats: int) -> dict:
    """Run this file as a Siconos worker in another interpreter."""
    done = subprocess.run([python, str(Path(__file__).resolve()), "--siconos-worker",
                           str(n), str(steps), str(repeats)], capture_output=True, text=True,
                          timeout=3600)
    if done.returncode != 0:
        return {"error": (done.stderr.strip().splitlines() or ["failed"])[-1]}
    return json.loads(done.stdout)


def siconos_available(python: str) -> str | None:
    """Where Siconos can run: ``"here"``, the other interpreter, or None."""
    try:
        import siconos.kernel  # noqa: F401
        return "here"
    except ImportError:
        pass
    if not python:
        return None
    try:
        check = subprocess.run([python, "-c", "import siconos.kernel"], capture_output=True,
                               timeout=120)
    except (OSError, subprocess.TimeoutExpired):
        return None
    return python if check.returncode == 0 else None


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m benchmarks.simulation",
                                     description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", default="3,10,100,1000,10000")
    parser.add_argument("--steps", type=int, default=200)
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--siconos-python", default=SICONOS_PYTHON,
                        help="interpreter that imports siconos ('' skips the peer)")
    parser.add_argument("--siconos-max", type=int, default=1000,
                        help="largest column given to Siconos")
    parser.add_argument("--siconos-worker", nargs=3, type=int, help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.siconos_worker:
        n, steps, repeats = args.siconos_worker
        rate, final = _median_rate(siconos_run, n, steps, repeats)
        print(json.dumps({"rate": rate, "final": final}))
        return 0
    sizes = [int(s) for s in args.sizes.split(",")]
    where = siconos_available(args.siconos_python)
    print(f"Moreau–Jean, bead column, Newton e = {E}, h = {H}, {args.steps} steps, "
          f"median of {args.repeats} runs")
    if where is None:
        print("siconos: not importable here nor in --siconos-python; comparison skipped")
    print(f"{'N':>6} | {'impactqp steps/s':>16} | {'Siconos steps/s':>15} | max |Δq| final")
    for n in sizes:
        rate, final = _median_rate(impactqp_run, n, args.steps, args.repeats)
        peer, diff = "skipped", ""
        if where is not None and n <= args.siconos_max:
            out = (dict(zip(("rate", "final"), _median_rate(siconos_run, n, args.steps,
                                                           args.repeats)))
                   if where == "here" else _siconos_in(where, n, args.steps, args.repeats))
            if "error" in out:
                peer = "failed"
                print(f"siconos N = {n}: {out['error']}", file=sys.stderr)
            else:
                peer = f"{out['rate']:.0f}"
                diff = f"{max(abs(a - b) for a, b in zip(final, out['final'])):.1e}"
        elif where is not None:
            peer = f"> cap {args.siconos_max}"
        print(f"{n:>6} | {rate:>16.0f} | {peer:>15} | {diff}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
