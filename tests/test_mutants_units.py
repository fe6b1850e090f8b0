"""The unit of each contact (docs/theory.md §15, "Contact units") against a reference written
here from its definition, written to kill the mutants benchmarks/mutation.py makes of
impactqp/kernels/units.py.

s_c = √W_nn,c where W_nn,c is positive and finite; else the largest positive finite √W_ii of
the contact's block; else the geometric mean of the other contacts' units (1 when none has
one); repeated over the contact's d entries.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from impactqp.kernels.units import contact_units


def _reference(diagonal: np.ndarray, d: int) -> np.ndarray:
    blocks = diagonal.reshape(-1, d)
    units = []
    for block in blocks:
        if 0.0 < block[0] < math.inf:
            units.append(math.sqrt(block[0]))
            continue
        finite = [x for x in block[1:] if 0.0 < x < math.inf]
        units.append(math.sqrt(max(finite)) if finite else None)
    known = [s for s in units if s is not None]
    fallback = math.exp(sum(math.log(s) for s in known) / len(known)) if known else 1.0
    return np.repeat([fallback if s is None else s for s in units], d)


@pytest.mark.parametrize("d", [1, 2, 3])
def test_normal_diagonals_give_their_roots(d):
    rng = np.random.default_rng(d)
    diagonal = rng.uniform(0.1, 9.0, 4 * d)
    got = contact_units(diagonal, d)
    np.testing.assert_allclose(got, np.repeat(np.sqrt(diagonal[::d]), d), rtol=1e-15)
    np.testing.assert_allclose(got, _reference(diagonal, d), rtol=1e-15)


@pytest.mark.parametrize("bad", [0.0, -4.0, np.inf, np.nan])
def test_a_contact_without_a_normal_unit_takes_its_largest_tangential_one(bad):
    diagonal = np.array([4.0, 1.0, 1.0,
                         bad, 16.0, 9.0,   # → √16 = 4, the largest of its block
                         bad, np.inf, 25.0,  # an infinite entry is skipped: √25
                         25.0, 0.5, 0.5])
    got = contact_units(diagonal, 3)
    np.testing.assert_allclose(got, np.repeat([2.0, 4.0, 5.0, 5.0], 3), rtol=1e-15)
    np.testing.assert_allclose(got, _reference(diagonal, 3), rtol=1e-15)


@pytest.mark.parametrize("d", [1, 2, 3])
def test_a_contact_with_no_unit_takes_the_geometric_mean_of_the_others(d):
    diagonal = np.zeros(3 * d)
    diagonal[0] = 4.0  # s = 2
    diagonal[2 * d] = 64.0  # s = 8: geometric mean 4
    if d > 1:
        diagonal[d + 1] = -1.0  # a negative tangential entry is no unit either
    got = contact_units(diagonal, d)
    np.testing.assert_allclose(got, np.repeat([2.0, 4.0, 8.0], d), rtol=1e-14)
    np.testing.assert_allclose(got, _reference(diagonal, d), rtol=1e-14)


@pytest.mark.parametrize("d", [1, 2, 3])
def test_no_contact_with_a_unit_gives_one(d):
    diagonal = np.full(2 * d, 0.0)
    diagonal[0] = np.nan
    np.testing.assert_array_equal(contact_units(diagonal, d), np.ones(2 * d))


def test_the_fallback_is_scale_free():
    """Scaling W by c scales every unit, the fallback included, by √c: a unit of the
    problem's own scale, never an absolute 1."""
    diagonal = np.array([4.0, 1.0, 0.0, 0.0, 9.0, 1.0])
    for c in (1e-6, 1.0, 1e6):
        np.testing.assert_allclose(contact_units(c * diagonal, 2),
                                   math.sqrt(c) * np.repeat([2.0, math.sqrt(6.0), 3.0], 2),
                                   rtol=1e-14)


@pytest.mark.parametrize("d", [1, 3])
def test_one_contact_with_a_unit_lends_it_to_the_others(d):
    """The geometric mean of one unit is that unit."""
    diagonal = np.zeros(3 * d)
    diagonal[d] = 9.0
    np.testing.assert_allclose(contact_units(diagonal, d), np.full(3 * d, 3.0), rtol=1e-15)
