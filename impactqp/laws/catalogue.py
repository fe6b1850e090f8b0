"""The laws impactqp ships: the one table of law names (files, the command line and
simulations read a law's name through :func:`law_named`), and which law each registered
backend serves (the laws × backends table of the README is generated from here, and a test
compares the two)."""

from __future__ import annotations

from typing import Any

from ..errors import InputError
from ..qp import backends
from ..qp.certified import FAST_PATHS
from .base import ImpactLaw
from .complementarity import Fremond, Newton
from .coulomb import Coulomb
from .lzb import LZB
from .moreau import Moreau
from .reflection import ReflectionLaw
from .sector import SectorLaw

LAWS: tuple[type[ImpactLaw], ...] = (Moreau, Newton, Fremond, SectorLaw, ReflectionLaw, LZB)
"""The law classes impactqp ships for frictionless contacts (the columns of the backend
table)."""

FRICTIONAL_LAWS: tuple[type[ImpactLaw], ...] = (Coulomb,)
"""The law classes impactqp ships for frictional contacts (docs/theory.md §16): solved
through their local problem (form ``"friction"``) by the registry's friction methods, as
:func:`~impactqp.solve_friction` solves it."""

NAMED_LAWS: dict[str, type[ImpactLaw]] = {law.name: law for law in (*LAWS, *FRICTIONAL_LAWS)
                                          if law.by_name}
"""The laws that problem and simulation files and the command line name, by name: the one
table every reader of a law's name uses."""


def law_named(name: object, coefficients: Any = None) -> ImpactLaw:
    """The law called ``name`` in a file or on the command line, with its coefficients.

    Raises
    ------
    InputError
        An unknown name, missing coefficients of a law that needs them, or coefficients the
        law refuses (its own errors, e.g. RestitutionError).
    """
    law = NAMED_LAWS.get(name) if isinstance(name, str) else None
    if law is None:
        raise InputError(f"law must be one of {list(NAMED_LAWS)}, got {name!r}")
    return law.from_coefficients(coefficients)


def laws_served(entry: backends.Backend) -> dict[str, tuple[str, ...]]:
    """For each shipped law, the forms in which ``entry`` can solve it (empty: not at all)."""
    return {law.name: tuple(f for f in law.forms if f in entry.forms)
            for law in (*LAWS, *FRICTIONAL_LAWS)}


def available_backends() -> list[dict]:
    """Every registered backend: whether it is installed, the program forms and laws it
    serves, and what it is for.

    Returns
    -------
    list of dict
        Keys ``name``, ``installed``, ``forms``, ``exact``, ``serves``, ``install`` and
        ``laws`` (law name → forms served, empty when the law is out of its reach). Closed-
        form laws (sector, reflection, LZB) are evaluated by ``"auto"`` only.
    """
    out = []
    for item in backends.available_backends():
        entry = backends.REGISTRY[item["name"]]
        out.append({**item, "laws": laws_served(entry), "fast_path": entry.name in FAST_PATHS})
    return out


def backend_table() -> str:
    """The laws × backends table in Markdown (what the README shows)."""
    names = [law.name for law in (*LAWS, *FRICTIONAL_LAWS)]
    head = "| backend | " + " | ".join(names) + " | serves |"
    rows = [head, "|" + "---|" * (len(names) + 2)]
    rows.append("| `\"auto\"` | " + " | ".join("✓" for _ in names)
                + " | fast path if one applies, else QP backends (friction methods for "
                "Coulomb), falling back on failure |")
    for item in available_backends():
        cells = []
        for name in names:
            forms = item["laws"][name]
            cells.append(", ".join(f[0] for f in forms) if forms else "–")
        rows.append(f"| `\"{item['name']}\"` | " + " | ".join(cells) + f" | {item['serves']} |")
    return "\n".join(rows)
