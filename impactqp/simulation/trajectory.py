"""The result of a simulation: states, contact impulses, energies and certified impact events
(docs/theory.md §14), saved as NPZ or CSV."""

from __future__ import annotations

import csv
import json
from collections.abc import Callable
from functools import cached_property
from pathlib import Path
from typing import Any

import numpy as np

from ..base.outputs import atomic_output, output_file
from ..errors import InputError
from ..laws.base import ImpactLaw
from .friction_step import FrictionEvent
from .impacts import ImpactEvent
from .sensitivity import Sensitivities, TrajectoryKink
from .system import LinearSystem

FORMATS = (".npz", ".csv")

LEAVING_S = {"kinetic": "velocity jump not an impulse of the cones",
             "kinematic": "kinematic residual above tolerance",
             "energetic": "energy rising"}
"""How a summary names each condition of u⁺ ∈ S (docs/theory.md §2) that a step fails."""


def _failed(verdict: Any) -> list[str]:
    """The conditions of u⁺ ∈ S a verdict fails: a frictionless
    :class:`~impactqp.model.admissible.Membership` or a frictional step's certificate."""
    if hasattr(verdict, "failed"):
        return list(verdict.failed())
    return [name for name, value in verdict.values.items()
            if not (np.isfinite(value) and value <= verdict.tol_of(name))]


