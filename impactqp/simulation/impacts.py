"""The impacts of a simulation: closed contacts → clusters → one certified impact problem each,
solved by :func:`impactqp.solve` with the chosen law (docs/theory.md §14).

The same machinery serves both integrators: event-driven integration applies the law to the
pre-impact velocity at an impact time; Moreau–Jean time-stepping applies it to the free
velocity of a step, complementarity laws in the step form of
:class:`~impactqp.simulation.step_law.MoreauJeanStep`.
"""

from __future__ import annotations

from functools import cached_property

import numpy as np

from ..base.checks import DEFAULT_TOL
from ..laws.base import ImpactLaw
from ..laws.pipeline import solve
from ..laws.result import ImpactResult
from ..model.admissible import Membership
from ..model.problem import ImpactProblem
from .clusters import Cluster, ClusterCache
from .step_law import MoreauJeanStep


class ImpactEvent:
    """One impact problem solved during a simulation, with its certificate and its verdict.

    Attributes
    ----------
    time : float
        When it happened (for time-stepping: the end of the step).
    kind : str
        ``"impact"`` (event-driven) or ``"step"`` (a Moreau–Jean step with closed contacts).
    dofs : ndarray
        The degrees of freedom of the impact (the rest of the system is not involved).
    contacts : ndarray
        System indices of its closed contacts (the columns of its W, in order).
    result : ImpactResult
        The certified answer of :func:`impactqp.solve`: ``result.problem`` holds M, W and u⁻
        of the cluster, ``result.certificate`` the law's recomputed certificate.
    settled : ndarray
        Contacts closed after the impact because they separate slower than the rest velocity
        (accumulation of impacts, event-driven only; docs/theory.md §14).
    """

    def __init__(self, time: float, kind: str, dofs: np.ndarray, contacts: np.ndarray,
                 result: ImpactResult) -> None:
        self.time = time
        self.kind = kind
        self.dofs = dofs
        self.contacts = contacts
        self.result = result
        self.settled = np.zeros(0, dtype=int)

    u_minus = property(lambda self: self.result.problem.u_minus, doc="u⁻ on ``dofs``.")
    u_plus = property(lambda self: self.result.u_plus, doc="u⁺ on ``dofs``.")
    impulses = property(lambda self: self.result.impulses, doc="Λ on ``contacts``.")
    certificate = property(lambda self: self.result.certificate,
                           doc="The law's recomputed certificate.")
    law = property(lambda self: self.result.law, doc="Name of the law that was solved.")

    @property
    def certified(self) -> bool:
        """The certificate's verdict (True for every recorded event)."""
        return bool(self.result.certificate.ok)

    @cached_property
    def admissible(self) -> Membership:
        """Whether u⁺ ∈ S of this impact (docs/theory.md §2), computed on first access."""
        return self.result.problem.admissible_set().contains(self.u_plus)

    def __repr__(self) -> str:
        return (f"ImpactEvent(t={self.time:.12g}, kind={self.kind!r}, law={self.law!r}, "
                f"contacts={self.contacts.tolist()[:6]}, "
                f"certificate={'ok' if self.certified else 'FAILED'})")


class ImpactSolver:
    """Solves the impacts of one system with one law, cluster by cluster.

    Parameters
    ----------
    cache : ClusterCache
        Clusters and structures of the system for the metric of the impacts.
    law : ImpactLaw
        Any impact law.
    backend : str
        Passed to :func:`impactqp.solve`.
    tol : float
        Certificate tolerance.
    """

    def __init__(self, cache: ClusterCache, law: ImpactLaw, *, backend: str = "auto",
                 tol: float = DEFAULT_TOL) -> None:
        self.cache, self.law, self.backend, self.tol = cache, law, backend, tol

    def solve(self, time: float, u_minus: np.ndarray, closed: np.ndarray, *,
              v_previous: np.ndarray | None = None, gamma_previous: np.ndarray | None = None,
              ) -> tuple[np.ndarray, np.ndarray, list[ImpactEvent]]:
        """(u⁺, Λ over all contacts, events) for the closed contacts (boolean mask).

        Without ``v_previous`` (event-driven) a cluster is an impact when one of its
        contacts approaches (γ⁻ᵢ < 0). With it and the normal velocities
        ``gamma_previous`` = Hᵀv_k of all contacts (a Moreau–Jean step from v_k),
        complementarity laws take the step form and a cluster is solved unless its step q
        (:func:`impactqp.kernels.step.step_q`) is ≥ 0, where Λ = 0 already solves it.
        """
        u_plus = u_minus.copy()
        impulses = np.zeros(self.cache.m)
        events: list[ImpactEvent] = []
        for cl in self.cache.clusters(closed):
            u_c = u_minus[cl.dofs]
            law = self._law(cl, u_c, None if v_previous is None else v_previous[cl.dofs],
                            gamma_previous)
            if law is None:
                continue
            result = self._solve(ImpactProblem.from_structure(cl.structure, u_c), law)
            u_plus[cl.dofs] = result.u_plus
            impulses[cl.contacts] = result.impulses
            kind = "impact" if v_previous is None else "step"
            events.append(ImpactEvent(time, kind, cl.dof_indices(self.cache.n), cl.contacts,
                                      result))
        return u_plus, impulses, events

    def _law(self, cl: Cluster, u_c: np.ndarray, v_prev: np.ndarray | None,
             gamma_previous: np.ndarray | None) -> ImpactLaw | None:
        """The law for this cluster, or None when nothing happens (Λ = 0)."""
        gamma = cl.structure.Wt_times(u_c)
        if v_prev is not None and gamma_previous is not None:
            E = self.law.step_restitution(cl.contacts)
            if E is not None:
                law = MoreauJeanStep(E, v_prev)
                return law if law.approaching(gamma, gamma_previous[cl.contacts]) else None
        if not np.any(gamma < 0):
            return None
        return self.law.restrict(cl.contacts)

    def _solve(self, problem: ImpactProblem, law: ImpactLaw) -> ImpactResult:
        """The certified answer of :func:`impactqp.solve` (whose u⁻ = 0 shortcut answers only
        when the law's own certificate passes, so the step law needs no special case)."""
        return solve(problem, law, self.backend, tol=self.tol)
