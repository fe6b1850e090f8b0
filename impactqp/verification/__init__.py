"""Verifying impact laws: sampled checks against S and of non-expansiveness, exact
certificates of piecewise-linear tables, the Frémond admissibility map, and laws compared
with the dispersive LZB model (docs/theory.md §7, §11, §13), and every backend compared on one
impact (:func:`~.bench.compare_backends`, docs/theory.md §8, §9).

This package is public: ``impactqp.verification`` re-exports the names below; the top level
of :mod:`impactqp` keeps :func:`~.sampled.verify_law` and :func:`~.bench.compare_backends`."""

from .bench import BackendComparison, BackendRun, compare_backends
from .compare import LawComparison, LawOutcome, compare_chain, compare_laws
from .fremond_map import fremond_admissibility_map
from .report import Counterexample, LawReport
from .sampled import verify_law

__all__ = [
    "verify_law", "LawReport", "Counterexample", "fremond_admissibility_map", "compare_laws",
    "compare_chain", "LawComparison", "LawOutcome", "compare_backends", "BackendComparison",
    "BackendRun",
]