class Trajectory:
    """States of a simulated system and the impacts on the way.

    Attributes
    ----------
    system : LinearSystem
    law : ImpactLaw
        The law the user chose.
    scheme : str
        ``"moreau-jean"`` or ``"event-driven"``.
    t : (k,) ndarray
        Record times: every step (time-stepping), or the output grid plus the state just
        before and just after every impact (event-driven; such times appear twice).
    q, v : (k, n) ndarray
        Positions and velocities.
    impulses : (k, d·m) ndarray
        Contact impulses Λ of the step ending at that record (time-stepping), or of the
        impact just before it (event-driven); zero elsewhere. One column per column of H:
        with friction (``contact_dim`` d > 1) the normal and tangent components of each
        contact.
    events : list of ImpactEvent or FrictionEvent
        Every impact problem solved, in order, each with its certificate (a run may pass a
        callable that builds the list: it is called on first read).
    settings : dict
        The integrator's parameters.
    sensitivities : Sensitivities or None
        The derivatives asked for with ``simulate(..., sensitivities=...)`` (read them with
        :meth:`sensitivity`, :meth:`vjp`, :attr:`sensitivity_kind` and :attr:`kinks`).
    """

    sensitivities: Sensitivities | None = None

    def __init__(self, system: LinearSystem, law: ImpactLaw, scheme: str, t: np.ndarray,
                 q: np.ndarray, v: np.ndarray, impulses: np.ndarray,
                 events: list[ImpactEvent | FrictionEvent]
                 | Callable[[], list[ImpactEvent]],
                 settings: dict[str, Any]) -> None:
        self.system, self.law, self.scheme = system, law, scheme
        self.t, self.q, self.v, self.impulses = t, q, v, impulses
        self._events = events
        self.settings = settings

    @property
    def events(self) -> list[ImpactEvent | FrictionEvent]:
        """Every impact problem solved, in order, each with its certificate."""
        if callable(self._events):
            self._events = self._events()
        return self._events

    # --- derived quantities --------------------------------------------------------------
    @property
    def generalized_impulses(self) -> np.ndarray:
        """p = HΛ of every record (Siconos' ``p(1)``), (k, n)."""
        return np.asarray(self.system.H @ self.impulses.T).T

    @cached_property
    def kinetic_energy(self) -> np.ndarray:
        """T = ½vᵀMv at every record."""
        return np.atleast_1d(self.system.kinetic_energy(self.v))

    @cached_property
    def potential_energy(self) -> np.ndarray:
        """V(q) at every record (NaN for a callable force without potential)."""
        return np.atleast_1d(self.system.potential_energy(self.q))

    @property
    def total_energy(self) -> np.ndarray:
        """T + V at every record."""
        return self.kinetic_energy + self.potential_energy

    @property
    def gaps(self) -> np.ndarray:
        """g = Hᵀq + b at every record, (k, m)."""
        return np.atleast_2d(self.system.gaps(self.q))

    @property
    def impact_times(self) -> np.ndarray:
        """Times of the recorded impact events."""
        return np.array([e.time for e in self.events])

    def energy_drift(self) -> float:
        """max abs(E(t) − E(t₀)) / abs(E(t₀)) over the records (absolute when E(t₀) = 0)."""
        E = self.total_energy
        scale = abs(E[0]) if E[0] != 0 else 1.0
        return float(np.max(np.abs(E - E[0])) / scale)

    @property
    def certified(self) -> bool:
        """True when every impact event passed its certificate (always, when returned)."""
        return all(e.certified for e in self.events)

    def admissible(self) -> np.ndarray:
        """u⁺ ∈ S for every event (computed on first call per event, docs/theory.md §2)."""
        return np.array([bool(e.admissible) for e in self.events], dtype=bool)

    def outside_S(self) -> dict[str, int]:
        """How many certified events leave S, by the condition of u⁺ ∈ S they fail
        (``kinetic``, ``kinematic``, ``energetic``; an event failing two counts under both).

        A certificate proves that an event solves its law; u⁺ ∈ S is a separate verdict, and
        some laws' certified answers leave S: Newton's restitution keeps a separating contact
        closed on a time step (the kinematic condition, docs/theory.md §14, §17) and, with
        Coulomb friction, can gain kinetic energy (the energetic one, docs/theory.md §16)."""
        counts = dict.fromkeys(LEAVING_S, 0)
        for event in self.events:
            if not event.admissible:
                for name in _failed(event.admissible):
                    counts[name] += 1
        return {name: count for name, count in counts.items() if count}

    def _outside_S_text(self) -> list[str]:
        counts = self.outside_S()
        if not counts:
            return []
        reasons = "; ".join(f"{LEAVING_S[name]}: {count} step{'s' if count > 1 else ''}"
                            for name, count in counts.items())
        frictional = self.system.contact_dim > 1
        why = ("Newton's restitution with Coulomb friction does this: its certified steps may "
               "keep a separating contact closed or gain energy (docs/theory.md §16, §17)"
               if frictional else
               "Newton's restitution on a time step keeps a separating contact closed "
               "(docs/theory.md §14)")
        return [f"  certified yet outside S — {reasons}", f"    {why}"]

    def summary(self) -> str:
        """A few lines: scheme, law, records, events, certificates, S-verdicts (with the count
        of each reason why certified events leave S, :meth:`outside_S`), energy."""
        adm = self.admissible()
        kept = self.settings.get("keep_events", True)
        return "\n".join([
            f"{self.scheme} simulation of {self.system!r} with {self.law!r}",
            f"  t ∈ [{self.t[0]:.6g}, {self.t[-1]:.6g}], {self.t.size} records, "
            + (f"{len(self.events)} impact problems" if kept else "impact events not kept"),
            f"  certificates: {'all ok' if self.certified else 'FAILED'}; "
            f"u⁺ ∈ S: {int(adm.sum())} of {adm.size}" if kept else
            "  certificates: every impact passed (a failing one stops the run)",
            *(self._outside_S_text() if kept else []),
            self._energy_text(),
        ])

    def _energy_text(self) -> str:
        """The summary's energy line: E(t₀) → E(t_end) and the drift, or what keeps them
        from being figures (no potential for the force; ½vᵀMv or V(q) beyond the floats)."""
        with np.errstate(over="ignore", invalid="ignore"):
            T, V = self.kinetic_energy, self.potential_energy
            E = T + V
        if np.all(np.isfinite(E)):
            return (f"  energy: {E[0]:.10g} → {E[-1]:.10g} "
                    f"(largest relative change {self.energy_drift():.3g})")
        beyond = int(np.sum(np.isinf(T) | np.isinf(V) | (np.isnan(E) & ~np.isnan(V))))
        if beyond:
            return (f"  energy: beyond the floats at {beyond} of {E.size} records (½vᵀMv or "
                    "V(q) overflows although q and v are finite): not checked")
        return (f"  energy: the force has no potential; kinetic {T[0]:.10g} → {T[-1]:.10g}")

    def __repr__(self) -> str:
        return (f"Trajectory(scheme={self.scheme!r}, records={self.t.size}, "
                f"events={len(self.events)})")

    # --- derivatives through time (docs/theory.md §21) ----------------------------------
    def _asked(self) -> Sensitivities:
        if self.sensitivities is None:
            raise InputError("this run has no sensitivities: pass simulate(..., "
                             "sensitivities=('q0', 'v0', ...))")
        return self.sensitivities

    @property
    def sensitivity_kind(self) -> str | None:
        """``"discrete-map"`` (Moreau–Jean: the derivative of the computed map, impact times
        quantized to steps), ``"flow"`` (event-driven: the derivative of the motion), or
        None without sensitivities."""
        return None if self.sensitivities is None else self.sensitivities.kind

    @property
    def kinks(self) -> list[TrajectoryKink]:
        """Where the derivative is one-sided: activation thresholds and degenerate contacts
        of steps, grazing, Zeno and simultaneous impacts (each a :class:`TrajectoryKink`)."""
        return self._asked().kinks

    def sensitivity(self, wrt: str | None = None) -> np.ndarray:
        """∂(q, v)/∂``wrt`` at every record, shape (records, 2n, k): rows [:n] the
        positions', [n:] the velocities'; k = n for ``"q0"``/``"v0"``, one column per
        coefficient of the law's parameter; every asked name side by side when None."""
        return self._asked().of(wrt)

    def vjp(self, q: Any = None, v: Any = None) -> dict[str, Any]:
        """The gradient of a loss L from ∂L/∂q and ∂L/∂v, each (n,) (a loss on the final
        state) or (records, n) (a loss on samples), by the adjoint (transposed) chain:
        a dict from each asked name to its cotangent."""
        return self._asked().vjp(q, v)

    # --- saving --------------------------------------------------------------------------
    def plot(self, kind: str = "positions", path: str | Path | None = None, *,
             title: str = "", dofs: Any = None) -> Any:
        """Draw a quantity of the run over time and write the figure when given ``path``
        (.png, .svg, .pdf). Needs the ``plot`` extra (matplotlib).

        Parameters
        ----------
        kind : {"positions", "velocities", "energy", "impulses", "contacts"}
            Coordinates or their velocities (one axes per kind of coordinate — translations,
            rotations — labelled with the system's names and units), the energies T, V and
            T + V, the contact impulses, or each contact's state (open/closed; with
            friction open, stick or slide).
        path : str or Path, optional
        title : str
        dofs : int, str or sequence of them, optional
            The coordinates drawn, by name (``"x"``, ``"φ"``, ``"q2"``) or by 1-based
            number as in the labels (default: the first 12).

        Returns
        -------
        matplotlib.figure.Figure
            (:func:`impactqp.simulation.pictures.plot` documents it in full.)
        """
        from . import pictures

        return pictures.plot(self, kind, path, title=title, dofs=dofs)

    def animate(self, path: str | Path | None = None, **options: Any) -> Any:
        """Animate the bodies of a builder's system — a cradle's balls on pendulums, balls
        on a vertical line, a rolling sphere with a mark that turns with it, a block on an
        incline, a box on a floor — written when given ``path`` (.gif or .mp4); ``options``
        are ``length``, ``radius``, ``frames``, ``fps`` and ``size``. Needs the ``plot``
        extra (matplotlib).

        Returns
        -------
        matplotlib.animation.FuncAnimation
            (:func:`impactqp.simulation.pictures.animate` documents it in full.)

        Raises
        ------
        impactqp.errors.UndrawableSystemError
            A system built from matrices, whose bodies are unknown.
        """
        from . import pictures

        return pictures.animate(self, path, **options)

    def event_arrays(self) -> dict[str, np.ndarray]:
        """The events as flat arrays (ragged fields as values plus offsets)."""
        ev = self.events

        def ragged(name: str, rows: list[np.ndarray]) -> dict[str, np.ndarray]:
            sizes = np.array([r.size for r in rows], dtype=int)
            flat = np.concatenate(rows) if rows else np.zeros(0)
            return {name: flat, f"{name}_offsets": np.concatenate([[0], np.cumsum(sizes)])}

        worst = [e.certificate.worst for e in ev]
        return {
            "event_time": np.array([e.time for e in ev], dtype=float),
            "event_kind": np.array([e.kind for e in ev], dtype=str),
            "event_law": np.array([e.law for e in ev], dtype=str),
            "event_certified": np.array([e.certified for e in ev], dtype=bool),
            "event_worst_residual": np.array([w[1] for w in worst], dtype=float),
            "event_admissible": self.admissible(),
            **ragged("event_dofs", [e.dofs for e in ev]),
            **ragged("event_contacts", [e.contacts for e in ev]),
            **ragged("event_u_minus", [e.u_minus for e in ev]),
            **ragged("event_u_plus", [e.u_plus for e in ev]),
            **ragged("event_impulses", [e.impulses for e in ev]),
        }

    def save(self, path: str | Path) -> Path:
        """Write the trajectory: ``.npz`` (everything, events included) or ``.csv`` (one row
        per record; the events go to ``<name>.events.csv`` beside it).

        Raises
        ------
        InputError
            Another suffix.
        """
        path = Path(path)
        suffix = path.suffix.lower()
        if suffix not in FORMATS:
            raise InputError(f"trajectory file must end in one of {FORMATS}, got {path.name!r}")
        output_file(path)
        if suffix == ".npz":
            meta = json.dumps({"scheme": self.scheme, "law": repr(self.law),
                               "settings": self.settings})
            with atomic_output(path) as temp:
                np.savez_compressed(temp, t=self.t, q=self.q, v=self.v, impulses=self.impulses,
                                    kinetic_energy=self.kinetic_energy,
                                    potential_energy=self.potential_energy,
                                    meta=np.array(meta), **self.event_arrays())
            return path
        n, m, d = self.system.n_dof, self.system.n_contacts, self.system.contact_dim
        impulses = [f"lambda{j}" for j in range(m)] if d == 1 else \
            [f"lambda{j}_{part}" for j in range(m) for part in ("n", "t1", "t2")[:d]]
        header = (["t"] + [f"q{i}" for i in range(n)] + [f"v{i}" for i in range(n)]
                  + impulses + ["kinetic_energy", "potential_energy"])
        table = np.column_stack([self.t, self.q, self.v, self.impulses, self.kinetic_energy,
                                 self.potential_energy])
        with atomic_output(path) as temp:
            np.savetxt(temp, table, fmt="%.17g", delimiter=",", header=",".join(header),
                       comments="", encoding="utf-8")
        self._save_events_csv(path.with_name(path.stem + ".events.csv"))
        return path

    def _save_events_csv(self, path: Path) -> None:
        def joined(values: np.ndarray) -> str:
            return " ".join(repr(float(x)) if values.dtype.kind == "f" else str(x)
                            for x in values)

        with atomic_output(path) as temp, temp.open("w", newline="", encoding="utf-8") as handle:
            writer = csv.writer(handle)
            writer.writerow(["time", "kind", "law", "certified", "worst_residual",
                             "admissible", "dofs", "contacts", "u_minus", "u_plus",
                             "impulses"])
            for e, ok in zip(self.events, self.admissible()):
                writer.writerow([repr(float(e.time)), e.kind, e.law, e.certified,
                                 repr(float(e.certificate.worst[1])), bool(ok),
                                 joined(e.dofs), joined(e.contacts), joined(e.u_minus),
                                 joined(e.u_plus), joined(e.impulses)])
