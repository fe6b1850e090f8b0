"""Automatic-differentiation adapters for impactqp's certified derivatives
(docs/theory.md §18–§20, docs/interop.rst): ``impactqp.interop.jax`` (the ``jax`` extra)
and ``impactqp.interop.torch`` (the ``torch`` extra).

Neither framework is imported by ``import impactqp`` nor by this package: only importing
one of the two submodules imports its framework, and a missing framework raises
:class:`~impactqp.errors.OptionalDependencyError` naming the extra to install. Both wrap
:class:`~impactqp.interop.core.ImpactMap`, the framework-free map (u⁻, law parameters) ↦
(u⁺, Λ) whose backward pass is :meth:`impactqp.ImpactDerivative.vjp`.
"""
