"""The solvers that the registry's families ``"cvxpy"`` and ``"qpsolvers"`` reach by name,
with the package and the extra of impactqp that brings each (pyproject.toml), and the error
that refuses one that is not installed by name, with what to install."""

from __future__ import annotations

from dataclasses import dataclass

from ...errors import UnknownBackendError


@dataclass(frozen=True)
class Solver:
    """A solver that the families ``"cvxpy"`` and ``"qpsolvers"`` reach by name.

    Attributes
    ----------
    name : str
        Its name in lower case, as qpsolvers spells it (cvxpy spells it in upper case).
    package : str
        The package on PyPI that brings it.
    extra : str or None
        The extra of impactqp that installs it: ``""`` for a dependency of impactqp itself,
        None when no extra does.
    families : tuple of str
        The registry families that run it.
    """

    name: str
    package: str
    extra: str | None
    families: tuple[str, ...]

    def spelled(self, family: str) -> str:
        """Its name as ``family`` spells it after the colon (``"cvxpy:SCS"``,
        ``"qpsolvers:scs"``)."""
        return self.name.upper() if family == "cvxpy" else self.name

    @property
    def install(self) -> str:
        """What to install for it."""
        if self.extra == "":
            return f"{self.package}, a dependency of impactqp (reinstall impactqp)"
        if self.extra is None:
            return f"pip install {self.package} (no extra of impactqp installs it)"
        return f"pip install 'impactqp[{self.extra}]' (adds {self.package})"


_BOTH = ("cvxpy", "qpsolvers")
SOLVERS: dict[str, Solver] = {s.name: s for s in (
    Solver("clarabel", "clarabel", "", _BOTH),
    Solver("osqp", "osqp", "", _BOTH),
    Solver("daqp", "daqp", "solvers", _BOTH),
    Solver("piqp", "piqp", "solvers", _BOTH),
    Solver("quadprog", "quadprog", "solvers", ("qpsolvers",)),
    Solver("ecos", "ecos", "solvers", _BOTH),
    Solver("scs", "scs", "solvers", _BOTH),
    Solver("highs", "highspy", "solvers", _BOTH),
    Solver("proxqp", "proxsuite", None, _BOTH),
)}
"""The solvers impactqp names for its families with sub-solvers, with the extra that
installs each (pyproject.toml: Clarabel and OSQP come with impactqp, the ``solvers`` extra
brings the others but ProxQP); :func:`impactqp.qp.backends.sub_solvers` says which are
installed."""


def missing_solver(family: str, solver: str, installed: tuple[str, ...]) -> UnknownBackendError:
    """The error for ``"family:solver"`` when ``family`` has no ``solver`` installed: it names
    the backend and what to install (the extra of impactqp that brings it)."""
    known = SOLVERS.get(solver.lower())
    have = ", ".join(installed) or "none"
    if known is not None and family in known.families:
        return UnknownBackendError(f"backend '{family}:{solver}' is not installed: "
                                   f"{known.install}; installed for {family}: {have}")
    extras = ", ".join(s.spelled(family) for s in SOLVERS.values()
                       if family in s.families and s.extra)
    return UnknownBackendError(f"backend '{family}:{solver}' is not installed: {family} has no "
                               f"solver {solver!r} here (installed for {family}: {have}; "
                               f"pip install 'impactqp[solvers]' adds {extras})")
