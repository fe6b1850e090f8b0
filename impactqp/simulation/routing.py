"""Which Moreau–Jean loop runs a simulation (docs/theory.md §14, §17): for Coulomb's law on
a system with friction columns, the compiled frictional loop where
:func:`friction_compiled_applies` says so and the Python frictional loop otherwise; for the
other laws, the compiled loop for the runs :func:`compiled_applies` accepts and the Python
loop for every other run; the combinations no loop takes are refused by name."""

from __future__ import annotations

from ..errors import InputError
from ..laws.base import ImpactLaw
from ..laws.complementarity import Fremond, Newton
from ..laws.coulomb import Coulomb
from ..laws.moreau import Moreau
from .friction_step import NEEDS_TANGENTS, check_friction_backend, step_backend
from .system import LinearSystem

COMPILED_LAWS = (Moreau, Newton, Fremond)
"""The laws the compiled loop takes, by exact type (a subclass may change the law)."""

MAX_COMPILED = 400
"""Most degrees of freedom and most contacts the compiled loop takes (it holds Ŵ⁻¹, Ŵ⁻¹H
and HᵀŴ⁻¹H dense)."""


def compiled_applies(system: LinearSystem, law: ImpactLaw, backend: str) -> bool:
    """Whether a run takes the compiled loop (the rule of :mod:`.time_stepping`): Moreau's,
    Newton's or Frémond's law (exact types), a constant or linear force, ``backend="auto"``,
    a dense system (M and H not scipy.sparse) with at least one contact and at most
    :data:`MAX_COMPILED` degrees of freedom and contacts."""
    return (backend == "auto" and type(law) in COMPILED_LAWS and not system.structure.sparse
            and (system.constant_force is not None or system.linear_force is not None)
            and 0 < system.n_contacts <= MAX_COMPILED and system.n_dof <= MAX_COMPILED)


def check_frictionless(system: LinearSystem, law: ImpactLaw, scheme: str) -> None:
    """InputError, naming ``scheme``, for Coulomb's law or a system with friction columns:
    only Moreau–Jean time-stepping has friction."""
    if isinstance(law, Coulomb) or system.contact_dim > 1:
        raise InputError(f"scheme={scheme!r} has no Coulomb friction: simulate frictional "
                         "systems with scheme='moreau-jean'")


def friction_compiled_applies(system: LinearSystem, backend: str) -> bool:
    """Whether a Coulomb run takes the compiled frictional loop: ``backend="auto"``, a
    constant or linear force, a dense system with at most :data:`MAX_COMPILED` degrees of
    freedom and contact rows."""
    return (backend == "auto" and not system.structure.sparse
            and (system.constant_force is not None or system.linear_force is not None)
            and 0 < system.H.shape[1] <= MAX_COMPILED and system.n_dof <= MAX_COMPILED)


def route(system: LinearSystem, law: ImpactLaw, backend: str, compiled: bool | None) -> str:
    """Which loop runs (the rule of :mod:`.time_stepping`): ``"friction"``, ``"compiled"`` or
    ``"python"``.

    Raises
    ------
    InputError
        Coulomb's law on a frictionless system (``contact_dim`` 1) or with a backend
        solve_friction does not take; another law on a frictional system; ``compiled=True``
        for a run outside :func:`compiled_applies` (:func:`friction_compiled_applies`).
    """
    frictional = isinstance(law, Coulomb)
    if frictional != (system.contact_dim > 1):
        if frictional:
            raise InputError(NEEDS_TANGENTS)
        raise InputError(f"a system with contact_dim = {system.contact_dim} has friction "
                         f"columns: simulate it with iq.Coulomb(mu, restitution), or build "
                         f"it with contact_dim=1 from the normal columns for {law!r}")
    if frictional:
        backend = check_friction_backend(step_backend(law, backend))
        fits = friction_compiled_applies(system, backend)
        use = fits if compiled is None else compiled
        if use and not fits:
            raise InputError("compiled=True: the compiled frictional loop does not take this "
                             "run (a backend other than 'auto', a callable force, a sparse or "
                             "a larger system)")
        return "friction-compiled" if use else "friction"
    use = compiled_applies(system, law, backend) if compiled is None else compiled
    if use and not compiled_applies(system, law, backend):
        raise InputError("compiled=True: the compiled loop does not take this run (a law, "
                         "force, backend or size outside compiled_applies)")
    return "compiled" if use else "python"
