"""Local frictional contact problems (FCLib's local form) and their certificate
(docs/theory.md §15).

Find r and u = W r + q such that, for every contact c, r_c ∈ K_μc ⟂ ũ_c ∈ K*_μc with
ũ_c = u_c + μ_c‖u_T,c‖e_n (De Saxcé's form of Coulomb's law). W is used as given (never its
symmetric part); the formulas are those of :mod:`impactqp.kernels.friction`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import scipy.sparse as sp

from ..base.arrays import as_array, as_count, as_matrix, check_tol
from ..base.checks import NamedChecks
from ..errors import InputError, ShapeError
from ..kernels.friction import certificate_sums

__all__ = ["FrictionCertificate", "FrictionContactProblem", "certify_friction",
           "friction_coefficients"]


def friction_coefficients(value: Any, n_contacts: int, name: str = "mu") -> np.ndarray:
    """Friction coefficients as one per contact: a number spread over the contacts or an
    (m,) array, each finite and ≥ 0.

    Raises
    ------
    NonFiniteError, ShapeError, InputError
        NaN or infinity, a length other than ``n_contacts``, a negative coefficient.
    """
    mu = as_array(name, value)
    if mu.ndim == 0:
        mu = np.full(n_contacts, float(mu))
    if mu.shape != (n_contacts,):
        raise ShapeError(f"{name} must be one number or one per contact ({n_contacts},), got "
                         f"shape {mu.shape}")
    if (mu < 0).any():
        raise InputError(f"{name} must be ≥ 0, got {mu[mu < 0][0]} at contact "
                         f"{int(np.argmax(mu < 0))}")
    return mu


class FrictionContactProblem:
    """The local frictional contact problem u = W r + q, r_c ∈ K_μc ⟂ ũ_c ∈ K*_μc
    (docs/theory.md §15).

    Parameters
    ----------
    W : (d·m, d·m) ndarray or scipy.sparse matrix
        The Delassus operator, used as given (not assumed symmetric).
    q : (d·m,) array
        The free velocity.
    mu : float or (m,) array
        Friction coefficients, each ≥ 0.
    contact_dim : int
        d = 3 (normal, two tangents) or 2 (normal, one tangent, in the plane).

    Raises
    ------
    InputError, ShapeError, NonFiniteError
        A d other than 2 or 3, shapes that do not fit, NaN or infinity, a negative μ.
    """

    def __init__(self, W, q, mu, *, contact_dim: int = 3) -> None:
        d = as_count("contact_dim", contact_dim)
        if d not in (2, 3):
            raise InputError(f"contact_dim must be 2 or 3, got {d}")
        W = as_matrix("W", W)
        q = as_array("q", q, ndim=1)
        n = q.size
        if n == 0 or n % d:
            raise ShapeError(f"q must hold contact_dim = {d} entries per contact (at least "
                             f"one contact), got {n} entries")
        if W.ndim != 2 or W.shape != (n, n):
            raise ShapeError(f"W must have shape ({n}, {n}) to match q, got {W.shape}")
        m = n // d
        mu = friction_coefficients(mu, m)
        self.W = W
        self.q = q
        self.mu = mu
        self.contact_dim = d
        self.n_contacts = m

    @classmethod
    def of_checked(cls, W, q: np.ndarray, mu: np.ndarray,
                   contact_dim: int) -> FrictionContactProblem:
        """The problem of arrays impactqp has built and checked itself (W square of size
        d·m and finite, q finite, μ ≥ 0 one per contact): no validation is repeated."""
        problem = cls.__new__(cls)
        problem.W, problem.q, problem.mu = W, q, mu
        problem.contact_dim, problem.n_contacts = contact_dim, mu.size
        return problem

    def velocity(self, r: np.ndarray) -> np.ndarray:
        """u = W r + q."""
        return np.asarray(self.W @ r).ravel() + self.q

    def dense_W(self) -> np.ndarray:
        """W as a dense float array."""
        return self.W.toarray() if sp.issparse(self.W) else self.W

    def __repr__(self) -> str:
        return (f"FrictionContactProblem(n_contacts={self.n_contacts}, "
                f"contact_dim={self.contact_dim})")


@dataclass(frozen=True)
class FrictionCertificate(NamedChecks):
    """The recomputed checks of one candidate answer (r, u) of a
    :class:`FrictionContactProblem` (docs/theory.md §15).

    Accepted when each of its ``residuals`` is within ``tol``:

    - natural_map: ‖r − P_K(r − ũ)‖ / ‖q‖ with u = W r + q recomputed (Acary–Brémond–Huber's
      error, the acceptance figure);
    - velocity: ‖u − (W r + q)‖ / ‖q‖ of the u given with r;
    - cone: ‖r − P_K(r)‖ / ‖r‖, r in the friction cones.

    Reported beside them (``reported``), not part of the verdict: ``siconos_error``
    ‖F‖/max(‖q‖, ‖r‖, ‖u‖), ``penetration`` ‖(−u_n)₊‖/‖q‖ (ũ ∈ K*_μ reduces to u_n ≥ 0)
    and ``complementarity`` ``Σ_c |r_c·ũ_c| / (‖r‖‖q‖)``.

    Parameters
    ----------
    values : dict
        The accepted residuals by name.
    tol : float
        Tolerance every accepted residual must meet.
    reported : dict
        The figures reported beside them.
    extras : dict, optional
        Anything a solver reports beside the residuals.
    """

    reported: dict = field(default_factory=dict)
    extras: dict = field(default_factory=dict)

    @property
    def error(self) -> float:
        """The acceptance figure ‖F‖/‖q‖ (ABH)."""
        return self.values["natural_map"]

    def summary(self) -> str:
        """One line: the verdict, the tolerance, the residuals and the reported figures."""
        extra = ", ".join(f"{k}={v:.1e}" for k, v in self.reported.items())
        return f"{super().summary()}; reported: {extra}"


def _ratio(num: float, den: float) -> float:
    """num/den for the certificate: 0 when num is 0, NaN as +inf."""
    if num == 0.0:
        return 0.0
    v = num / den if den > 0.0 else math.inf
    return v if v == v else math.inf


QUANTITY_RANGE = (1e-100, 1e100)
"""max|qᵢ| within which the certificate's sums of squares are formed as given."""


