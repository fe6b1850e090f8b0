"""Impact laws as objects (docs/theory.md §3, §6, §10) and the one solve pipeline.

Each law owns its program, the recovery of u⁺ and Λ, and its residuals (:mod:`.base`);
:func:`~.pipeline.solve` alone decides backends and certifies; :mod:`.batch` runs the same
laws over many pre-impact velocities.
"""
