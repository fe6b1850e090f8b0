"""Motion with unilateral contacts (docs/theory.md §14): a linear mechanical system with gaps
g = Hᵀq + b ≥ 0 (:mod:`.system`, :mod:`.builders`), integrated by Moreau–Jean time-stepping
(:mod:`.time_stepping`) or event by event (:mod:`.event_driven`) with any impact law solved
through :func:`impactqp.solve`, into a :class:`~.trajectory.Trajectory` whose every impact
carries its certificate and its verdict on u⁺ ∈ S (:func:`.simulate.simulate`)."""
