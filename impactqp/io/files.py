"""Problem files: an impact problem (docs/theory.md §1), optionally a law, its coefficients and a
candidate u⁺.

One flat schema, stored as JSON or TOML (chosen by the file suffix)::

    version  = 1                          # optional; 1 is the only version
    # either a general problem ...
    M        = [[1.0, 0.0], [0.0, 2.0]]   # (n, n) mass matrix
    W        = [[-1.0], [1.0]]            # (n, m·d) contact directions
    contact_dim = 1                       # optional: d = 1 frictionless (default), 2 or 3
    # ... or a chain of balls (docs/theory.md §5), frictionless
    masses     = [1.0, 1.0, 1.0]
    left_wall  = false                    # optional
    right_wall = false                    # optional
    # always
    u_minus  = [1.0, 0.0, 0.0]
    # optional
    law      = "moreau"   # "moreau" | "newton" | "fremond" | "sector" | "reflection" | "coulomb"
    eps      = 0.5                        # moreau; "e" for newton, "E" for fremond
    u_plus   = [0.0, 0.0, 1.0]            # a candidate post-impact velocity

Frictional contacts (docs/theory.md §16) have ``contact_dim = 2`` (planar) or ``3``
(spatial): W holds d columns per contact, the normal first, and the law is ``"coulomb"``
with ``mu`` (friction coefficients, required: one number ≥ 0 or one per contact) and ``e``
(Newton's restitution of the normal velocities in [0, 1], one or one per contact; default
0). ``coulomb`` on frictionless contacts and a frictionless law on frictional ones are
refused, as is a W whose column count is not a multiple of ``contact_dim``.

Reading is strict: unknown or duplicate keys, wrong types, ragged or mis-shaped arrays and
non-finite numbers are refused with a :class:`~impactqp.errors.ProblemFileError` that names
the field. Nothing is evaluated or unpickled. Only regular files are read, at most
:data:`MAX_FILE_BYTES` of them (a FIFO or a device cannot hang or exhaust memory); numbers
too large for a float and nesting too deep for the parser are refused; problems above
:data:`MAX_DOF` degrees of freedom, and general (dense) problems above
:data:`MAX_DENSE_CONTACTS` columns of W, are refused before any work is done. Writing is in
:mod:`impactqp.io.save`. (Problem structure: docs/theory.md §1, §3, §5, §16.)
"""

from __future__ import annotations

import json
import math
import stat
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from ..base.arrays import as_vector
from ..errors import InputError, ProblemFileError
from ..model.builders import chain
from ..model.problem import ImpactProblem
from .file_laws import KNOWN_COEFFICIENTS, LAWS, check_friction, read_coefficients

MAX_FILE_BYTES = 10 * 1024 * 1024
"""Largest problem file that is read (10 MB)."""

MAX_DOF = 10_000
"""Largest number of degrees of freedom (and of contacts) a problem file may declare."""

MAX_DENSE_CONTACTS = 1_000
"""Largest number of columns of W (frictionless contacts, or d per frictional contact) of a
general problem in a file: its Delassus matrix is dense (m² entries) and every solve costs
at least m³, so larger impacts belong in Python with scipy.sparse matrices, where the caller
decides what is affordable."""

VERSION = 1
CONTACT_DIMS = (1, 2, 3)
GENERAL_KEYS = ("M", "W")
CHAIN_KEYS = ("masses", "left_wall", "right_wall")
KNOWN_KEYS = ("version", *GENERAL_KEYS, "contact_dim", *CHAIN_KEYS, "u_minus", "law",
              *KNOWN_COEFFICIENTS, "u_plus")
FORMATS = {".json": "json", ".toml": "toml"}


@dataclass(frozen=True)
class ProblemFile:
    """The content of a problem file.

    Attributes
    ----------
    problem : ImpactProblem
    law : str or None
        A name of :data:`!impactqp.laws.catalogue.NAMED_LAWS` (``"moreau"``, ``"newton"``,
        ``"fremond"``, ``"sector"``, ``"reflection"``, ``"coulomb"``) or None when absent.
    coefficients : float, ndarray, tuple or None
        ε (Moreau), the eᵢ (Newton, an (m,) array), Frémond's (m, m) matrix E, or Coulomb's
        pair (μ, e): each a number or an (m,) array as the file gives it, e None when
        absent (the law's default 0).
    u_plus : ndarray or None
        A candidate post-impact velocity.
    path : Path or None
        Where it was read from.
    """

    problem: ImpactProblem
    law: str | None = None
    coefficients: float | np.ndarray | None = None
    u_plus: np.ndarray | None = None
    path: Path | None = None


def file_format(path: Path) -> str:
    """``"json"`` or ``"toml"`` from the suffix of ``path``."""
    fmt = FORMATS.get(path.suffix.lower())
    if fmt is None:
        raise ProblemFileError(f"{path}: unknown problem file suffix {path.suffix!r}; "
                               f"use one of {sorted(FORMATS)}")
    return fmt


