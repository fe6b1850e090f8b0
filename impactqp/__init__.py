"""impactqp: rigid-body impacts as convex programs.

The top level holds the names of daily use: problems (:class:`ImpactProblem`, :func:`chain`,
:func:`newtons_cradle`, problem files via :func:`load_problem` / :func:`save_problem`), the
admissible set S (:class:`AdmissibleSet`) and the geometric classification
(:func:`classify`), impact laws as objects (:class:`Moreau`, :class:`Newton`,
:class:`Fremond`, :class:`SectorLaw`, :class:`ReflectionLaw`, :class:`Coulomb`,
:class:`LZB`) solved by the one pipeline :func:`solve` (and its one-call forms
:func:`moreau`, :func:`newton`, :func:`fremond`, :func:`sector_law`,
:func:`reflection_law`), many impacts at once (:func:`solve_batch`, :func:`moreau_batch`,
:func:`sector_law_batch`), LCPs with symmetric matrices (:func:`solve_lcp`), the law
verifier :func:`verify_law`, every backend compared on one impact
(:func:`compare_backends`), motion with any law (:class:`LinearSystem`, :func:`simulate`),
FCLib's local contact problems (:class:`FrictionContactProblem`, :func:`solve_friction`,
:func:`load_fclib`), figures of S and of the sector law (:func:`plot_admissible`,
:func:`plot_sectors`; the ``plot`` extra) and the errors callers catch most
(:class:`ImpactError` and below).

Everything else lives in public submodules, each a complete view of its area:
:mod:`impactqp.problems`, :mod:`impactqp.results`, :mod:`impactqp.friction`,
:mod:`impactqp.simulation`, :mod:`impactqp.tables`, :mod:`impactqp.chains`,
:mod:`impactqp.verification` and :mod:`impactqp.errors`. A name that moved from the top level
to a submodule still resolves here, with a :class:`DeprecationWarning` naming its new place.
The theory and the conventions are in docs/theory.md of the repository.
"""

import importlib
import warnings
from importlib.metadata import PackageNotFoundError, version
from typing import Any

from . import (  # noqa: F401  (the public submodules, attributes of the package)
    chains,
    errors,
    friction,
    problems,
    results,
    simulation,
    tables,
    verification,
)
from .derivatives.batch import derivative_batch
from .derivatives.impact import ImpactDerivative
from .derivatives.solve import derivative
from .errors import (
    BackendUnsuitableError,
    CertificateError,
    ImpactError,
    InputError,
    NoSolutionError,
    OutOfRangeError,
    SolverError,
)
from .figures.sections import plot_admissible, plot_sectors
from .io.fclib import load_fclib, save_fclib
from .io.files import load_problem
from .io.save import save_problem
from .laws.base import Answer, ImpactLaw
from .laws.batch import moreau_batch, sector_law_batch, solve_batch
from .laws.catalogue import available_backends
from .laws.complementarity import Fremond, Newton
from .laws.coulomb import Coulomb
from .laws.friction import solve_friction
from .laws.functions import fremond, moreau, newton, reflection_law, sector_law
from .laws.lzb import LZB
from .laws.moreau import Moreau
from .laws.pipeline import solve
from .laws.reflection import ReflectionLaw
from .laws.result import ImpactResult
from .laws.sector import SectorLaw
from .model.admissible import AdmissibleSet
from .model.builders import chain, newtons_cradle, random_impact
from .model.classify import classify
from .model.friction import FrictionContactProblem
from .model.problem import ImpactProblem
from .qp.lcp import solve_lcp
from .simulation.simulate import simulate
from .simulation.system import LinearForce, LinearSystem
from .simulation.trajectory import Trajectory
from .verification.bench import compare_backends
from .verification.sampled import verify_law

try:
    __version__ = version("impactqp")
except PackageNotFoundError:  # running from a source tree that was never installed
    __version__ = "0+unknown"

__all__ = [
    # problems
    "ImpactProblem", "chain", "newtons_cradle", "random_impact", "load_problem",
    "save_problem", "AdmissibleSet", "classify",
    # laws
    "ImpactLaw", "Answer", "Moreau", "Newton", "Fremond", "SectorLaw", "ReflectionLaw",
    "Coulomb", "LZB",
    # solving
    "solve", "moreau", "newton", "fremond", "sector_law", "reflection_law", "solve_batch",
    "moreau_batch", "sector_law_batch", "solve_lcp", "available_backends", "ImpactResult",
    "verify_law", "compare_backends",
    # derivatives
    "derivative", "derivative_batch", "ImpactDerivative",
    # motion
    "LinearSystem", "LinearForce", "simulate", "Trajectory",
    # figures (the plot extra)
    "plot_admissible", "plot_sectors",
    # friction
    "FrictionContactProblem", "solve_friction", "load_fclib", "save_fclib",
    # errors
    "ImpactError", "InputError", "SolverError", "CertificateError", "BackendUnsuitableError",
    "NoSolutionError", "OutOfRangeError",
]

SUBMODULES = ("problems", "results", "friction", "simulation", "tables", "chains",
              "verification", "errors")
"""The public submodules, each with an ``__all__`` of its own."""

_MOVED = {
    **dict.fromkeys(["ImpactStructure", "ChainInfo", "ProblemFile", "Membership",
                     "Classification"], "problems"),
    **dict.fromkeys(["BatchResult", "LCPResult", "ResidualChecks", "Certificate",
                     "SectorLawCertificate", "DEFAULT_TOL"], "results"),
    **dict.fromkeys(["FrictionResult", "FrictionCertificate", "point_on_plane",
                     "sphere_on_plane", "two_spheres"], "friction"),
    **dict.fromkeys(["ImpactEvent", "FrictionEvent", "MoreauJeanStep", "bouncing_ball",
                     "cradle_system", "bead_chain", "block_on_incline", "rolling_sphere",
                     "box_on_floor"], "simulation"),
    **dict.fromkeys(["sector_law_table", "SectorTable", "SectorCone", "TableCertificate",
                     "SectorCertificate", "reflection_law_table", "continuous_mass_ratios"],
                    "tables"),
    **dict.fromkeys(["LZBAnswer", "LZBCertificate", "LZBRecord", "PhysicalChain",
                     "ball_chain", "monodisperse_chain", "tapered_chain", "hertz_stiffness",
                     "sphere_mass"], "chains"),
    **dict.fromkeys(["LawReport", "Counterexample", "fremond_admissibility_map",
                     "compare_laws", "compare_chain", "LawComparison", "LawOutcome"],
                    "verification"),
    **dict.fromkeys(["ShapeError", "NonFiniteError", "MassMatrixError", "RestitutionError",
                     "UnknownBackendError", "NonConvexLCPError", "NonSymmetricLCPError",
                     "ProblemFileError", "OptionalDependencyError", "NonFiniteStateError",
                     "SectorLawError", "SectorInputError", "SectorTableTooLarge",
                     "IntegrationBudgetError"], "errors"),
}
"""Names that left the top level, each with the public submodule that holds it now."""


def __getattr__(name: str) -> Any:
    """A name that moved to a public submodule: the same object, with a DeprecationWarning
    that names its new place."""
    if name not in _MOVED:
        raise AttributeError(f"module 'impactqp' has no attribute {name!r}")
    where = f"impactqp.{_MOVED[name]}"
    warnings.warn(f"iq.{name} moved to {where}.{name}", DeprecationWarning, stacklevel=2)
    return getattr(importlib.import_module(where), name)


def __dir__() -> list[str]:
    """The names of daily use, the public submodules and ``__version__``."""
    return sorted([*__all__, *SUBMODULES, "__version__"])
