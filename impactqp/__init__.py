"""impactqp: rigid-body impacts as convex programs.

Problems (:class:`ImpactProblem`, :func:`chain`, :func:`newtons_cradle`), the admissible
set S (:class:`AdmissibleSet`), impact laws (:func:`moreau`, :func:`newton`,
:func:`fremond`), LCPs with symmetric matrices (:func:`solve_lcp`) and the geometric
classification (:func:`classify`). See ``docs`` in the README for the conventions.
"""

from .admissible import AdmissibleSet, Membership
from .certificate import Certificate
from .classify import Classification, classify
from .errors import (BackendUnsuitableError, CertificateError, ImpactError, InputError,
                     MassMatrixError, NoSolutionError, NonConvexLCPError, NonFiniteError,
                     NonSymmetricLCPError, RestitutionError, ShapeError, SolverError,
                     UnknownBackendError)
from .errors import OptionalDependencyError, ProblemFileError
from .files import ProblemFile, load_problem
from .laws import fremond, moreau, newton
from .lcp import LCPResult, solve_lcp
from .problem import ChainInfo, ImpactProblem, ImpactStructure
from .problems import chain, newtons_cradle, random_impact
from .result import ImpactResult
from .save import save_problem

__version__ = "0.1.0"

__all__ = [
    "AdmissibleSet", "BackendUnsuitableError", "Certificate", "CertificateError", "ChainInfo",
    "Classification", "ImpactError", "ImpactProblem", "ImpactResult", "ImpactStructure",
    "InputError", "LCPResult", "MassMatrixError", "Membership", "NoSolutionError",
    "NonConvexLCPError", "NonFiniteError", "NonSymmetricLCPError", "RestitutionError",
    "ShapeError", "SolverError", "UnknownBackendError", "chain", "classify", "fremond",
    "moreau", "newton", "newtons_cradle", "random_impact", "solve_lcp",
    "OptionalDependencyError", "ProblemFile", "ProblemFileError", "load_problem", "save_problem",
]
