"""Certified derivatives of impact maps (docs/theory.md §18–§20)."""
