"""Certified derivatives of impact maps (docs/theory.md §18–§20): exact on a stable active
set, one-sided with limiting Jacobians at kinks, and a certificate that audits them
against finite differences."""
