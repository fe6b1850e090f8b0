"""``impactqp simulate FILE``: simulate a system described in a JSON or TOML simulation file
(:mod:`impactqp.io.simulation_files`; docs/theory.md §14, §17) and report the run;
optionally save the trajectory and its energy plot.

Frictional systems (``contact_dim`` 2 or 3, law ``"coulomb"``) run with Moreau–Jean
time-stepping like the others; their saved trajectories carry the impulse components
``lambda{j}_n``, ``lambda{j}_t1``, .... Long runs show a progress bar (tqdm) on stderr when
it is a terminal.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np

from ...base.arrays import as_real
from ...base.outputs import output_file
from ...errors import ProblemFileError
from ...io.simulation_files import check_scheme, read_simulation
from ...simulation.simulate import SCHEMES, simulate
from ...simulation.trajectory import Trajectory
from ..progress import on_terminal

APPROACHING = 1e-6
"""A contact approaches at the start of a step when its normal velocity is below −APPROACHING
times the largest contact velocity of the run, normal or tangent (a resting or sliding
contact keeps a normal velocity of the order of the step's certificate tolerance, 1e-9 of
the step's free velocity)."""


class _Bar:
    """A tqdm bar over simulated time on stderr, shown only for runs longer than 2 s and only
    when ``enabled`` (the command enables it when stderr is a terminal and not ``--quiet``)."""

    def __init__(self, t0: float, t_end: float, enabled: bool) -> None:
        self.bar, self.done, self.t0 = None, 0.0, t0
        if enabled:
            try:
                from tqdm import tqdm
            except ImportError:  # the bar is a convenience, not a requirement
                return
            self.bar = tqdm(total=t_end - t0, unit="s", desc="simulating", delay=2.0,
                            file=sys.stderr, bar_format="{l_bar}{bar}| t = {n:.3g} of "
                            "{total:.3g} [{elapsed}<{remaining}]")

    def __call__(self, t: float) -> None:
        if self.bar is not None:
            self.bar.update(max(0.0, t - self.t0 - self.done))
            self.done = t - self.t0

    def close(self) -> None:
        if self.bar is not None:
            self.bar.close()


def impact_times(trajectory: Trajectory) -> list[float]:
    """The times of the run's impacts: every event of event-driven integration, and of
    time-stepping the steps where a contact closes with an impulse: approaching at the start
    of the step (normal velocity below −:data:`APPROACHING` of the run's largest contact
    velocity) and pushed by a positive normal impulse. A resting or sliding contact, closed on
    every step with zero normal velocity (docs/theory.md §14, §17), has no impact."""
    system, events = trajectory.system, trajectory.events
    d = system.contact_dim
    velocity = np.atleast_2d(np.asarray(system.H.T @ trajectory.v.T).T)  # (k, d·m)
    normal = velocity[:, ::d]
    speed = float(np.abs(velocity).max()) if velocity.size else 0.0
    times = []
    for event in events:
        if event.kind != "step":
            times.append(float(event.time))
            continue
        i = int(np.abs(trajectory.t - event.time).argmin())
        contacts = np.asarray(event.contacts, dtype=int)
        if i == 0 or contacts.size == 0:
            continue
        closing = (normal[i - 1, contacts] < -APPROACHING * speed) \
            & (trajectory.impulses[i, d * contacts] > 0)
        if closing.any():
            times.append(float(event.time))
    return times


def run(args: argparse.Namespace) -> int:
    system, law, sim = read_simulation(Path(args.file))
    for flag, key in (("scheme", "scheme"), ("t_end", "t_end"), ("h", "h")):
        if getattr(args, flag) is not None:
            sim[key] = getattr(args, flag)
    check_scheme(system, sim.get("scheme", "moreau-jean"),
                 "--scheme" if args.scheme is not None else "simulation.scheme")
    if "t_end" not in sim:
        raise ProblemFileError(f"{args.file}: [simulation] needs t_end (or pass --t-end)")
    t0, t_end = as_real("simulation.t0", sim.get("t0", 0.0)), as_real("simulation.t_end",
                                                                       sim["t_end"])
    if args.out:
        output_file(args.out)  # refused before the run, not after it
    bar = _Bar(t0, t_end, not args.quiet and on_terminal())
    try:
        trajectory = simulate(system, law, progress=bar, **sim)
    finally:
        bar.close()
    written = []
    if args.out:
        written.append(str(trajectory.save(args.out)))
    if args.energy_plot:
        from ...figures.motion import plot_energy
        written.append(str(plot_energy(trajectory, args.energy_plot)))
    if args.json:
        adm = trajectory.admissible()
        print(json.dumps({
            "scheme": trajectory.scheme, "law": repr(law), "records": int(trajectory.t.size),
            "events": len(trajectory.events), "certified": trajectory.certified,
            "admissible": int(adm.sum()), "outside_S": trajectory.outside_S(),
            "impact_times": impact_times(trajectory),
            "energy": _energy(trajectory),
            "final_state": {"q": trajectory.q[-1].tolist(), "v": trajectory.v[-1].tolist()},
            "written": written}, indent=2))
    else:
        print(trajectory.summary())
        for name in written:
            print(f"  wrote {name}")
    return 0


def _energy(trajectory: Trajectory) -> dict[str, float | None]:
    """The run's energy figures for JSON: null where one is not a float (overflow, or a
    force without potential), since JSON has no NaN or infinity."""
    with np.errstate(over="ignore", invalid="ignore"):
        E = trajectory.total_energy
        drift = trajectory.energy_drift()
    return {name: (float(value) if np.isfinite(value) else None) for name, value in
            (("initial", E[0]), ("final", E[-1]), ("largest_relative_change", drift))}


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("simulate", help="simulate a system with an impact law "
                       "(simulation file .json/.toml)")
    p.add_argument("file", help="simulation file (.json or .toml)")
    p.add_argument("--scheme", choices=SCHEMES, help="override the file's scheme")
    p.add_argument("--t-end", dest="t_end", type=float, help="override the final time")
    p.add_argument("--h", type=float, help="override the step (output interval if "
                   "event-driven)")
    p.add_argument("--out", help="save the trajectory (.npz or .csv)")
    p.add_argument("--energy-plot", dest="energy_plot", help="write the energy plot "
                   "(.png/.svg; needs matplotlib)")
    p.add_argument("--json", action="store_true", help="print the report as JSON")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    p.set_defaults(func=run)
