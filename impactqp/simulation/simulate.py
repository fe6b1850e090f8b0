"""The one simulation entry point: :func:`simulate` (docs/theory.md §14)."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

import numpy as np

from ..base.arrays import as_count, as_flag, as_real, check_tol
from ..base.checks import DEFAULT_TOL
from ..errors import InputError, NonFiniteStateError
from ..laws.base import ImpactLaw
from ..laws.planner import check_backend, check_law
from ..model.problem import ImpactProblem
from .event_driven import event_driven
from .friction_step import check_friction_backend, coulomb_coefficients
from .routing import check_frictionless
from .system import LinearSystem
from .through_time import check, differentiate
from .time_stepping import moreau_jean
from .trajectory import Trajectory

SCHEMES = ("moreau-jean", "event-driven")
MAX_STEPS = 1e8
"""Most time steps (Moreau–Jean) or output points (event-driven) a run may take."""
METHODS = ("DOP853", "RK45", "Radau", "BDF", "LSODA")
_POSITIVE = ("gap_tol", "rest_velocity", "rtol", "atol")
OPTIONS = {
    "moreau-jean": ("record_every", "keep_events"),
    "event-driven": ("gap_tol", "rest_velocity", "method", "rtol", "atol", "max_events",
                     "keep_events"),
}


def _options(scheme: str, options: dict[str, Any]) -> dict[str, Any]:
    unknown = sorted(set(options) - set(OPTIONS[scheme]))
    if unknown:
        raise InputError(f"unknown option(s) {unknown} for scheme {scheme!r}; it takes "
                         f"{list(OPTIONS[scheme])}")
    out: dict[str, Any] = {}
    for key, value in options.items():
        if key in _POSITIVE:
            out[key] = as_real(key, value, positive=True)
        elif key in ("record_every", "max_events"):
            out[key] = as_count(key, value, minimum=1)
        elif key == "keep_events":
            out[key] = as_flag(key, value)
        elif key == "method":
            if value not in METHODS:
                raise InputError(f"method must be one of {METHODS}, got {value!r}")
            out[key] = value
    return out


def simulate(system: LinearSystem, law: ImpactLaw, t_end: float,
             scheme: str = "moreau-jean", h: float | None = None, theta: float = 0.5, *,
             t0: float = 0.0, backend: str = "auto", tol: float = DEFAULT_TOL,
             progress: Callable[[float], None] | None = None,
             sensitivities: Sequence[str] | None = None, **options: Any) -> Trajectory:
    """Simulate a system with unilateral contacts and any impact law (docs/theory.md §14).

    Parameters
    ----------
    system : LinearSystem
        ``iq.LinearSystem(M, q0, v0, force, H, b)`` or a builder's
        (``iq.simulation.bouncing_ball()``, ``iq.simulation.cradle_system(n)``,
        ``iq.simulation.bead_chain(n)``).
    law : ImpactLaw
        ``iq.Moreau(eps)``, ``iq.Newton(e)`` (one coefficient, or one per contact of the
        system), ``iq.Fremond(E)`` (m × m), ``iq.SectorLaw()``, ``iq.ReflectionLaw()`` or any
        :class:`impactqp.ImpactLaw`; ``iq.Coulomb(mu, restitution)`` for a system with
        ``contact_dim`` 2 or 3 (Moreau–Jean only, docs/theory.md §17).
    t_end : float
        Final time, after ``t0``.
    scheme : {"moreau-jean", "event-driven"}
        Time-stepping (θ-scheme, velocity-level impacts with the contacts closed at each
        step) or event-driven integration (impacts at located events).
    h : float, optional
        Moreau–Jean: the time step. Event-driven: the output interval. Default
        (t_end − t0)/1000.
    theta : float
        θ ∈ [0, 1] of the Moreau–Jean scheme (unused by event-driven integration).
    t0 : float
        Initial time.
    backend, tol : str, float
        For every impact problem, passed to :func:`impactqp.solve` (with Coulomb's law to
        :func:`impactqp.solve_friction`: ``"auto"``, ``"clarabel"`` or ``"nsgs"``).
    progress : callable, optional
        Called with the simulated time now and then.
    sensitivities : sequence of str, optional
        Differentiate the run with respect to these (docs/theory.md §21): ``"q0"``,
        ``"v0"`` and the law's parameter (``"eps"`` for Moreau, ``"e"`` for Newton, ``"E"``
        for Frémond, ``"mu"`` and ``"restitution"`` for Coulomb). Moreau–Jean gives the
        derivative of its discrete map
        (``trajectory.sensitivity_kind == "discrete-map"``), event-driven integration the
        derivative of the motion (``"flow"``, saltation at each impact); read them with
        ``trajectory.sensitivity(...)``, ``trajectory.vjp(...)`` and ``trajectory.kinks``.
        Complementarity laws and Coulomb's (Moreau–Jean only) under a constant or linear
        force.
    **options
        Moreau–Jean: ``record_every`` (int), ``keep_events`` (bool). Event-driven:
        ``gap_tol`` (1e-10 of the system's length scale), ``rest_velocity`` (1e-7 of its
        velocity scale), ``method`` ("DOP853"), ``rtol``
        (1e-12), ``atol`` (1e-14), ``max_events`` (100000), ``keep_events``.

    Returns
    -------
    Trajectory
        t, q, v, contact impulses, energies and every impact event with its certificate
        and its u⁺ ∈ S verdict.

    Raises
    ------
    InputError
        Bad arguments (naming them); a law that does not fit the system's contacts (e.g.
        ``SectorLawError`` for the sector law on a chain with a wall); more than 10⁸ steps
        (or output points) for ``h`` and ``t_end``; Coulomb's law on a frictionless system,
        another law on a frictional one, or friction with ``scheme="event-driven"``.
    NonFiniteStateError
        A recorded state is NaN or infinite (the message gives the first such time).
    SolverError, CertificateError, NoSolutionError
        From the integrator or from an impact no backend could certify.
    """
    if not isinstance(system, LinearSystem):
        raise InputError(f"system must be an impactqp LinearSystem, got "
                         f"{type(system).__name__}")
    check_law(law)
    if scheme not in SCHEMES:
        raise InputError(f"scheme must be one of {SCHEMES}, got {scheme!r}")
    frictional = law.frictional
    if frictional or system.contact_dim > 1:
        if scheme != "moreau-jean":
            check_frictionless(system, law, scheme)
        if frictional:
            coulomb_coefficients(law, system)
    else:
        law.check(ImpactProblem.from_structure(system.structure, np.zeros(system.n_dof)))
    t0 = as_real("t0", t0)
    t_end = as_real("t_end", t_end)
    if not t_end > t0:
        raise InputError(f"t_end must be after t0 = {t0!r}, got {t_end!r}")
    h = (t_end - t0) / 1000.0 if h is None else as_real("h", h, positive=True)
    steps = (t_end - t0) / h
    if not steps <= MAX_STEPS:  # also catches an overflowing t_end − t0
        what = "steps" if scheme == "moreau-jean" else "output points"
        raise InputError(f"h = {h:.6g} is too small for t_end − t0 = {t_end - t0:.6g}: "
                         f"{steps:.3g} {what}, at most {MAX_STEPS:.0e}; raise h or shorten "
                         "the run")
    theta = as_real("theta", theta, low=0.0, high=1.0)
    if frictional:
        check_friction_backend(backend)
    elif law.forms or backend != law.closed_form_backend:
        check_backend(backend)
    tol = check_tol(tol)
    if progress is not None and not callable(progress):
        raise InputError(f"progress must be a callable, got {type(progress).__name__}")
    opts = _options(scheme, options)
    cols = None if sensitivities is None else check(system, law, scheme, sensitivities, opts)
    if scheme == "moreau-jean":
        trajectory = moreau_jean(system, law, t_end, h, theta, t0=t0, backend=backend,
                                 tol=tol, progress=progress, **opts)
    else:
        trajectory = event_driven(system, law, t_end, h, t0=t0, backend=backend, tol=tol,
                                  progress=progress, **opts)
    check_finite_states(trajectory.t, trajectory.q, trajectory.v)
    if cols is not None:
        trajectory.sensitivities = differentiate(trajectory, cols)
    return trajectory


def check_finite_states(T: np.ndarray, Q: np.ndarray, V: np.ndarray) -> None:
    """Raise NonFiniteStateError, with the first time, when a recorded state is not finite."""
    bad = ~(np.isfinite(Q).all(axis=1) & np.isfinite(V).all(axis=1))
    if bad.any():
        i = int(np.argmax(bad))
        raise NonFiniteStateError(f"the state is not finite at t = {T[i]:.12g} (q or v NaN or "
                                  "infinite): a force that turns non-finite, or motion beyond "
                                  "the float range")
