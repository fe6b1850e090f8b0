"""``impactqp simulate FILE``: simulate a system described in a JSON or TOML file
(docs/theory.md §14) and report the run; optionally save the trajectory and its energy plot.

A simulation file has three tables::

    version = 1                      # optional
    [system]
    kind = "cradle"                  # "bouncing_ball" | "cradle" | "bead_chain" | "linear"
    n_balls = 5                      # the builder's own arguments (iq.cradle_system, ...);
    amplitude = 0.1                  # "linear": M, q0, v0, force, stiffness, H, b
    [law]
    name = "sector"                  # "moreau" (eps) | "newton" (e) | "fremond" (E) |
                                     # "sector" | "reflection"
    [simulation]
    scheme = "event-driven"          # or "moreau-jean"
    t_end = 4.0
    h = 0.01                         # optional; also theta, t0, backend and the options of
                                     # iq.simulate (rest_velocity, gap_tol, record_every, ...)

Reading is strict: unknown keys, wrong types and malformed arrays raise a
:class:`~impactqp.errors.ProblemFileError` naming the field. Long runs show a progress bar
(tqdm) on stderr.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from pathlib import Path
from typing import Any

import numpy as np

from ...base.arrays import as_real
from ...base.outputs import output_file
from ...errors import InputError, ProblemFileError
from ...laws.base import ImpactLaw
from ...laws.catalogue import NAMED_LAWS, law_named
from ...simulation.builders import bead_chain, bouncing_ball, cradle_system
from ...simulation.simulate import SCHEMES, simulate
from ...simulation.system import LinearForce, LinearSystem

MAX_FILE_BYTES = 10 * 1024 * 1024
MAX_COUNT = 100_000
"""Largest number of balls or beads a simulation file may ask for."""

INTEGERS = ("n_balls", "n_beads", "released", "record_every", "max_events")
SYSTEMS = {
    "bouncing_ball": ("mass", "q0", "v0", "gravity", "radius"),
    "cradle": ("n_balls", "mass", "length", "gravity", "amplitude", "released"),
    "bead_chain": ("n_beads", "mass", "radius", "height", "spacing", "gravity", "velocity"),
    "linear": ("M", "q0", "v0", "force", "stiffness", "H", "b"),
}
LAWS = {name: law.coefficient_key for name, law in NAMED_LAWS.items() if not law.frictional}
"""The laws a simulation file names: frictionless ones (its systems have no frictional
contacts yet)."""
SIMULATION = ("scheme", "t_end", "h", "theta", "t0", "backend", "record_every", "keep_events",
              "gap_tol", "rest_velocity", "method", "rtol", "atol", "max_events")


def _table(data: Any, name: str, known: tuple[str, ...]) -> dict[str, Any]:
    if not isinstance(data, dict):
        raise ProblemFileError(f"{name} must be a table, got {type(data).__name__}")
    unknown = sorted(set(data) - set(known))
    if unknown:
        raise ProblemFileError(f"unknown key(s) {unknown} in {name}; known: {list(known)}")
    return data


def _value(name: str, value: Any) -> Any:
    """A number, a bool, a string or a rectangular array of numbers, checked for its kind."""
    key = name.rsplit(".", 1)[-1]
    if key in INTEGERS:
        if isinstance(value, bool) or not isinstance(value, int) or not 0 < value <= MAX_COUNT:
            raise ProblemFileError(f"{name} must be a whole number in [1, {MAX_COUNT}], "
                                   f"got {value!r}")
        return value
    if isinstance(value, (bool, str)):
        return value
    if isinstance(value, (int, float)):
        if not math.isfinite(float(value)):
            raise ProblemFileError(f"{name} must be finite, got {value!r}")
        return float(value)
    if isinstance(value, list):
        try:
            arr = np.array(value, dtype=float)
        except (TypeError, ValueError):
            raise ProblemFileError(f"{name} must be a rectangular array of numbers") from None
        if not np.all(np.isfinite(arr)) or any(
                isinstance(x, bool) for x in np.asarray(value, dtype=object).ravel()):
            raise ProblemFileError(f"{name} must hold finite numbers (not booleans)")
        return arr
    raise ProblemFileError(f"{name} has an unsupported type {type(value).__name__}")


def read_simulation(path: Path) -> tuple[LinearSystem, ImpactLaw, dict[str, Any]]:
    """(system, law, keyword arguments of :func:`simulate`) from a simulation file.

    Raises
    ------
    ProblemFileError
        Unreadable, malformed or invalid content, naming the file and the field.
    """
    if path.suffix.lower() not in (".json", ".toml"):
        raise ProblemFileError(f"{path}: a simulation file ends in .json or .toml")
    try:
        if not path.is_file() or path.stat().st_size > MAX_FILE_BYTES:
            raise ProblemFileError(f"{path}: not a regular file of at most 10 MB")
        text = path.read_text(encoding="utf-8")
        if path.suffix.lower() == ".toml":
            try:
                import tomllib
            except ImportError:  # Python 3.10: the tomli backport (a dependency there)
                import tomli as tomllib
            data = tomllib.loads(text)
        else:
            def unique(pairs: list) -> dict:
                if len({k for k, _ in pairs}) != len(pairs):
                    raise ValueError("duplicate key")
                return dict(pairs)
            data = json.loads(text, object_pairs_hook=unique)
    except (OSError, UnicodeDecodeError, ValueError, RecursionError) as exc:
        raise ProblemFileError(f"{path}: cannot read it: {exc}") from None
    try:
        return _content(data)
    except ProblemFileError as exc:
        raise ProblemFileError(f"{path}: {exc}") from None
    except InputError as exc:
        raise ProblemFileError(f"{path}: {exc}") from exc


def _content(data: Any) -> tuple[LinearSystem, ImpactLaw, dict[str, Any]]:
    top = _table(data, "the file", ("version", "system", "law", "simulation"))
    if top.get("version", 1) != 1 or isinstance(top.get("version"), bool):
        raise ProblemFileError(f"version must be 1, got {top['version']!r}")
    for key in ("system", "law", "simulation"):
        if key not in top:
            raise ProblemFileError(f"missing table [{key}]")
    system = _system(top["system"])
    law = _law(top["law"])
    sim = {k: _value(f"simulation.{k}", v) for k, v in
           _table(top["simulation"], "[simulation]", SIMULATION).items()}
    if "t_end" not in sim:
        raise ProblemFileError("[simulation] needs t_end")
    return system, law, sim


def _system(data: Any) -> LinearSystem:
    kind = data.get("kind") if isinstance(data, dict) else None
    if kind not in SYSTEMS:
        raise ProblemFileError(f"system.kind must be one of {list(SYSTEMS)}, got {kind!r}")
    table = _table(data, "[system]", ("kind", *SYSTEMS[kind]))
    args = {k: _value(f"system.{k}", v) for k, v in table.items() if k != "kind"}
    if kind == "bouncing_ball":
        return bouncing_ball(**args)
    if kind == "cradle":
        return cradle_system(**args)
    if kind == "bead_chain":
        return bead_chain(**args)
    missing = [k for k in ("M", "q0", "v0") if k not in args]
    if missing:
        raise ProblemFileError(f"a linear system needs M, q0 and v0; missing {missing}")
    force = args.get("force")
    if "stiffness" in args:
        force = LinearForce(args["stiffness"], force)
    return LinearSystem(args["M"], args["q0"], args["v0"], force, args.get("H"), args.get("b"))


def _law(data: Any) -> ImpactLaw:
    name = data.get("name") if isinstance(data, dict) else None
    if name not in LAWS:
        raise ProblemFileError(f"law.name must be one of {list(LAWS)}, got {name!r}")
    coefficient = LAWS[name]
    table = _table(data, "[law]", ("name",) + ((coefficient,) if coefficient else ()))
    if coefficient and coefficient not in table:
        raise ProblemFileError(f"law {name!r} needs its coefficient {coefficient!r}")
    value = _value(f"law.{coefficient}", table[coefficient]) if coefficient else None
    return law_named(name, value)


class _Bar:
    """A tqdm bar over simulated time on stderr, shown only for runs longer than 2 s."""

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


def run(args: argparse.Namespace) -> int:
    system, law, sim = read_simulation(Path(args.file))
    for flag, key in (("scheme", "scheme"), ("t_end", "t_end"), ("h", "h")):
        if getattr(args, flag) is not None:
            sim[key] = getattr(args, flag)
    if sim.get("scheme", "moreau-jean") not in SCHEMES:
        raise ProblemFileError(f"simulation.scheme must be one of {SCHEMES}, got "
                               f"{sim['scheme']!r}")
    if "t_end" not in sim:
        raise ProblemFileError(f"{args.file}: [simulation] needs t_end (or pass --t-end)")
    t0, t_end = as_real("simulation.t0", sim.get("t0", 0.0)), as_real("simulation.t_end",
                                                                       sim["t_end"])
    if args.out:
        output_file(args.out)  # refused before the run, not after it
    bar = _Bar(t0, t_end, not args.quiet)
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
            "admissible": int(adm.sum()), "impact_times": trajectory.impact_times.tolist(),
            "energy": {"initial": float(trajectory.total_energy[0]),
                       "final": float(trajectory.total_energy[-1]),
                       "largest_relative_change": trajectory.energy_drift()},
            "final_state": {"q": trajectory.q[-1].tolist(), "v": trajectory.v[-1].tolist()},
            "written": written}, indent=2))
    else:
        print(trajectory.summary())
        for name in written:
            print(f"  wrote {name}")
    return 0


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
