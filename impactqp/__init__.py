"""impactqp: rigid-body impacts as convex programs.

Problems (:class:`ImpactProblem`, :func:`chain`, :func:`newtons_cradle`, problem files via
:func:`load_problem` / :func:`save_problem`), the admissible set S (:class:`AdmissibleSet`),
impact laws (:func:`moreau`, :func:`newton`, :func:`fremond`, :func:`sector_law` with its
table :func:`sector_law_table`, :func:`reflection_law` for unequal masses), many impacts at
once (:func:`moreau_batch`, :func:`sector_law_batch`), the law verifier :func:`verify_law`,
LCPs with symmetric matrices (:func:`solve_lcp`) and the geometric classification
(:func:`classify`). Conventions: the README and the geometry note it cites (§1–§7).
"""

from .admissible import AdmissibleSet, Membership
from .batch import BatchResult, moreau_batch, sector_law_batch
from .certificate import Certificate
from .classify import Classification, classify
from .coxeter import continuous_mass_ratios
from .errors import (
                     BackendUnsuitableError,
                     CertificateError,
                     ImpactError,
                     InputError,
                     MassMatrixError,
                     NonConvexLCPError,
                     NonFiniteError,
                     NonSymmetricLCPError,
                     NoSolutionError,
                     OptionalDependencyError,
                     ProblemFileError,
                     RestitutionError,
                     SectorInputError,
                     SectorLawError,
                     SectorTableTooLarge,
                     ShapeError,
                     SolverError,
                     UnknownBackendError,
)
from .files import ProblemFile, load_problem
from .fremond_map import fremond_admissibility_map
from .laws import fremond, moreau, newton
from .lcp import LCPResult, solve_lcp
from .problem import ChainInfo, ImpactProblem, ImpactStructure
from .problems import chain, newtons_cradle, random_impact
from .reflection_law import reflection_law
from .reflection_table import reflection_law_table
from .result import ImpactResult
from .save import save_problem
from .sector import SectorCone, SectorTable, sector_law_table
from .sector_certificate import SectorCertificate
from .sector_law import SectorLawCertificate, sector_law
from .verify import Counterexample, LawReport, verify_law

__version__ = "0.1.0"

__all__ = [
    "AdmissibleSet", "BackendUnsuitableError", "BatchResult", "Certificate", "CertificateError",
    "ChainInfo", "Classification", "Counterexample", "ImpactError", "ImpactProblem",
    "ImpactResult", "ImpactStructure", "InputError", "LCPResult", "LawReport", "MassMatrixError",
    "Membership", "NoSolutionError", "NonConvexLCPError", "NonFiniteError",
    "NonSymmetricLCPError", "OptionalDependencyError", "ProblemFile", "ProblemFileError",
    "RestitutionError", "SectorCertificate", "SectorCone", "SectorInputError",
    "SectorLawCertificate", "SectorLawError", "SectorTable", "SectorTableTooLarge", "ShapeError",
    "SolverError", "UnknownBackendError", "chain", "classify", "continuous_mass_ratios",
    "fremond", "fremond_admissibility_map", "load_problem", "moreau", "moreau_batch", "newton",
    "newtons_cradle", "random_impact", "reflection_law", "reflection_law_table", "save_problem",
    "sector_law", "sector_law_batch", "sector_law_table", "solve_lcp", "verify_law",
]
