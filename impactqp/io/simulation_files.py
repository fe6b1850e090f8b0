"""Simulation files: a system with unilateral contacts, an impact law and the arguments of
:func:`~impactqp.simulate` (docs/theory.md §14, §17), read by ``impactqp simulate``.

Three tables, stored as JSON or TOML (chosen by the file suffix)::

    version = 1                      # optional
    [system]
    kind = "cradle"                  # "bouncing_ball" | "cradle" | "bead_chain" |
                                     # "rolling_sphere" | "block_on_incline" |
                                     # "box_on_floor" | "linear"
    n_balls = 5                      # the builder's own arguments (cradle_system, ...);
    amplitude = 0.1                  # "linear": M, q0, v0, force, stiffness, H, b,
                                     # contact_dim, coordinates (names, for figures)
                                     # and coordinate_kinds ("translation" | "rotation"
                                     # | "generalized", one per name)
    [law]
    name = "sector"                  # "moreau" (eps) | "newton" (e) | "fremond" (E) |
                                     # "sector" | "reflection" | "coulomb" (mu, e)
    [simulation]
    scheme = "event-driven"          # or "moreau-jean"
    t_end = 4.0
    h = 0.01                         # optional; also theta, t0, backend and the options of
                                     # iq.simulate (rest_velocity, gap_tol, record_every, ...)

Frictional systems (docs/theory.md §17): a ``"linear"`` system with ``contact_dim = 2`` or
``3`` has d columns of H per contact, the normal first, and one gap offset in b per contact;
the builders ``rolling_sphere``, ``block_on_incline`` and ``box_on_floor`` make frictional
systems. Their law is ``"coulomb"`` with ``mu`` (required) and ``e`` (default 0), read as in
problem files (:mod:`impactqp.io.file_laws`), and their scheme ``"moreau-jean"``.

Reading is strict: unknown keys, wrong types, malformed arrays, a law that does not fit the
system's contacts and friction with the event-driven scheme raise a
:class:`~impactqp.errors.ProblemFileError` naming the field.
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import InputError, ProblemFileError
from ..laws.base import ImpactLaw
from ..laws.catalogue import NAMED_LAWS, law_named
from ..simulation.builders import (
    bead_chain,
    block_on_incline,
    bouncing_ball,
    box_on_floor,
    cradle_system,
    rolling_sphere,
)
from ..simulation.simulate import SCHEMES
from ..simulation.system import LinearForce, LinearSystem
from .file_laws import COEFFICIENT_KEYS, KNOWN_COEFFICIENTS, check_friction, read_coefficients

MAX_FILE_BYTES = 10 * 1024 * 1024
"""Largest simulation file that is read (10 MB)."""

MAX_COUNT = 100_000
"""Largest number of balls or beads a simulation file may ask for."""

INTEGERS = ("n_balls", "n_beads", "released", "record_every", "max_events")
CHOICES = {"contact_dim": (1, 2, 3), "dim": (2, 3)}
"""Whole-number keys that take one of a few values: columns of H per contact of a linear
system, dimension of a frictional builder's space."""
BUILDERS = {
    "bouncing_ball": bouncing_ball, "cradle": cradle_system, "bead_chain": bead_chain,
    "rolling_sphere": rolling_sphere, "block_on_incline": block_on_incline,
    "box_on_floor": box_on_floor,
}
SYSTEMS = {
    "bouncing_ball": ("mass", "q0", "v0", "gravity", "radius"),
    "cradle": ("n_balls", "mass", "length", "gravity", "amplitude", "released"),
    "bead_chain": ("n_beads", "mass", "radius", "height", "spacing", "gravity", "velocity"),
    "rolling_sphere": ("mass", "radius", "gravity", "velocity", "spin", "height",
                       "vertical_velocity", "gap"),
    "block_on_incline": ("angle", "mass", "gravity", "dim", "position", "speed", "gap",
                         "normal_speed", "twist"),
    "box_on_floor": ("dim", "mass", "half_sizes", "gravity", "velocity", "gap"),
    "linear": ("M", "q0", "v0", "force", "stiffness", "H", "b", "contact_dim", "coordinates",
               "coordinate_kinds"),
}
"""Each system kind and its keys: a builder's arguments, or the matrices of LinearSystem."""
NAMES = ("coordinates", "coordinate_kinds")
"""Keys that hold a list of strings."""
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
    if key in NAMES:
        if not isinstance(value, list) or not all(isinstance(x, str) for x in value):
            raise ProblemFileError(f"{name} must be a list of strings, got {value!r}")
        return value
    if key in CHOICES:
        if isinstance(value, bool) or not isinstance(value, int) or value not in CHOICES[key]:
            raise ProblemFileError(f"{name} must be one of the integers {CHOICES[key]}, "
                                   f"got {value!r}")
        return value
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


def _parse(path: Path) -> Any:
    if path.suffix.lower() not in (".json", ".toml"):
        raise ProblemFileError(f"{path}: a simulation file ends in .json or .toml")
    try:
        if not path.is_file() or path.stat().st_size > MAX_FILE_BYTES:
            raise ProblemFileError(f"{path}: not a regular file of at most 10 MB")
        text = path.read_text(encoding="utf-8-sig")  # a leading byte-order mark dropped
        if path.suffix.lower() == ".toml":
            try:
                import tomllib
            except ImportError:  # Python 3.10: the tomli backport (a dependency there)
                import tomli as tomllib
            return tomllib.loads(text)

        def unique(pairs: list) -> dict:
            if len({k for k, _ in pairs}) != len(pairs):
                raise ValueError("duplicate key")
            return dict(pairs)
        return json.loads(text, object_pairs_hook=unique)
    except (OSError, UnicodeDecodeError, ValueError, RecursionError) as exc:
        raise ProblemFileError(f"{path}: cannot read it: {exc}") from None


