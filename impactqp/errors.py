"""Exception tree of impactqp.

Every error the library raises on purpose derives from :class:`ImpactError`.
Errors caused by the caller's input also derive from :class:`ValueError`, so
``except ValueError`` keeps working for code that does not know impactqp.

This module is public: ``impactqp.errors`` holds every exception class; the top level of
:mod:`impactqp` re-exports the base and the few that callers catch most.
"""

from __future__ import annotations

__all__ = [
    "ImpactError",
    "InputError",
    "ShapeError",
    "NonFiniteError",
    "MassMatrixError",
    "RestitutionError",
    "UnknownBackendError",
    "NonConvexLCPError",
    "NonSymmetricLCPError",
    "OutOfRangeError",
    "ProblemFileError",
    "OptionalDependencyError",
    "BackendUnsuitableError",
    "SolverError",
    "NonFiniteStateError",
    "NoSolutionError",
    "CertificateError",
    "SectorLawError",
    "SectorInputError",
    "SectorTableTooLarge",
    "IntegrationBudgetError",
    "UndrawableSystemError",
    "DerivativeUnsupportedError",
]


class ImpactError(Exception):
    """Root of all impactqp errors."""


class InputError(ImpactError, ValueError):
    """An argument has the wrong shape, type or value; the message names it."""


class ShapeError(InputError):
    """Arrays whose shapes do not fit together."""


class NonFiniteError(InputError):
    """NaN or infinity where a finite number is required."""


class MassMatrixError(InputError):
    """The mass matrix is not symmetric positive definite."""


class RestitutionError(InputError):
    """A restitution coefficient outside [0, 1] (or NaN)."""


class UnknownBackendError(InputError):
    """A backend name that impactqp does not know or cannot load."""


class NonConvexLCPError(InputError):
    """An LCP whose matrix is not symmetric positive semidefinite.

    Such an LCP is not a convex QP; impactqp refuses it instead of answering
    with something that is not a solution.
    """


class NonSymmetricLCPError(NonConvexLCPError):
    """An LCP whose matrix is not symmetric."""


class OutOfRangeError(InputError):
    """An answer whose magnitude floats cannot represent (it would overflow to infinity or
    vanish below the smallest float); the message gives its scale."""


class ProblemFileError(InputError):
    """A problem file that cannot be read: syntax, unknown keys, types, shapes or size."""


class OptionalDependencyError(ImpactError, ImportError):
    """An optional extra (e.g. matplotlib for figures) is needed but not installed."""


class BackendUnsuitableError(ImpactError):
    """A backend cannot handle this program (size, structure); try another one."""


class SolverError(ImpactError):
    """A backend failed or returned an answer that does not pass its certificate."""


class NonFiniteStateError(SolverError):
    """A simulation's state became NaN or infinite (a force that turns non-finite, motion
    beyond the float range); the message gives the time."""


class NoSolutionError(ImpactError):
    """The impact law has no solution for this input (e.g. an unbounded LCP)."""


class CertificateError(SolverError):
    """No backend produced an answer within the certificate's tolerance.

    Attributes
    ----------
    best : object or None
        The best answer that was found and failed its certificate, where the caller can use
        or inspect it (:func:`impactqp.solve_friction` sets a result whose ``status`` is
        ``"not certified"``, with its ABH ``error`` and certificate); None otherwise.
    attempts : list of str
        What was tried, in order (empty where the raiser did not record it).
    """

    def __init__(self, message: str, *, best: object = None,
                 attempts: list[str] | None = None) -> None:
        super().__init__(message)
        self.best = best
        self.attempts = list(attempts or [])

    def __reduce__(self):  # keyword attributes survive pickling (dask workers, processes)
        return (_rebuild_certificate_error,
                (type(self), str(self), self.best, self.attempts))


def _rebuild_certificate_error(cls: type, message: str, best: object,
                               attempts: list[str]) -> CertificateError:
    return cls(message, best=best, attempts=attempts)


class SectorLawError(InputError):
    """The sector law does not apply to this problem (not a chain, walls, unequal masses)."""


class UndrawableSystemError(InputError):
    """An animation was asked of a system whose bodies impactqp does not know (one built
    from matrices); the message says what can be drawn."""


class SectorInputError(InputError):
    """Invalid argument to a sector-law routine (ball count, mass, array shape)."""


class SectorTableTooLarge(InputError):
    """The n! cones of the sector table are too many to enumerate (n_balls > 8)."""


class IntegrationBudgetError(CertificateError):
    """An integration (the LZB model's) would exceed or has spent its budget of steps; the
    message says which budget, why, and what option to change."""


class DerivativeUnsupportedError(ImpactError):
    """The law has no derivative (the LZB model, a user's law without a ``derivative``
    hook; docs/theory.md §20): the message names the law."""
