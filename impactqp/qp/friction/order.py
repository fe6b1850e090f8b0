"""Where ``auto`` tries the repairs of Newton (:mod:`.repair`, docs/theory.md §22) among the
friction methods: a choice from the problem's size alone, so that the same problem takes the
same route on any machine."""

from __future__ import annotations

from collections.abc import Sequence

from . import FrictionProgram

REPAIR_FIRST = 1000
"""Fewest contacts of a problem on which ``auto`` tries the repairs before the SOCP route
(:func:`friction_order`): below, a cone program of the whole problem is cheap and the SOCP
route certifies BoxesStack1 (52 contacts) in 81 ms and spheres-in-a-box (256) in 0.25 s,
where the repairs take 0.19 s and 1.2 s; on the 2,020-contact granular flow the repairs
certify in 2.7 s and the SOCP route does not."""


def friction_order(order: Sequence[str], program: FrictionProgram) -> list[str]:
    """The friction methods ``auto`` tries on ``program`` (``order``: the registry's,
    :data:`~impactqp.qp.backends.AUTO_ORDER`): the repairs before the SOCP route on problems
    of at least :data:`REPAIR_FIRST` contacts, right after it below."""
    names = list(order)
    if program.n_contacts < REPAIR_FIRST and {"newton-repair", "clarabel"} <= set(names):
        names.remove("newton-repair")
        names.insert(names.index("clarabel") + 1, "newton-repair")
    return names