def read_simulation(path: Path) -> tuple[LinearSystem, ImpactLaw, dict[str, Any]]:
    """(system, law, keyword arguments of :func:`~impactqp.simulate`) from a simulation file.

    Raises
    ------
    ProblemFileError
        Unreadable, malformed or invalid content, naming the file and the field.
    """
    data = _parse(path)
    try:
        return _content(data)
    except ProblemFileError as exc:
        raise ProblemFileError(f"{path}: {exc}") from None
    except InputError as exc:
        raise ProblemFileError(f"{path}: {exc}") from exc


def check_scheme(system: LinearSystem, scheme: Any, where: str = "simulation.scheme") -> None:
    """ProblemFileError, naming ``where`` (the file's key or a command-line option), for an
    unknown scheme, or for the event-driven scheme on a system with friction columns (only
    Moreau–Jean time-stepping has friction, docs/theory.md §17)."""
    if scheme not in SCHEMES:
        raise ProblemFileError(f"{where} must be one of {SCHEMES}, got {scheme!r}")
    if scheme != "moreau-jean" and system.contact_dim > 1:
        raise ProblemFileError(f"{where} = {scheme!r} has no friction, and the "
                               f"system has contact_dim = {system.contact_dim}: simulate it "
                               "with scheme = 'moreau-jean'")


def _content(data: Any) -> tuple[LinearSystem, ImpactLaw, dict[str, Any]]:
    top = _table(data, "the file", ("version", "system", "law", "simulation"))
    if top.get("version", 1) != 1 or isinstance(top.get("version"), bool):
        raise ProblemFileError(f"version must be 1, got {top['version']!r}")
    for key in ("system", "law", "simulation"):
        if key not in top:
            raise ProblemFileError(f"missing table [{key}]")
    try:
        system = _system(top["system"])
    except ProblemFileError:
        raise
    except InputError as exc:
        raise ProblemFileError(f"[system]: {exc}") from exc
    try:
        law = _law(top["law"], system)
    except ProblemFileError:
        raise
    except InputError as exc:
        raise ProblemFileError(f"[law]: {exc}") from exc
    sim = {k: _value(f"simulation.{k}", v) for k, v in
           _table(top["simulation"], "[simulation]", SIMULATION).items()}
    if "t_end" not in sim:
        raise ProblemFileError("[simulation] needs t_end")
    check_scheme(system, sim.get("scheme", "moreau-jean"))
    return system, law, sim


def _system(data: Any) -> LinearSystem:
    kind = data.get("kind") if isinstance(data, dict) else None
    if kind not in SYSTEMS:
        raise ProblemFileError(f"system.kind must be one of {list(SYSTEMS)}, got {kind!r}")
    table = _table(data, "[system]", ("kind", *SYSTEMS[kind]))
    args = {k: _value(f"system.{k}", v) for k, v in table.items() if k != "kind"}
    if kind in BUILDERS:
        return BUILDERS[kind](**args)
    missing = [k for k in ("M", "q0", "v0") if k not in args]
    if missing:
        raise ProblemFileError(f"a linear system needs M, q0 and v0; missing {missing}")
    d = args.get("contact_dim", 1)
    H = args.get("H")
    if H is not None and np.ndim(H) == 2 and H.shape[1] % d:
        raise ProblemFileError(f"system.H has {H.shape[1]} columns, not a multiple of "
                               f"system.contact_dim = {d}: give {d} columns per contact, "
                               "the normal first")
    force = args.get("force")
    if "stiffness" in args:
        force = LinearForce(args["stiffness"], force)
    names, kinds = args.get("coordinates"), args.get("coordinate_kinds")
    if kinds is not None:
        if names is None or len(kinds) != len(names):
            raise ProblemFileError("system.coordinate_kinds needs system.coordinates, one kind "
                                   "per name")
        names = list(zip(names, kinds))
    return LinearSystem(args["M"], args["q0"], args["v0"], force, H, args.get("b"),
                        contact_dim=d, coordinates=names)


def _law(data: Any, system: LinearSystem) -> ImpactLaw:
    """The law of the file for ``system``: its name fits the system's contacts and its
    coefficients are read as a problem file's (:func:`~.file_laws.read_coefficients`)."""
    name = data.get("name") if isinstance(data, dict) else None
    if name not in NAMED_LAWS:
        raise ProblemFileError(f"law.name must be one of {list(NAMED_LAWS)}, got {name!r}")
    table = _table(data, "[law]", ("name", *KNOWN_COEFFICIENTS))
    keys = COEFFICIENT_KEYS.get(name, ())
    if keys and keys[0] not in table:
        raise ProblemFileError(f"law {name!r} needs its coefficient {keys[0]!r}")
    check_friction(name, system.contact_dim, matrix="H")
    typed = {}
    for key in KNOWN_COEFFICIENTS:
        if key in table:
            value = _value(f"law.{key}", table[key])
            if isinstance(value, (bool, str)):
                raise ProblemFileError(f"law.{key} must be a number or an array of numbers, "
                                       f"got {value!r}")
            typed[key] = value
    return law_named(name, read_coefficients(name, typed, system.n_contacts))
