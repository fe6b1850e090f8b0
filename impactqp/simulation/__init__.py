"""Motion with unilateral contacts (docs/theory.md §14): a linear mechanical system with gaps
g = Hᵀq + b ≥ 0 (:mod:`.system`, :mod:`.builders`), integrated by Moreau–Jean time-stepping
(:mod:`.time_stepping`) or event by event (:mod:`.event_driven`) with any impact law solved
through :func:`impactqp.solve`, into a :class:`~.trajectory.Trajectory` whose every impact
carries its certificate and its verdict on u⁺ ∈ S (:func:`.simulate.simulate`).

This package is public: ``impactqp.simulation`` re-exports the names below; the top level of
:mod:`impactqp` keeps :class:`~.system.LinearSystem`, :class:`~.system.LinearForce`,
:func:`~.simulate.simulate` and :class:`~.trajectory.Trajectory`."""

from .builders import (
    bead_chain,
    block_on_incline,
    bouncing_ball,
    box_on_floor,
    cradle_system,
    rolling_sphere,
)
from .contact_states import contact_states
from .coordinates import Coordinate, Scene
from .friction_step import FrictionEvent
from .impacts import ImpactEvent
from .sensitivity import Sensitivities, TrajectoryKink
from .simulate import simulate
from .step_law import MoreauJeanStep
from .system import LinearForce, LinearSystem
from .trajectory import Trajectory

__all__ = [
    "LinearSystem", "LinearForce", "simulate", "Trajectory", "ImpactEvent", "FrictionEvent",
    "MoreauJeanStep", "bouncing_ball", "cradle_system", "bead_chain", "block_on_incline",
    "rolling_sphere", "box_on_floor", "Coordinate", "Scene", "contact_states",
    "Sensitivities", "TrajectoryKink",
]
