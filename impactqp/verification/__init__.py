"""Verifying impact laws: sampled checks against S and of non-expansiveness, exact
certificates of piecewise-linear tables, and the Frémond admissibility map
(docs/theory.md §7, §11)."""
