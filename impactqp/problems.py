"""Impact problems, public face: M, W and u⁻ with their structure, builders, problem files,
the admissible set S and the geometric classification of a post-impact velocity
(docs/theory.md §1, §2, §4, §5).

The top level of :mod:`impactqp` keeps :class:`ImpactProblem`, :func:`chain`,
:func:`newtons_cradle`, :func:`random_impact`, :func:`load_problem`, :func:`save_problem`,
:class:`AdmissibleSet` and :func:`classify`.
"""

from .io.files import ProblemFile, load_problem
from .io.save import save_problem
from .model.admissible import AdmissibleSet, Membership
from .model.builders import chain, newtons_cradle, random_impact
from .model.classify import Classification, classify
from .model.problem import ImpactProblem
from .model.structure import ChainInfo, ImpactStructure

__all__ = [
    "ImpactProblem", "ImpactStructure", "ChainInfo", "chain", "newtons_cradle",
    "random_impact", "load_problem", "save_problem", "ProblemFile", "AdmissibleSet",
    "Membership", "classify", "Classification",
]
