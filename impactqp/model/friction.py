"""Local frictional contact problems (FCLib's local form) and their certificate
(docs/theory.md §15).

Find r and u = W r + q such that, for every contact c, r_c ∈ K_μc ⟂ ũ_c ∈ K*_μc with
ũ_c = u_c + μ_c‖u_T,c‖e_n (De Saxcé's form of Coulomb's law). W is used as given (never its
symmetric part). Every problem is solved and judged in its contacts' units
(:meth:`FrictionContactProblem.in_contact_units`, docs/theory.md §15); the certificate checks
the defining conditions with formulas written here, which no solver calls, beside ABH's
natural map of :mod:`impactqp.kernels.friction` (docs/theory.md §15).
"""

from __future__ import annotations

import math
from typing import Any, NamedTuple

import numpy as np
import scipy.sparse as sp

from ..base.arrays import as_array, as_count, as_matrix, check_tol
from ..base.checks import FRICTION_TOL, Certificate
from ..errors import InputError, OutOfRangeError, ShapeError
from ..kernels.coulomb_certificate import FRICTION_FIGURES, friction_figures
from ..kernels.friction import kernel_mu, natural_map
from ..kernels.friction_tiny import LOG2_RANGE
from ..kernels.units import contact_units

__all__ = ["ContactUnits", "FrictionCertificate", "FrictionContactProblem", "certify_friction",
           "friction_coefficients"]

QUANTITY_RANGE = (1e-100, 1e100)
"""max|q̃ᵢ| (q in contact units) within which a problem is solved and judged as posed; beyond
it, in units of a power of two near max|q̃ᵢ| (docs/theory.md §15)."""


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
    mu.setflags(write=False)  # a private copy, read-only like the laws' own μ
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

    Notes
    -----
    W, q and μ are the problem's own copies (μ read-only). q may be rewritten in place
    between solves: what impactqp keeps for a problem (its units, a few-contact pack, the
    arrays of qp/friction/data.py) is checked against q and the W and μ objects at each solve
    (:meth:`holds`). W edited in place is not seen: give a new W a new problem.
    """

    _kept: Any = None
    """What a route keeps with the :meth:`state` it was made for (the few-contact route's pack,
    laws/friction_small.py); a class default: reading it builds no ``__dict__``."""

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
        self.W, self.q, self.mu = W, q, mu
        self.contact_dim, self.n_contacts = d, m
        self._units: ContactUnits | None = None
        self._units_state: tuple | None = None

    @classmethod
    def of_checked(cls, W, q: np.ndarray, mu: np.ndarray,
                   contact_dim: int) -> FrictionContactProblem:
        """The problem of arrays impactqp has built and checked itself (W square of size
        d·m and finite, q finite, μ ≥ 0 one per contact): no validation is repeated."""
        problem = cls.__new__(cls)
        problem.W, problem.q, problem.mu = W, q, mu
        problem.contact_dim, problem.n_contacts = contact_dim, mu.size
        problem._units = problem._units_state = None
        return problem

    @classmethod
    def of_contact_units(cls, W, q: np.ndarray, mu: np.ndarray,
                         contact_dim: int) -> FrictionContactProblem:
        """:meth:`of_checked` for a problem impactqp has already posed in its contacts' units
        (normal diagonal one, as :meth:`in_contact_units` makes it): its units are taken as
        s = 1, only the scale-first rule on q is applied."""
        problem = cls.of_checked(W, q, mu, contact_dim)
        problem._units = _units_of(problem, np.ones(q.size))
        problem._units_state = problem.state()
        return problem

    def state(self) -> tuple:
        """What a result kept for this problem depends on (:meth:`holds`): the W and μ
        objects, d, and q's bytes (a simulator may rewrite q in place at each step)."""
        return (self.W, self.mu, self.contact_dim, self.q.tobytes())

    def holds(self, state: tuple | None) -> bool:
        """Whether ``state`` (from :meth:`state`) is still this problem's: the same W and μ
        objects, the same d, and q equal byte for byte."""
        return (state is not None and state[0] is self.W and state[1] is self.mu
                and state[2] == self.contact_dim and state[3] == self.q.tobytes())

    def in_contact_units(self) -> ContactUnits:
        """The problem posed in its contacts' units (docs/theory.md §15): W̃ = DWD,
        q̂ = 2⁻ᵏDq, D = diag(1/s), s = √W_nn of each contact
        (:func:`impactqp.kernels.units.contact_units`) and 2ᵏ = 1 unless max|Dq| lies
        outside :data:`~impactqp.model.friction.QUANTITY_RANGE`, where it is the power of two
        nearest it. Its
        reaction r̂ = 2⁻ᵏ s∘r and velocity û = 2⁻ᵏ u/s; the cones do not change (a positive
        factor per contact), so r solves this problem exactly when r̂ solves that one. The
        same object every time while the problem :meth:`holds` the state it was computed
        for (computed again where q, W or μ has changed since); a problem already in its
        units is its own unit problem.

        Raises
        ------
        OutOfRangeError
            W̃ is not finite (``|W_ij|`` far beyond √(W_ii W_jj)): floats cannot pose it.
        """
        if self._units is None or not self.holds(self._units_state):
            s = contact_units(np.ascontiguousarray(_diagonal(self.W)), self.contact_dim)
            self._units = _units_of(self, s)
            self._units_state = self.state()
        return self._units

    def velocity(self, r: np.ndarray) -> np.ndarray:
        """u = W r + q (as given, in the problem's units)."""
        return np.asarray(self.W @ r).ravel() + self.q

    def dense_W(self) -> np.ndarray:
        """W as a dense float array."""
        return self.W.toarray() if sp.issparse(self.W) else self.W

    def __repr__(self) -> str:
        return (f"FrictionContactProblem(n_contacts={self.n_contacts}, "
                f"contact_dim={self.contact_dim})")