def _toml_module():
    """tomllib (Python ≥ 3.11) or the ``tomli`` backport on 3.10."""
    try:
        import tomllib
    except ImportError:
        try:
            import tomli as tomllib
        except ImportError:
            raise ProblemFileError("reading TOML problem files on Python 3.10 needs the "
                                   "'tomli' package: pip install tomli (or use JSON)") from None
    return tomllib


def _reject_constant(name: str) -> None:
    raise ValueError(f"{name} is not a finite number")


def _no_duplicates(pairs: list[tuple[str, Any]]) -> dict[str, Any]:
    out: dict[str, Any] = {}
    for key, value in pairs:
        if key in out:
            raise ValueError(f"duplicate key {key!r}")
        out[key] = value
    return out


def _parse(text: str, fmt: str) -> Any:
    if fmt == "json":
        return json.loads(text, object_pairs_hook=_no_duplicates,
                          parse_constant=_reject_constant)
    return _toml_module().loads(text)


def _number(name: str, value: Any) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise ProblemFileError(f"{name} must be a number, got {type(value).__name__} "
                               f"{str(value)[:40]!r}")
    try:
        x = float(value)
    except OverflowError:
        raise ProblemFileError(f"{name} is too large for a floating-point number "
                               f"({len(str(value))} digits)") from None
    if not math.isfinite(x):
        raise ProblemFileError(f"{name} must be finite, got {value!r}")
    return x


def _vector(name: str, value: Any) -> np.ndarray:
    if not isinstance(value, list):
        raise ProblemFileError(f"{name} must be a list of numbers, got {type(value).__name__}")
    if len(value) > MAX_DOF:
        raise ProblemFileError(f"{name} has {len(value)} entries; problem files are limited to "
                               f"{MAX_DOF} (MAX_DOF)")
    return np.array([_number(f"{name}[{i}]", x) for i, x in enumerate(value)], dtype=float)


def _matrix(name: str, value: Any) -> np.ndarray:
    if not isinstance(value, list) or not value:
        raise ProblemFileError(f"{name} must be a non-empty list of rows (a matrix)")
    if len(value) > MAX_DOF:
        raise ProblemFileError(f"{name} has {len(value)} rows; problem files are limited to "
                               f"{MAX_DOF} (MAX_DOF)")
    rows = [_vector(f"{name}[{i}]", row) for i, row in enumerate(value)]
    widths = {r.size for r in rows}
    if len(widths) > 1:
        raise ProblemFileError(f"{name} is ragged: its rows have lengths {sorted(widths)}")
    return np.stack(rows)


def _bool(name: str, value: Any) -> bool:
    if not isinstance(value, bool):
        raise ProblemFileError(f"{name} must be true or false, got {value!r}")
    return value


def _typed_coefficients(data: dict[str, Any]) -> dict[str, Any]:
    """The coefficients present in ``data``, typed: ``E`` a matrix, ``eps`` a number, the
    others (``e``, ``mu``, the LZB model's ``stiffness`` and ``exponent``) a number or a vector
    (what they mean is checked by the law's reading)."""
    out: dict[str, Any] = {}
    for key in KNOWN_COEFFICIENTS:
        if key not in data:
            continue
        value = data[key]
        out[key] = (_matrix(key, value) if key == "E" else
                    _vector(key, value) if key != "eps" and isinstance(value, list) else
                    _number(key, value))
    return out


def _contact_dim(data: dict[str, Any]) -> int:
    value = data.get("contact_dim", 1)
    if isinstance(value, bool) or not isinstance(value, int) or value not in CONTACT_DIMS:
        raise ProblemFileError(f"contact_dim must be the integer 1 (frictionless), 2 (planar "
                               f"friction) or 3 (spatial friction), got {value!r}")
    return value


