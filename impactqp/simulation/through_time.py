"""Sensitivities of a run, as ``simulate(..., sensitivities=...)`` asks for them
(docs/theory.md §21): checked before the run, computed after it by the scheme's derivative
(:mod:`.discrete_map` for Moreau–Jean, :mod:`.friction_map` for Moreau–Jean with Coulomb
friction, :mod:`.flow` for event-driven integration)."""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

from ..errors import InputError
from ..laws.base import ImpactLaw
from .discrete_map import discrete_map
from .flow import flow
from .friction_map import frictional_map
from .sensitivity import Columns, Sensitivities, columns, full_restitution
from .system import LinearSystem


def check(system: LinearSystem, law: ImpactLaw, scheme: str, wrt: Sequence[str],
          options: dict[str, Any]) -> Columns:
    """The tangent columns of ``wrt`` for a run that can be differentiated.

    Raises
    ------
    InputError
        A law without a complementarity form (other than Coulomb's), Coulomb friction with
        event-driven integration (its flow is not differentiated), a callable force,
        Moreau–Jean with ``record_every`` > 1 (the derivative is read from every step), an
        event-driven run without its events, or an unknown name.
    """
    if law.frictional or system.contact_dim > 1:
        if scheme != "moreau-jean":
            raise InputError("sensitivities of a run with Coulomb friction are those of "
                             "Moreau–Jean's discrete map (scheme='moreau-jean'); the flow "
                             "of a frictional motion is not differentiated")
    else:
        full_restitution(law, system.n_contacts)  # raises for a law without a step form
    if system.linear_force is None and system.constant_force is None:
        raise InputError("sensitivities need a constant force or a LinearForce (c - Kq); a "
                         "callable force has no Jacobian impactqp could differentiate")
    if scheme == "moreau-jean" and options.get("record_every", 1) != 1:
        raise InputError("sensitivities of a Moreau–Jean run need record_every = 1: each "
                         "step's derivative is read from its record")
    return columns(wrt, law, system.n_dof, system.n_contacts)


def differentiate(trajectory: Any, cols: Columns) -> Sensitivities:
    """The sensitivities of a finished run: ``"discrete-map"`` or ``"flow"``."""
    tr = trajectory
    if tr.scheme == "moreau-jean" and tr.law.frictional:
        return frictional_map(tr.system, tr.law, tr.q, tr.v, tr.impulses, tr.settings, cols)
    if tr.scheme == "moreau-jean":
        return discrete_map(tr.system, tr.law, tr.q, tr.v, tr.impulses, tr.settings, cols)
    return flow(tr.system, tr.law, tr.t, tr.q, tr.v, tr.impulses, tr.settings, cols)
