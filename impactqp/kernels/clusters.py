"""Closed contacts grouped into independent impacts in compiled code (docs/theory.md §14):
the connected components of the graph whose edges are the couplings of the metric and the
degrees of freedom each closed contact touches, found by union–find, numbered by their first
degree of freedom as :class:`impactqp.simulation.clusters.ClusterCache` numbers them."""

from __future__ import annotations

import numpy as np

from .jit import kernel


@kernel(internal=True)
def _root(parent, i):
    """The root of i in the union–find forest, halving the path on the way."""
    while parent[i] != i:
        parent[i] = parent[parent[i]]
        i = parent[i]
    return i


@kernel(internal=True)
def _join(parent, a, b):
    """Merge the sets of a and b; the smaller index becomes the root, so every root is the
    first degree of freedom of its set."""
    ra = _root(parent, a)
    rb = _root(parent, b)
    if ra < rb:
        parent[rb] = ra
    elif rb < ra:
        parent[ra] = rb


@kernel(internal=True)
def group_work(n):
    """Scratch of :func:`group` for n degrees of freedom: (parent, cluster of each root,
    fill pointers of dofs and of contacts)."""
    return (np.empty(n, dtype=np.int64), np.empty(n, dtype=np.int64),
            np.empty(n, dtype=np.int64), np.empty(n, dtype=np.int64))


@kernel
def group(closed, Ht_ptr, Ht_idx, couple_a, couple_b, work, dofs, cons, n_of, m_of):
    """The clusters of the closed contacts (a boolean mask): returns their number c, with
    cluster a's degrees of freedom ``dofs[n_of[a]:n_of[a + 1]]`` and contacts
    ``cons[m_of[a]:m_of[a + 1]]``, both ascending.

    Contact i touches dofs ``Ht_idx[Ht_ptr[i]:Ht_ptr[i + 1]]``; the metric couples the
    pairs (couple_a[p], couple_b[p]); ``work`` is :func:`group_work`'s scratch.
    """
    parent, cluster_of, fill_n, fill_m = work
    n, m = parent.size, closed.size
    for i in range(n):
        parent[i] = i
    for p in range(couple_a.size):
        _join(parent, couple_a[p], couple_b[p])
    for i in range(m):
        if closed[i]:
            for p in range(Ht_ptr[i] + 1, Ht_ptr[i + 1]):
                _join(parent, Ht_idx[Ht_ptr[i]], Ht_idx[p])
    for i in range(n):
        cluster_of[i] = -1
    for i in range(m):  # roots (each component's first dof) with a closed contact
        if closed[i]:
            cluster_of[_root(parent, Ht_idx[Ht_ptr[i]])] = -2
    count = 0
    for i in range(n):  # numbered in the order of their first dof
        if cluster_of[i] == -2:
            cluster_of[i] = count
            count += 1
    for a in range(count + 1):
        n_of[a] = 0
        m_of[a] = 0
    for i in range(n):  # counting sort of dofs and contacts by cluster
        a = cluster_of[_root(parent, i)]
        if a >= 0:
            n_of[a + 1] += 1
    for i in range(m):
        if closed[i]:
            m_of[cluster_of[_root(parent, Ht_idx[Ht_ptr[i]])] + 1] += 1
    for a in range(count):
        n_of[a + 1] += n_of[a]
        m_of[a + 1] += m_of[a]
        fill_n[a] = n_of[a]
        fill_m[a] = m_of[a]
    for i in range(n):
        a = cluster_of[_root(parent, i)]
        if a >= 0:
            dofs[fill_n[a]] = i
            fill_n[a] += 1
    for i in range(m):
        if closed[i]:
            a = cluster_of[_root(parent, Ht_idx[Ht_ptr[i]])]
            cons[fill_m[a]] = i
            fill_m[a] += 1
    return count
