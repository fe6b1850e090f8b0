"""Which Moreau–Jean loop runs a simulation (docs/theory.md §14, §17): the loop of the
:class:`~impactqp.laws.planner.Route` that :func:`impactqp.laws.planner.plan` gives the
system's structure and the law. A frictional law (``law.frictional``) on a system with
friction columns takes the compiled frictional loop where it fits and the Python frictional
loop otherwise; a law of a compiled family (``law.family``) takes the compiled loop where
:func:`compiled_applies` says so; every other run takes the Python loop. The combinations no
loop takes are refused by name."""

from __future__ import annotations

import numpy as np

from ..errors import InputError
from ..laws.base import ImpactLaw
from ..laws.planner import Route, Stepping, loop_fits, plan
from ..model.problem import ImpactProblem
from .friction_step import NEEDS_TANGENTS, check_friction_backend, step_backend
from .system import LinearSystem


def _stepping(system: LinearSystem, compiled: bool | None = None) -> Stepping:
    return Stepping(system.constant_force is not None or system.linear_force is not None,
                    compiled)


def _structure(system: LinearSystem) -> ImpactProblem:
    """The system's structure as the planner takes it (u⁻ unused)."""
    return ImpactProblem.from_structure(system.structure, np.zeros(system.n_dof))


def compiled_applies(system: LinearSystem, law: ImpactLaw, backend: str) -> bool:
    """Whether a run of a frictionless law takes the compiled loop (the rule of
    :mod:`.time_stepping`): a law of a compiled family (``law.family``: Moreau's, Newton's or
    Frémond's law, declared per class), a constant or linear force, ``backend="auto"``, a
    dense system (M and H not scipy.sparse) with at least one contact and at most
    :data:`~impactqp.laws.planner.MAX_COMPILED_LOOP` degrees of freedom and contacts."""
    return (not law.frictional and system.contact_dim == 1
            and plan(_structure(system), law, backend, mode="run",
                     stepping=_stepping(system)).path == "compiled")


def check_frictionless(system: LinearSystem, law: ImpactLaw, scheme: str) -> None:
    """InputError, naming ``scheme``, for a frictional law or a system with friction
    columns: only Moreau–Jean time-stepping has friction."""
    if law.frictional or system.contact_dim > 1:
        raise InputError(f"scheme={scheme!r} has no Coulomb friction: simulate frictional "
                         "systems with scheme='moreau-jean'")


def friction_compiled_applies(system: LinearSystem, backend: str) -> bool:
    """Whether a frictional run with the method ``backend`` of its local problem takes the
    compiled frictional loop (:func:`~impactqp.laws.planner.loop_fits`): ``backend="auto"``,
    a constant or linear force, a dense system with at most
    :data:`~impactqp.laws.planner.MAX_COMPILED_LOOP` degrees of freedom and contact rows."""
    return loop_fits(_structure(system), backend, _stepping(system))


def plan_run(system: LinearSystem, law: ImpactLaw, backend: str,
             compiled: bool | None = None) -> Route:
    """The :class:`~impactqp.laws.planner.Route` of a Moreau–Jean run (mode ``"run"``, its
    loop in ``path``).

    Raises
    ------
    InputError
        A frictional law on a frictionless system (``contact_dim`` 1) or with a backend
        solve_friction does not take; another law on a frictional system; ``compiled=True``
        for a run no compiled loop takes.
    """
    if law.frictional != (system.contact_dim > 1):
        if law.frictional:
            raise InputError(NEEDS_TANGENTS)
        raise InputError(f"a system with contact_dim = {system.contact_dim} has friction "
                         f"columns: simulate it with iq.Coulomb(mu, restitution), or build "
                         f"it with contact_dim=1 from the normal columns for {law!r}")
    if law.frictional:
        backend = check_friction_backend(step_backend(law, backend))
    return plan(_structure(system), law, backend, mode="run",
                stepping=_stepping(system, compiled))


def route(system: LinearSystem, law: ImpactLaw, backend: str, compiled: bool | None) -> str:
    """Which loop runs (the rule of :mod:`.time_stepping`): ``"friction-compiled"``,
    ``"friction"``, ``"compiled"`` or ``"python"``, the path of :func:`plan_run`."""
    return plan_run(system, law, backend, compiled).path
