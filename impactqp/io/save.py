"""Writing problem files in the flat schema of :mod:`impactqp.io.files` (JSON or TOML).

TOML is written here, scalars by ``tomli_w`` and floats as their shortest ``repr`` (which
round-trips exactly), with each array on one line where it fits in :data:`TOML_LINE`
characters, a matrix one row a line otherwise, and a long vector wrapped; JSON by the
standard library. Every file is validated by
:func:`impactqp.io.files.problem_from_dict` before it is written.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np
import tomli_w

from ..base.arrays import as_dense
from ..base.outputs import atomic_output, output_file
from ..errors import InputError
from ..model.problem import ImpactProblem
from .file_laws import COEFFICIENT_KEYS
from .files import VERSION, file_format, problem_from_dict


def _coefficient_entries(law: str | None, coefficients: Any) -> dict[str, Any]:
    """The file keys of ``law``'s coefficients: one value, or a tuple in the order of
    :data:`~impactqp.io.file_laws.COEFFICIENT_KEYS` (Coulomb's (μ, e), an entry None left out)."""
    keys = COEFFICIENT_KEYS.get(law, ()) if law else ()
    if not keys:
        raise InputError(f"coefficients need a law among {list(COEFFICIENT_KEYS)}, "
                         f"got law={law!r}")
    if len(keys) == 1:
        values = (coefficients,)
    elif isinstance(coefficients, (tuple, list)) and len(coefficients) == len(keys):
        values = tuple(coefficients)
    else:
        raise InputError(f"law {law!r} takes its coefficients as a pair "
                         f"({', '.join(keys)}), got {coefficients!r}")
    return {key: _numbers(key, value)
            for key, value in zip(keys, values, strict=True) if value is not None}


def _numbers(key: str, value: Any) -> Any:
    """A coefficient as a number or (nested) lists of numbers, or InputError naming it."""
    try:
        return np.asarray(value, dtype=float).tolist()
    except (TypeError, ValueError):
        raise InputError(f"coefficient {key!r} must be a number or an array of numbers, got "
                         f"{value!r}") from None


def problem_to_dict(problem: ImpactProblem, *, law: str | None = None, coefficients: Any = None,
                    u_plus: Any = None) -> dict[str, Any]:
    """The file content of a problem as plain lists and numbers (validated by a re-read).
    Frictional problems (``contact_dim`` 2 or 3, docs/theory.md §16) are written with their
    ``contact_dim`` and dense M and W."""
    data: dict[str, Any] = {"version": VERSION}
    info = problem.chain
    if info is not None and problem.contact_dim == 1:
        data["masses"] = info.masses.tolist()
        data.update(left_wall=info.left_wall, right_wall=info.right_wall)
    else:
        data.update(M=as_dense(problem.M).tolist(), W=as_dense(problem.W).tolist())
        if problem.contact_dim > 1:
            data["contact_dim"] = problem.contact_dim
    data["u_minus"] = problem.u_minus.tolist()
    if law is not None:
        data["law"] = law
    if coefficients is not None:
        data.update(_coefficient_entries(law, coefficients))
    if u_plus is not None:
        data["u_plus"] = np.asarray(u_plus, dtype=float).tolist()
    problem_from_dict(data)  # refuse to write what could not be read back
    return data


TOML_LINE = 100
"""Longest line of a TOML file written here, where the numbers allow it."""


def _toml_scalar(value: Any) -> str:
    if isinstance(value, float) and np.isfinite(value):
        return repr(value)  # what tomli_w writes, without a call per number
    return tomli_w.dumps({"v": value})[len("v = "):].rstrip("\n")


def _toml_inline(value: Any) -> str:
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(_toml_inline(v) for v in value) + "]"
    return _toml_scalar(value)


def _toml_entry(key: str, value: Any) -> list[str]:
    """The lines of ``key = value``: one where it fits, else a matrix one row a line or a
    vector wrapped at :data:`TOML_LINE` characters."""
    one = f"{key} = {_toml_inline(value)}"
    if len(one) <= TOML_LINE or not isinstance(value, (list, tuple)) or not value:
        return [one]
    if all(isinstance(v, (list, tuple)) for v in value):
        return [f"{key} = [", *(f"    {_toml_inline(row)}," for row in value), "]"]
    lines, line = [f"{key} = ["], "   "
    for item in (_toml_inline(v) for v in value):
        if len(line) + len(item) + 2 > TOML_LINE and line.strip():
            lines.append(line)
            line = "   "
        line += f" {item},"
    return [*lines, line, "]"]


def to_toml(data: dict[str, Any]) -> str:
    """TOML text of the flat schema (top-level keys with numbers, booleans, strings and
    nested arrays of numbers): each array on one line where it fits in :data:`TOML_LINE`
    characters, a matrix one row a line otherwise, a long vector several numbers a line.

    Parameters
    ----------
    data : dict
        The file content, as returned by :func:`problem_to_dict`.

    Returns
    -------
    str
        TOML text that :func:`impactqp.load_problem` reads back bit-exactly.
    """
    bare = set("ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789_-")
    lines = []
    for key, value in data.items():
        name = key if key and set(key) <= bare else tomli_w.dumps({key: 0}).split(" = ")[0]
        lines += _toml_entry(name, value)
    return "\n".join(lines) + "\n"


def to_json(data: dict[str, Any]) -> str:
    """JSON text with one top-level key per line (matrices stay on one line each)."""
    return "{\n" + ",\n".join(f" {json.dumps(k)}: {json.dumps(v)}" for k, v in data.items()) \
        + "\n}\n"


def save_problem(problem: ImpactProblem, path: str | Path, *, law: str | None = None,
                 coefficients: Any = None, u_plus: Any = None) -> Path:
    """Write a problem file; the format follows the suffix (``.json`` or ``.toml``).

    Chains are written as chains (masses and walls), every other problem as dense M and W
    (with ``contact_dim`` for frictional contacts).

    Parameters
    ----------
    problem : ImpactProblem
    path : str or Path
    law : {"moreau", "newton", "fremond", "sector", "reflection", "coulomb"}, optional
    coefficients : float, array_like or tuple, optional
        ε, the eᵢ or E of ``law``; for ``"coulomb"`` the pair (μ, e) (``law.coefficients``
        of an :class:`~impactqp.Coulomb`), each one number or one per contact.
    u_plus : (n,) array_like, optional
        A candidate post-impact velocity.

    Returns
    -------
    Path
        The path written.
    """
    path = output_file(path)
    fmt = file_format(path)
    data = problem_to_dict(problem, law=law, coefficients=coefficients, u_plus=u_plus)
    text = to_json(data) if fmt == "json" else to_toml(data)
    with atomic_output(path) as temp:
        temp.write_text(text, encoding="utf-8")
    return path
