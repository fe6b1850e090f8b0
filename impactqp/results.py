"""Results and certificates, public face: what the solvers return and the certificate every
answer carries, recomputed from u⁺ and Λ (docs/theory.md §8).

The top level of :mod:`impactqp` keeps :class:`ImpactResult` and :class:`Answer`.
"""

from .base.checks import DEFAULT_TOL, ResidualChecks
from .derivatives.batch import DerivativeBatch
from .derivatives.certificate import Audit, DerivativeCertificate
from .derivatives.impact import ImpactDerivative, Tangents
from .derivatives.local import Kink, LinearPiece, LocalMap
from .laws.base import Answer
from .laws.batch import BatchResult
from .laws.certificate import Certificate, SectorLawCertificate
from .laws.result import ImpactResult
from .qp.lcp import LCPResult

__all__ = [
    "ImpactResult", "Answer", "BatchResult", "LCPResult", "ResidualChecks", "Certificate",
    "SectorLawCertificate", "DEFAULT_TOL", "ImpactDerivative", "DerivativeCertificate",
    "DerivativeBatch", "Audit", "Tangents", "Kink",
    "LinearPiece", "LocalMap",
]