def _norm(x: np.ndarray) -> float:
    """‖x‖₂ of a float vector (as numpy's norm computes it, √(x·x))."""
    return math.sqrt(float(x @ x))


def _candidate(name: str, value, n: int) -> np.ndarray:
    """A candidate vector of length n as floats (NaN and infinity allowed: they fail the
    certificate); a float vector impactqp made itself is taken as it is."""
    if not (isinstance(value, np.ndarray) and value.dtype == np.float64 and value.ndim == 1):
        value = as_array(name, value, ndim=1, allow_nonfinite=True)
    if value.shape != (n,):
        raise ShapeError(f"{name} must have shape ({n},), got {value.shape}")
    return value


def certify_friction(problem: FrictionContactProblem, r, u=None, *,
                     tol: float = 1e-8) -> FrictionCertificate:
    """Recompute the certificate of a candidate reaction ``r`` (and velocity ``u``).

    Parameters
    ----------
    problem : FrictionContactProblem
    r : (d·m,) array
        The candidate reaction.
    u : (d·m,) array, optional
        The candidate velocity; its distance to W r + q is the ``velocity`` residual (0 when
        not given). Every other figure uses u = W r + q recomputed.
    tol : float
        Tolerance of the residuals.
    """
    tol = check_tol(tol)
    n = problem.q.size
    r = _candidate("r", r, n)
    q = problem.q
    if u is not None:
        u = _candidate("u", u, n)
    # every figure is a ratio, invariant under (r, u, q) → (r, u, q)/c: far from order one
    # (‖q‖² would underflow or overflow) they are computed in units of c = max|qᵢ|
    c = float(np.abs(q).max())
    if c > 0.0 and not QUANTITY_RANGE[0] < c < QUANTITY_RANGE[1]:
        with np.errstate(over="ignore", under="ignore", invalid="ignore"):
            q, r = q / c, r / c
            u = None if u is None else u / c
    u_w = np.asarray(problem.W @ r).ravel() + q
    qn = _norm(q)
    q_scale = qn if qn > 0.0 else 1.0
    consistency = 0.0
    if u is not None:
        consistency = _ratio(_norm(u - u_w), q_scale)
    f2, comp, pen, cone = certificate_sums(r, u_w, problem.mu, problem.contact_dim)
    fn = math.sqrt(f2)
    rn = _norm(r)
    un = _norm(u_w)
    values = {"natural_map": _ratio(fn, q_scale), "velocity": consistency,
              "cone": _ratio(math.sqrt(cone), rn)}
    reported = {"siconos_error": _ratio(fn, max(qn, rn, un)),
                "penetration": _ratio(math.sqrt(pen), q_scale),
                "complementarity": _ratio(comp, rn * q_scale)}
    return FrictionCertificate(values, tol, reported)