class ContactUnits(NamedTuple):
    """A :class:`FrictionContactProblem` posed in its contacts' units
    (:meth:`FrictionContactProblem.in_contact_units`, docs/theory.md §15).

    Attributes
    ----------
    problem : FrictionContactProblem
        W̃ = DWD and q̂ = 2⁻ᵏDq, D = diag(1/s).
    s : (d·m,) ndarray
        The unit s_c of the contact of each entry.
    k : int
        The scale-first exponent (0 unless max|Dq| lies outside
        :data:`~impactqp.model.friction.QUANTITY_RANGE`).
    """

    problem: FrictionContactProblem
    s: np.ndarray
    k: int

    def reaction(self, r_unit: np.ndarray) -> np.ndarray:
        """r = 2ᵏ r̂/s of the problem as given (inf or 0 where floats do not hold it)."""
        with np.errstate(over="ignore", under="ignore"):
            return np.ldexp(r_unit / self.s, self.k)

    def velocity(self, u_unit: np.ndarray) -> np.ndarray:
        """u = 2ᵏ s∘û of the problem as given."""
        with np.errstate(over="ignore", under="ignore"):
            return np.ldexp(u_unit * self.s, self.k)

    def unit_reaction(self, r: np.ndarray) -> np.ndarray:
        """r̂ = 2⁻ᵏ s∘r."""
        with np.errstate(over="ignore", under="ignore", invalid="ignore"):
            return np.ldexp(r, -self.k) * self.s

    def unit_velocity(self, u: np.ndarray) -> np.ndarray:
        """û = 2⁻ᵏ u/s."""
        with np.errstate(over="ignore", under="ignore", invalid="ignore"):
            return np.ldexp(u, -self.k) / self.s


def _diagonal(W) -> np.ndarray:
    """W's diagonal as a float array."""
    return np.asarray(W.diagonal(), dtype=float).ravel()


def _units_of(problem: FrictionContactProblem, s: np.ndarray) -> ContactUnits:
    """:class:`ContactUnits` of ``problem`` with the units s (the problem itself when s = 1
    and q needs no scaling)."""
    q = problem.q
    mq, eq = np.frexp(q)
    ms, es = np.frexp(s)
    exponents = (eq - es)[q != 0.0]
    top = int(exponents.max()) if exponents.size else 0  # max|qᵢ/sᵢ| in [2^(top−2), 2^top)
    k = 0 if LOG2_RANGE[0] < top < LOG2_RANGE[1] else top
    ones = bool(np.all(s == 1.0))
    if ones and k == 0:
        return ContactUnits(problem, s, 0)
    with np.errstate(under="ignore"):  # entries below 2⁻¹⁰⁷⁴ of the largest are not kept
        q_unit = np.ldexp(mq / ms, eq - es - k)
    if ones:
        W = problem.W
    else:
        D = 1.0 / s
        with np.errstate(over="ignore", invalid="ignore"):
            if sp.issparse(problem.W):
                W = sp.csc_matrix(sp.diags(D) @ problem.W @ sp.diags(D))
                finite = np.isfinite(W.data).all()
            else:
                W = problem.W * D[:, None] * D[None, :]
                finite = np.isfinite(W).all()
        if not finite:
            raise OutOfRangeError("W in its contacts' units (W_ij/√(W_ii W_jj)) is beyond "
                                  "the floats")
    unit = FrictionContactProblem.of_checked(W, q_unit, problem.mu, problem.contact_dim)
    unit._units = ContactUnits(unit, np.ones(q.size), 0)
    unit._units_state = unit.state()
    return ContactUnits(unit, s, k)


FRICTION_CHECKS = ("natural_map", "velocity", "cone", "dual_cone", "complementarity")
"""The residuals of a certificate of :func:`certify_friction`."""

