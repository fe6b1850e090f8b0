"""Duplicate and parallel contacts collapsed before an impact is solved (docs/theory.md §1).

Contacts whose columns of W point the same way, wⱼ = cⱼ w_g with cⱼ > 0, constrain the
same contact velocity γ_g = w_gᵀu and push along the same direction: for a law of a
compiled family with one coefficient per contact (``law.restitution_per_contact``: Moreau's
law, local Newton) when their coefficients agree, the impact equals the one with each group
replaced by its representative w_g. Its impulse Λ_g is split back as λⱼ = Λ_g / (k_g cⱼ)
over the k_g members, so Σⱼ wⱼλⱼ = w_gΛ_g, every λⱼ ≥ 0, and each member's complementarity
holds with γⱼ = cⱼγ_g. The answer is certified on the original problem.

Thousands of copies of one contact make the impulse form an LCP of that size (a dense G of
rank n); collapsed, it is an impact with at most n independent-looking contacts. The
grouping sorts the normalized columns, O(n m log m).
"""

from __future__ import annotations

import weakref
from typing import NamedTuple

import numpy as np
import scipy.sparse as sp

from ..base.arrays import as_dense
from ..model.problem import ImpactProblem
from ..model.structure import ImpactStructure
from .base import FAMILIES, MOREAU_FAMILY, Answer, ImpactLaw

MAX_ENTRIES = 50_000_000
"""Largest n·m that is searched for parallel columns (the search forms the dense W)."""

PARALLEL_TOL = 1e-13
"""Normalized columns closer than this (largest entry difference) are the same direction."""


class Groups(NamedTuple):
    """Parallel columns of one W: ``representative[g]`` is the first column of group g,
    ``label[j]`` the group of column j and ``ratio[j] = ‖wⱼ‖ / ‖w_g‖``."""

    representative: np.ndarray
    label: np.ndarray
    ratio: np.ndarray
    reduced: ImpactStructure


_GROUPS: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def parallel_groups(structure: ImpactStructure) -> Groups | None:
    """The groups of parallel columns of the structure's W, with the reduced structure; None
    when no two columns are parallel or W is too large to search (kept per structure)."""
    if structure in _GROUPS:
        return _GROUPS[structure]
    _GROUPS[structure] = found = _find(structure)
    return found


def _find(structure: ImpactStructure) -> Groups | None:
    n, m = structure.n, structure.m
    if m < 2 or n * m > MAX_ENTRIES:
        return None
    W = as_dense(structure.W)
    norms = np.abs(W).max(axis=0)
    U = W / norms
    order = np.lexsort(U[::-1])
    same = np.all(np.abs(np.diff(U[:, order], axis=1)) <= PARALLEL_TOL, axis=0)
    if not same.any():
        return None
    group_sorted = np.concatenate([[0], np.cumsum(~same)])
    label = np.empty(m, dtype=np.intp)
    label[order] = group_sorted
    first = np.full(group_sorted[-1] + 1, m, dtype=np.intp)
    np.minimum.at(first, label, np.arange(m))
    # groups numbered by their first column, so the reduced W keeps the original order
    rank = np.empty_like(first)
    rank[np.argsort(first, kind="stable")] = np.arange(first.size)
    label, representative = rank[label], np.sort(first)
    ratio = norms / norms[representative][label]
    Wr = W[:, representative]
    reduced = ImpactStructure(structure.M, sp.csc_matrix(Wr) if structure.sparse else Wr)
    return Groups(representative, label, ratio, reduced)


def collapsible(problem: ImpactProblem, law: ImpactLaw) -> Groups | None:
    """The groups to collapse ``problem`` by, when ``law`` acts alike on every member of each
    group (a law of a compiled family with ``restitution_per_contact``, one coefficient per
    group: Moreau's law, local Newton) and there are more contacts than degrees of freedom
    (fewer are answered as they are); else None."""
    if (problem.n_impulses <= problem.n_dof or law.family not in FAMILIES
            or not law.restitution_per_contact):
        return None
    groups = parallel_groups(problem.structure)
    if groups is None:
        return None
    if law.family == MOREAU_FAMILY:  # one ε for every contact
        return groups
    e = np.asarray(law.restitution(problem.n_contacts))
    if e.ndim != 1 or np.any(e != e[groups.representative][groups.label]):
        return None
    return groups


def reduced_law(law: ImpactLaw, groups: Groups) -> ImpactLaw:
    """The law on the representatives (Newton's coefficients taken at them)."""
    return law.restrict(groups.representative)


def expand(answer: Answer, groups: Groups) -> Answer:
    """The reduced answer on the original contacts: λⱼ = Λ_g / (k_g cⱼ)."""
    count = np.bincount(groups.label)
    impulses = answer.impulses[groups.label] / (count[groups.label] * groups.ratio)
    return Answer(answer.u_plus, impulses, answer.z)
