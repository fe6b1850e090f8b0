"""impactqp: rigid-body impacts as convex programs.

Problems (:class:`ImpactProblem`, :func:`chain`, :func:`newtons_cradle`, problem files via
:func:`load_problem` / :func:`save_problem`), the admissible set S (:class:`AdmissibleSet`),
impact laws as objects (:class:`Moreau`, :class:`Newton`, :class:`Fremond`,
:class:`SectorLaw`, :class:`ReflectionLaw`) solved by the one pipeline :func:`solve` (and its
one-call forms :func:`moreau`, :func:`newton`, :func:`fremond`, :func:`sector_law`,
:func:`reflection_law`), many impacts at once (:func:`solve_batch`, :func:`moreau_batch`,
:func:`sector_law_batch`), the law verifier :func:`verify_law`, LCPs with symmetric matrices
(:func:`solve_lcp`), the geometric classification (:func:`classify`) and motion with any
law (:class:`LinearSystem`, :func:`simulate`), and the dispersive LZB model of multiple
impacts (:class:`LZB`) beside the rigid laws (:func:`compare_chain`). Frictional impacts
(``contact_dim`` 2 or 3, :class:`Coulomb`), frictional motion, and FCLib's local contact
problems (:class:`FrictionContactProblem`, :func:`solve_friction`, :func:`load_fclib`) are
certified the same way. The theory and the conventions are in docs/theory.md of the
repository.
"""

from importlib.metadata import PackageNotFoundError, version

from .base.checks import DEFAULT_TOL, ResidualChecks
from .errors import (
    BackendUnsuitableError,
    CertificateError,
    ImpactError,
    InputError,
    IntegrationBudgetError,
    MassMatrixError,
    NonConvexLCPError,
    NonFiniteError,
    NonFiniteStateError,
    NonSymmetricLCPError,
    NoSolutionError,
    OptionalDependencyError,
    OutOfRangeError,
    ProblemFileError,
    RestitutionError,
    SectorInputError,
    SectorLawError,
    SectorTableTooLarge,
    ShapeError,
    SolverError,
    UnknownBackendError,
)
from .io.fclib import load_fclib, save_fclib
from .io.files import ProblemFile, load_problem
from .io.save import save_problem
from .laws.base import Answer, ImpactLaw
from .laws.batch import BatchResult, moreau_batch, sector_law_batch, solve_batch
from .laws.catalogue import available_backends
from .laws.certificate import Certificate, SectorLawCertificate
from .laws.complementarity import Fremond, Newton
from .laws.coulomb import Coulomb
from .laws.friction import FrictionResult, solve_friction
from .laws.functions import fremond, moreau, newton, reflection_law, sector_law
from .laws.lzb import LZB, LZBAnswer, LZBCertificate, LZBRecord
from .laws.moreau import Moreau
from .laws.pipeline import solve
from .laws.reflection import ReflectionLaw
from .laws.result import ImpactResult
from .laws.sector import SectorLaw
from .model.admissible import AdmissibleSet, Membership
from .model.builders import chain, newtons_cradle, random_impact
from .model.classify import Classification, classify
from .model.friction import FrictionCertificate, FrictionContactProblem
from .model.friction_builders import point_on_plane, sphere_on_plane, two_spheres
from .model.physical_chains import (
    PhysicalChain,
    ball_chain,
    hertz_stiffness,
    monodisperse_chain,
    sphere_mass,
    tapered_chain,
)
from .model.problem import ImpactProblem
from .model.structure import ChainInfo, ImpactStructure
from .qp.lcp import LCPResult, solve_lcp
from .simulation.builders import (
    bead_chain,
    block_on_incline,
    bouncing_ball,
    box_on_floor,
    cradle_system,
    rolling_sphere,
)
from .simulation.friction_step import FrictionEvent
from .simulation.impacts import ImpactEvent
from .simulation.simulate import simulate
from .simulation.step_law import MoreauJeanStep
from .simulation.system import LinearForce, LinearSystem
from .simulation.trajectory import Trajectory
from .tables.certificate import SectorCertificate, TableCertificate
from .tables.coxeter import continuous_mass_ratios
from .tables.reflection_table import reflection_law_table
from .tables.sector_table import SectorCone, SectorTable, sector_law_table
from .verification.compare import LawComparison, LawOutcome, compare_chain, compare_laws
from .verification.fremond_map import fremond_admissibility_map
from .verification.report import Counterexample, LawReport
from .verification.sampled import verify_law

try:
    __version__ = version("impactqp")
except PackageNotFoundError:  # running from a source tree that was never installed
    __version__ = "0+unknown"

__all__ = [
    "AdmissibleSet", "Answer", "BackendUnsuitableError", "BatchResult", "Certificate",
    "CertificateError", "ChainInfo", "FrictionEvent", "block_on_incline", "box_on_floor",
    "rolling_sphere", "Classification", "Coulomb", "Counterexample",
    "DEFAULT_TOL", "Fremond",
    "FrictionCertificate", "FrictionContactProblem", "FrictionResult",
    "ImpactError", "ImpactEvent", "ImpactLaw", "ImpactProblem", "ImpactResult", "ImpactStructure",
    "InputError", "IntegrationBudgetError", "LCPResult", "LZB", "LZBAnswer", "LZBCertificate",
    "LZBRecord", "LawComparison", "LawOutcome", "LawReport", "LinearForce", "LinearSystem",
    "MassMatrixError", "Membership", "Moreau", "MoreauJeanStep", "Newton", "NoSolutionError",
    "NonConvexLCPError", "NonFiniteError", "NonFiniteStateError", "NonSymmetricLCPError",
    "OptionalDependencyError", "OutOfRangeError", "PhysicalChain", "ProblemFile",
    "ProblemFileError", "ReflectionLaw", "ResidualChecks", "RestitutionError", "SectorCertificate",
    "SectorCone", "SectorInputError", "SectorLaw", "SectorLawCertificate", "SectorLawError",
    "SectorTable", "SectorTableTooLarge", "TableCertificate", "ShapeError", "SolverError",
    "Trajectory", "UnknownBackendError", "available_backends", "ball_chain", "bead_chain",
    "bouncing_ball", "chain", "classify", "compare_chain", "compare_laws",
    "continuous_mass_ratios", "cradle_system", "fremond", "fremond_admissibility_map",
    "hertz_stiffness", "load_problem", "monodisperse_chain", "moreau", "moreau_batch", "newton",
    "newtons_cradle", "random_impact", "reflection_law", "reflection_law_table", "save_problem",
    "sector_law", "sector_law_batch", "sector_law_table", "simulate", "solve", "solve_batch",
    "solve_friction", "solve_lcp", "sphere_mass", "tapered_chain", "verify_law",
    "load_fclib", "save_fclib", "point_on_plane", "sphere_on_plane", "two_spheres",
]