def _problem(data: dict[str, Any]) -> ImpactProblem:
    general = [k for k in GENERAL_KEYS if k in data]
    chained = [k for k in CHAIN_KEYS if k in data]
    d = _contact_dim(data)
    if general and chained:
        raise ProblemFileError(f"give either a general problem (M, W) or a chain (masses), "
                               f"not both: found {general + chained}")
    if "u_minus" not in data:
        raise ProblemFileError("missing key 'u_minus' (the pre-impact velocity)")
    u_minus = _vector("u_minus", data["u_minus"])
    if chained:
        if "masses" not in data:
            raise ProblemFileError(f"a chain needs 'masses'; found only {chained}")
        if d > 1:
            raise ProblemFileError(f"contact_dim = {d} needs a general problem (M, W with "
                                   f"{d} columns per contact); a chain's contacts are "
                                   "frictionless")
        return chain(_vector("masses", data["masses"]), u_minus,
                     left_wall=_bool("left_wall", data.get("left_wall", False)),
                     right_wall=_bool("right_wall", data.get("right_wall", False)))
    if not general:
        raise ProblemFileError("give either a general problem (keys 'M' and 'W') or a chain "
                               "(key 'masses')")
    missing = [k for k in GENERAL_KEYS if k not in data]
    if missing:
        raise ProblemFileError(f"a general problem needs 'M' and 'W'; missing {missing}")
    M, W = _matrix("M", data["M"]), _matrix("W", data["W"])
    if W.shape[1] > MAX_DENSE_CONTACTS:
        raise ProblemFileError(f"W has {W.shape[1]} columns; problem files hold general "
                               f"problems of at most {MAX_DENSE_CONTACTS} columns (frictionless "
                               "contacts, or d per frictional contact; MAX_DENSE_CONTACTS: "
                               "the Delassus matrix is dense); build "
                               "larger impacts in Python with scipy.sparse matrices")
    if W.shape[1] % d:
        raise ProblemFileError(f"W has {W.shape[1]} columns, not a multiple of contact_dim = "
                               f"{d}: give {d} columns per contact, the normal first")
    return ImpactProblem(M, W, u_minus, contact_dim=d)


def problem_from_dict(data: Any) -> ProblemFile:
    """Validate the parsed content of a problem file (see the module docstring).

    Raises
    ------
    ProblemFileError
        Naming the offending field.
    """
    if not isinstance(data, dict):
        raise ProblemFileError(f"a problem file must hold a table/object at the top level, "
                               f"got {type(data).__name__}")
    unknown = sorted(set(data) - set(KNOWN_KEYS))
    if unknown:
        raise ProblemFileError(f"unknown key(s) {unknown}; known keys are {list(KNOWN_KEYS)}")
    if "version" in data and (isinstance(data["version"], bool) or data["version"] != VERSION):
        raise ProblemFileError(f"version must be {VERSION}, got {data['version']!r}")
    law = data.get("law")
    if law is not None and law not in LAWS:
        raise ProblemFileError(f"law must be one of {list(LAWS)}, got {law!r}")
    try:
        problem = _problem(data)
        check_friction(law, problem.contact_dim)
        coefficients = read_coefficients(law, _typed_coefficients(data), problem.n_contacts)
        u_plus = (as_vector("u_plus", _vector("u_plus", data["u_plus"]), problem.n_dof)
                  if "u_plus" in data else None)
    except ProblemFileError:
        raise
    except InputError as exc:
        raise ProblemFileError(str(exc)) from exc
    return ProblemFile(problem, law, coefficients, u_plus)


def _read_capped(path: Path) -> str:
    """The text of a regular file of at most MAX_FILE_BYTES, read without following it into
    a FIFO, a device or a directory."""
    try:
        info = path.stat()
        if not stat.S_ISREG(info.st_mode):
            raise ProblemFileError(f"{path}: not a regular file")
        with path.open("rb") as handle:
            data = handle.read(MAX_FILE_BYTES + 1)
    except OSError as exc:
        raise ProblemFileError(f"{path}: cannot read: {exc.strerror or exc}") from exc
    if len(data) > MAX_FILE_BYTES:
        raise ProblemFileError(f"{path}: more than the {MAX_FILE_BYTES // 2**20} MB limit of "
                               "problem files")
    try:
        return data.decode("utf-8-sig")  # a leading byte-order mark (Windows editors) dropped
    except UnicodeDecodeError as exc:
        raise ProblemFileError(f"{path}: not UTF-8 text ({exc.reason} at byte "
                               f"{exc.start})") from None


def load_problem(path: str | Path) -> ProblemFile:
    """Read a problem file (``.json`` or ``.toml``).

    Parameters
    ----------
    path : str or Path

    Returns
    -------
    ProblemFile
        The problem, and the law, coefficients and candidate u⁺ when the file has them.

    Raises
    ------
    ProblemFileError
        Unreadable, too large, malformed or invalid; the message names the file and the field.
    """
    if not isinstance(path, (str, Path)):
        raise ProblemFileError(f"path must be a str or Path, got {type(path).__name__}")
    path = Path(path)
    fmt = file_format(path)
    text = _read_capped(path)
    try:
        parsed = _parse(text, fmt)
    except ProblemFileError:
        raise
    except RecursionError:
        raise ProblemFileError(f"{path}: nested too deeply to be a problem file") from None
    except (ValueError, OverflowError) as exc:  # JSONDecodeError, TOMLDecodeError, big ints
        raise ProblemFileError(f"{path}: not valid {fmt.upper()}: {exc}") from exc
    try:
        content = problem_from_dict(parsed)
    except ProblemFileError as exc:
        raise ProblemFileError(f"{path}: {exc}") from exc
    return ProblemFile(content.problem, content.law, content.coefficients, content.u_plus, path)
