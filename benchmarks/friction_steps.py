"""Cost of a frictional Moreau–Jean step beside the frictionless one (docs/theory.md §17).

    python -m benchmarks.friction_steps [--steps 1000] [--repeats 5]

Each system slides for the whole run, so that every step solves a local problem: a block on
an incline (1 contact, in the plane and in space) and boxes flat on a floor on their corners
(2 contacts in the plane; 4, 8 and 16 in space, the latter two several boxes side by side in
one system, which the frictional step solves as one local problem). The frictional run,
``iq.Coulomb(μ)`` on the system, in the compiled and in the Python frictional loop, is timed
beside the frictionless one, Newton's law (e = 0) on the system's normal columns, in the
compiled and in the Python loop. Times are the
median of the repeats of ``simulate`` (set-up included), divided by the number of steps,
after one untimed warm-up of each run.
"""

from __future__ import annotations

import argparse
import statistics
import time
from collections.abc import Callable
from functools import partial

import numpy as np
import scipy.linalg as sla

from impactqp.laws.complementarity import Newton
from impactqp.laws.coulomb import Coulomb
from impactqp.simulation.builders import block_on_incline, box_on_floor
from impactqp.simulation.system import LinearSystem
from impactqp.simulation.time_stepping import moreau_jean

H_STEP = 1e-3
MU = 0.3


def boxes(count: int) -> LinearSystem:
    """``count`` boxes on the floor, sliding in different directions, as one system."""
    parts = [box_on_floor(3, velocity=(4.0 * np.cos(k), 4.0 * np.sin(k)), gap=-1e-9)
             for k in range(count)]
    return LinearSystem(sla.block_diag(*(p.M for p in parts)),
                        np.concatenate([p.q0 for p in parts]),
                        np.concatenate([p.v0 for p in parts]),
                        np.concatenate([p.constant_force for p in parts]),
                        sla.block_diag(*(p.H for p in parts)),
                        np.concatenate([p.b for p in parts]), contact_dim=3)


SYSTEMS: dict[str, Callable[[], LinearSystem]] = {
    "block, plane (1 contact)": lambda: block_on_incline(0.6, dim=2, gap=-1e-9),
    "block, space (1 contact)": lambda: block_on_incline(0.6, dim=3, gap=-1e-9),
    "box, plane (2 contacts)": lambda: box_on_floor(2, velocity=4.0, gap=-1e-9),
    "box, space (4 contacts)": lambda: boxes(1),
    "2 boxes (8 contacts)": lambda: boxes(2),
    "4 boxes (16 contacts)": lambda: boxes(4),
}


def frictionless(system: LinearSystem) -> LinearSystem:
    """The same system with the normal columns of its contacts only."""
    d = system.contact_dim
    return LinearSystem(system.M, system.q0, system.v0, system.constant_force,
                        system.H[:, ::d], system.b)


def per_step(run: Callable[[], object], steps: int, repeats: int) -> float:
    """Median µs per step of ``run`` over ``repeats`` timed calls after a warm-up."""
    run()
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        run()
        times.append(time.perf_counter() - start)
    return statistics.median(times) / steps * 1e6


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--steps", type=int, default=1000)
    parser.add_argument("--repeats", type=int, default=5)
    args = parser.parse_args(argv)
    t_end = args.steps * H_STEP
    print(f"µs per step, {args.steps} steps of h = {H_STEP}, median of {args.repeats}")
    print("| system | Coulomb, compiled | Coulomb, Python | Newton, compiled | Newton, Python |")
    print("|---|---|---|---|---|")
    for name, build in SYSTEMS.items():
        rough = build()
        smooth = frictionless(rough)
        runs = [partial(moreau_jean, rough, Coulomb(MU), t_end, H_STEP, compiled=True),
                partial(moreau_jean, rough, Coulomb(MU), t_end, H_STEP, compiled=False),
                partial(moreau_jean, smooth, Newton(0.0), t_end, H_STEP, compiled=True),
                partial(moreau_jean, smooth, Newton(0.0), t_end, H_STEP, compiled=False)]
        times = [per_step(run, args.steps, args.repeats) for run in runs]
        print(f"| {name} | " + " | ".join(f"{t:.2f}" for t in times) + " |")


if __name__ == "__main__":
    main()