FrictionCertificate = Certificate
"""The certificate of a frictional contact problem is a :class:`~impactqp.results.Certificate`
made by :func:`certify_friction` (the name is kept for code written before there was one
type). Accepted when each of its residuals is within ``tol``, all in contact units:

- natural_map: ‖r̂ − P_K(r̂ − ũ)‖ / ‖q̂‖ (Acary–Brémond–Huber's error, the acceptance
  figure, :func:`impactqp.kernels.friction.natural_map`);
- velocity: ‖û − (W̃ r̂ + q̂)‖ / ‖q̂‖ of the u given with r;

and the defining conditions, by the formulas of
:func:`impactqp.kernels.coulomb_conditions.coulomb_violation_sums`, which no solver calls:

- cone: r̂_c ∈ K_μc (‖r_T‖ ≤ μ r_n), over max(‖q̂‖, ‖r̂‖);
- dual_cone: ũ_c = û_c + μ_c‖û_T,c‖e_n ∈ K_{1/μc} (μ‖ũ_T‖ ≤ ũ_n), over ‖q̂‖;
- complementarity: ``|r̂_c·ũ_c|`` / (‖r̂_c‖ + ‖ũ_c‖) contact by contact, over ‖q̂‖.

Reported beside them (``reported``), not part of the verdict: ``siconos_error``
‖F‖/max(‖q̂‖, ‖r̂‖, ‖û‖) and ``penetration`` ‖(−û_n)₊‖/‖q̂‖; ``extras["error"]`` is the
acceptance figure.
"""


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
                     tol: float = FRICTION_TOL) -> Certificate:
    """Recompute the certificate of a candidate reaction ``r`` (and velocity ``u``) in the
    problem's contacts' units (docs/theory.md §15): r̂, û and q̂ of
    :meth:`FrictionContactProblem.in_contact_units`, û = W̃ r̂ + q̂ recomputed.

    Accepted when each of its residuals is within ``tol``:

    - natural_map: ‖r̂ − P_K(r̂ − ũ)‖ / ‖q̂‖ (Acary–Brémond–Huber's error, the acceptance
      figure, :func:`impactqp.kernels.friction.natural_map`; also the extra ``error``);
    - velocity: ‖û − (W̃ r̂ + q̂)‖ / ‖q̂‖ of the u given with r;

    and the defining conditions, by the formulas of
    :func:`impactqp.kernels.coulomb_conditions.coulomb_violation_sums`, which no solver calls:

    - cone: r̂_c ∈ K_μc (‖r_T‖ ≤ μ r_n), over max(‖q̂‖, ‖r̂‖);
    - dual_cone: ũ_c = û_c + μ_c‖û_T,c‖e_n ∈ K_{1/μc} (μ‖ũ_T‖ ≤ ũ_n), over ‖q̂‖;
    - complementarity: |r̂_c·ũ_c| / (‖r̂_c‖ + ‖ũ_c‖) contact by contact, over ‖q̂‖.

    Reported beside them (``reported``), not part of the verdict: ``siconos_error``
    ‖F‖/max(‖q̂‖, ‖r̂‖, ‖û‖) and ``penetration`` ‖(−û_n)₊‖/‖q̂‖.

    Parameters
    ----------
    problem : FrictionContactProblem
    r : (d·m,) array
        The candidate reaction, in the problem's units.
    u : (d·m,) array, optional
        The candidate velocity; its distance to W r + q is the ``velocity`` residual (0 when
        not given). Every other figure uses u = W r + q recomputed.
    tol : float
        Tolerance of the residuals.

    Raises
    ------
    OutOfRangeError
        The problem cannot be posed in its contacts' units in floats.
    """
    tol = check_tol(tol)
    n = problem.q.size
    r = _candidate("r", r, n)
    if u is not None:
        u = _candidate("u", u, n)
    units = problem.in_contact_units()
    unit = units.problem
    r = units.unit_reaction(r)
    with np.errstate(over="ignore", invalid="ignore"):
        u_w = np.asarray(unit.W @ r).ravel() + unit.q
        mismatch = 0.0 if u is None else _norm(units.unit_velocity(u) - u_w)
        mu = kernel_mu(unit.mu)
        f_norm = _norm(natural_map(r, u_w, mu, unit.contact_dim))
    figures = np.empty(len(FRICTION_FIGURES))
    friction_figures(r, u_w, unit.q, mu, unit.contact_dim, (f_norm, mismatch), figures)
    return friction_certificate(figures, tol)


def friction_certificate(figures: np.ndarray, tol: float) -> Certificate:
    """The :class:`~impactqp.results.Certificate` of the figures of
    :func:`impactqp.kernels.coulomb_certificate.friction_figures` (order
    :data:`~impactqp.kernels.coulomb_certificate.FRICTION_FIGURES`)."""
    values = dict(zip(FRICTION_CHECKS, figures[:5].tolist()))
    reported = {"siconos_error": float(figures[5]), "penetration": float(figures[6])}
    return Certificate(values, tol, reported=reported, names=FRICTION_CHECKS,
                       extras={"error": values["natural_map"]})
