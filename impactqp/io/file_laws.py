"""The law of a problem or simulation file (:mod:`impactqp.io.files`,
:mod:`impactqp.io.simulation_files`): which names and coefficient keys go together, the
coefficients read for a problem's or a system's contacts, and frictional laws on frictional
contacts only (docs/theory.md §16, §17)."""

from __future__ import annotations

from typing import Any

import numpy as np

from ..errors import ProblemFileError
from ..laws.catalogue import NAMED_LAWS
from ..laws.complementarity import check_restitution
from ..laws.moreau import check_eps
from ..model.friction import friction_coefficients

LAWS = tuple(NAMED_LAWS)
COEFFICIENT_KEYS: dict[str, tuple[str, ...]] = {
    name: law.coefficient_keys for name, law in NAMED_LAWS.items() if law.coefficient_keys}
"""The keys of each named law's coefficients, in the order of the law's coefficients."""
KNOWN_COEFFICIENTS: dict[str, tuple[str, ...]] = {
    key: tuple(name for name, keys in COEFFICIENT_KEYS.items() if key in keys)
    for key in dict.fromkeys(k for keys in COEFFICIENT_KEYS.values() for k in keys)}
"""Each coefficient key and the laws it goes with (``e``: newton and coulomb)."""


def check_friction(law: str | None, contact_dim: int, matrix: str = "W") -> None:
    """A frictional law on frictional contacts (``contact_dim`` 2 or 3), a frictionless one
    on frictionless ones (ProblemFileError otherwise, naming ``matrix``, the columns of the
    contacts: W of a problem file, H of a simulation file)."""
    if law is None:
        return
    d = contact_dim
    if NAMED_LAWS[law].frictional and d == 1:
        raise ProblemFileError(f"law {law!r} needs frictional contacts: set contact_dim = 2 "
                               f"or 3 with d columns of {matrix} per contact (for "
                               "frictionless contacts use law 'newton')")
    if not NAMED_LAWS[law].frictional and d > 1:
        frictional = [n for n, cls in NAMED_LAWS.items() if cls.frictional]
        raise ProblemFileError(f"law {law!r} acts on frictionless contacts, but contact_dim "
                               f"= {d}: use law {frictional[0]!r} (with mu), or "
                               "contact_dim = 1")


def coefficient(law: str, key: str, value: float | np.ndarray,
                m: int) -> float | np.ndarray:
    """One coefficient of ``law`` under ``key`` (already typed), checked for ``m`` contacts."""
    if key == "eps":
        return check_eps(value)
    if key == "E":
        return check_restitution("E", value, m, matrix=True)
    if key == "mu":
        friction_coefficients(value, m)
        return value
    if key in ("stiffness", "exponent"):  # the LZB model's, checked by the law itself
        return value
    if NAMED_LAWS[law].frictional:  # e of Coulomb's law: kept as the file gives it
        check_restitution(key, value, m)
        return value
    return check_restitution(key, value, m)


def read_coefficients(law: str | None, data: dict[str, Any],
                      m: int) -> float | np.ndarray | tuple | None:
    """The coefficients of ``law`` for ``m`` contacts from the typed ``data`` of a file: one
    value, or a tuple in the order of :data:`COEFFICIENT_KEYS` (an absent key None); None
    when the file gives none.

    Raises
    ------
    ProblemFileError
        A key that does not go with the law (or any key without a law).
    InputError
        A coefficient the law refuses (negative μ, e outside [0, 1], a wrong length).
    """
    given = [k for k in KNOWN_COEFFICIENTS if k in data]
    wanted = COEFFICIENT_KEYS.get(law, ()) if law else ()
    stray = [k for k in given if k not in wanted]
    if stray:
        where = f"law {law!r}" if law else "no law"
        uses = ", ".join(f"{key} with {' or '.join(laws)}"
                         for key, laws in KNOWN_COEFFICIENTS.items())
        raise ProblemFileError(f"coefficient {stray[0]!r} does not fit {where}; {uses}")
    if not wanted:
        return None
    values = tuple(coefficient(law, k, data[k], m) if k in data else None for k in wanted)
    if len(values) == 1:
        return values[0]
    return None if all(v is None for v in values) else values
