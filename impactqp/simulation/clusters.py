"""Closed contacts grouped into independent impacts, with their factorized structures cached
(docs/theory.md §14).

Bodies that no closed contact and no entry of the mass matrix connect do not interact in an
impact: the impact LCP splits into one block per connected cluster. Each cluster becomes one
:class:`~impactqp.model.problem.ImpactProblem` on its own degrees of freedom, with an
:class:`~impactqp.model.structure.ImpactStructure` built once per set of contacts and reused
for the rest of the run. On a chain a cluster is a run of touching balls, itself a chain
(docs/theory.md §5): the sector law applies to it and Moreau-type laws take the O(N)
isotonic path.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components

from ..base.arrays import Matrix
from ..laws.small import SHORT_CHAIN
from ..model.builders import chain_directions
from ..model.structure import ChainInfo, ImpactStructure

MAX_CACHED = 4096
"""Structures kept per run; the cache starts afresh when it is full."""


@dataclass(frozen=True)
class Cluster:
    """One independent impact: some degrees of freedom and the closed contacts among them.

    Attributes
    ----------
    dofs : slice or ndarray
        Degrees of freedom of the cluster (a slice for a run of balls of a chain).
    contacts : ndarray
        System indices of its contacts, ascending (the columns of its W, in that order).
    structure : ImpactStructure
        M and W of the cluster, factorized once.
    """

    dofs: slice | np.ndarray
    contacts: np.ndarray
    structure: ImpactStructure

    def dof_indices(self, n: int) -> np.ndarray:
        """The degrees of freedom as an index array."""
        return np.arange(n)[self.dofs]


class ClusterCache:
    """Clusters of any set of closed contacts of one system, for one metric.

    Parameters
    ----------
    metric : (n, n) ndarray or scipy.sparse matrix
        The mass matrix of the impacts (M, or Moreau–Jean's iteration matrix M + h²θ²K).
    H : (n, m) ndarray or scipy.sparse matrix
        Contact directions of the system.
    chain : ChainInfo or None
        The system's chain description; used when the metric is diagonal.
    """

    def __init__(self, metric: Matrix, H: Matrix, chain: ChainInfo | None) -> None:
        self.sparse = sp.issparse(metric) or sp.issparse(H)
        self.metric = sp.csr_matrix(metric) if self.sparse else np.asarray(metric)
        self.H = sp.csc_matrix(H)
        self.n, self.m = self.H.shape
        diag = self.metric.diagonal()
        off = self.metric - (sp.diags(diag) if self.sparse else np.diag(diag))
        coupled = (sp.csr_matrix(off).count_nonzero() if self.sparse
                   else np.count_nonzero(off))
        self.diagonal = np.asarray(diag, dtype=float).ravel() if coupled == 0 else None
        self.chain = chain if chain is not None and self.diagonal is not None else None
        self._coupling = None if coupled == 0 else sp.coo_matrix(off != 0)
        self._decompositions: dict[bytes, tuple[Cluster, ...]] = {}
        self._structures: dict[object, ImpactStructure] = {}

    def clusters(self, closed: np.ndarray) -> tuple[Cluster, ...]:
        """The independent clusters of the closed contacts (a boolean mask over the system's
        contacts), each with its cached structure."""
        key = np.packbits(closed).tobytes()
        found = self._decompositions.get(key)
        if found is None:
            if len(self._decompositions) >= MAX_CACHED:
                self._decompositions.clear()
            contacts = np.flatnonzero(closed)
            groups = self._chain_groups(contacts) if self.chain is not None \
                else self._graph_groups(contacts)
            found = tuple(self._cluster(dofs, c) for dofs, c in groups)
            self._decompositions[key] = found
        return found

    # --- grouping ------------------------------------------------------------------------
    def _chain_groups(self, contacts: np.ndarray) -> list[tuple[slice, np.ndarray]]:
        """Runs of touching balls: gap contact j (after the left wall, if any) joins balls
        j and j + 1; a wall contact belongs to its end ball."""
        first = 1 if self.chain.left_wall else 0
        n = self.n
        ball = np.clip(contacts - first, 0, n - 1)  # the left ball of each contact
        link = np.zeros(max(n - 1, 0), dtype=bool)
        gaps = (contacts >= first) & (contacts < first + n - 1)
        link[contacts[gaps] - first] = True
        label = np.concatenate([[0], np.cumsum(~link)])  # balls joined by links share a label
        starts = np.flatnonzero(np.concatenate([[True], ~link]))  # first ball of each label
        ends = np.concatenate([starts[1:], [n]])
        lab = label[ball]
        cuts = np.flatnonzero(np.diff(lab)) + 1
        return [(slice(int(starts[run[0]]), int(ends[run[0]])), c)
                for c, run in zip(np.split(contacts, cuts), np.split(lab, cuts))]

    def _graph_groups(self, contacts: np.ndarray) -> list[tuple[np.ndarray, np.ndarray]]:
        """Connected components of the graph whose edges are the metric's couplings and the
        bodies each closed contact touches."""
        Hc = self.H[:, contacts]
        rows, cols = [], []
        for j in range(contacts.size):
            support = Hc.indices[Hc.indptr[j]:Hc.indptr[j + 1]]
            rows.append(support[:-1])
            cols.append(support[1:])
        if self._coupling is not None:
            rows.append(self._coupling.row)
            cols.append(self._coupling.col)
        r = np.concatenate(rows) if rows else np.zeros(0, dtype=int)
        c = np.concatenate(cols) if cols else np.zeros(0, dtype=int)
        graph = sp.coo_matrix((np.ones(r.size), (r, c)), shape=(self.n, self.n))
        _, label = connected_components(graph, directed=False)
        first_row = Hc.indices[Hc.indptr[:-1]]
        lab = label[first_row]
        order = np.argsort(lab, kind="stable")
        lab_sorted, contacts_sorted = lab[order], contacts[order]
        cuts = np.flatnonzero(np.diff(lab_sorted)) + 1
        by_label = np.argsort(label, kind="stable")  # dofs grouped by label, ascending
        bounds = np.searchsorted(label[by_label], np.arange(label.max() + 2))
        return [(by_label[bounds[run[0]]:bounds[run[0] + 1]], np.sort(c))
                for c, run in zip(np.split(contacts_sorted, cuts), np.split(lab_sorted, cuts))]

    # --- structures ----------------------------------------------------------------------
    def _cluster(self, dofs: slice | np.ndarray, contacts: np.ndarray) -> Cluster:
        if isinstance(dofs, slice):  # a run of a chain: the structure depends on its masses
            masses = self.diagonal[dofs]
            left = bool(self.chain.left_wall and contacts[0] == 0)
            right = bool(self.chain.right_wall and contacts[-1] == self.m - 1)
            key: object = ("chain", masses.tobytes(), left, right)
        else:
            key = frozenset(contacts.tolist())
        structure = self._structures.get(key)
        if structure is None:
            if len(self._structures) >= MAX_CACHED:
                self._structures.clear()
            structure = self._build(dofs, contacts, key)
            self._structures[key] = structure
        return Cluster(dofs, contacts, structure)

    def _build(self, dofs: slice | np.ndarray, contacts: np.ndarray,
               key: object) -> ImpactStructure:
        if isinstance(dofs, slice):
            # a run of a chain is a chain: dense while the compiled path takes it, sparse
            # beyond (its Delassus matrix then costs O(k))
            masses = self.diagonal[dofs].copy()
            left, right = key[2], key[3]
            sparse = contacts.size > SHORT_CHAIN
            H = chain_directions(masses.size, left_wall=left, right_wall=right, sparse=sparse)
            info = ChainInfo(masses=masses, left_wall=left, right_wall=right)
            M = sp.diags(masses, format="csc") if sparse else np.diag(masses)
            return ImpactStructure(M, H, chain=info)
        H = self.H[dofs, :][:, contacts]
        M = self.metric[dofs][:, dofs]
        if not self.sparse:
            return ImpactStructure(M, H.toarray())
        return ImpactStructure(sp.csc_matrix(M), H)
