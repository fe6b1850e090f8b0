"""Cone programs: the backend-neutral form of every second-order cone program of impactqp
(docs/theory.md §9).

    minimize    ½ xᵀ P x + cᵀ x
    subject to  A x + s = b,   s ∈ K = K₁ × … × K_p

with P symmetric positive semidefinite (or absent: a linear objective) and each Kⱼ one of

* ``Cone("zero", k)``: s = 0 (k equations);
* ``Cone("nonnegative", k)``: s ≥ 0;
* ``Cone("soc", k)``: the second-order cone {(t, w) ∈ ℝ × ℝᵏ⁻¹ : ‖w‖₂ ≤ t}.

The cones take the rows of A in the order listed. The multipliers z of the rows satisfy
P x + c + Aᵀz = 0 and z ∈ K* (free on a zero cone; the other cones are self-dual), with
sⱼᵀzⱼ = 0 on each cone. :meth:`ConeProgram.certificate` recomputes all of this from the
program and (x, z) alone, whatever backend produced them; backends never learn which law or
model built the program.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property
from typing import Any, NamedTuple

import numpy as np
import scipy.sparse as sp

from ..base.arrays import as_array, as_count, as_matrix
from ..base.checks import Certificate
from ..errors import InputError, ShapeError
from ..kernels.friction import project_cones

CONE_KINDS = ("zero", "nonnegative", "soc")
"""The cones a :class:`ConeProgram` may list."""


class Cone(NamedTuple):
    """One factor of K: ``kind`` (one of :data:`CONE_KINDS`) over ``size`` consecutive rows."""

    kind: str
    size: int


def as_cones(cones: Any) -> tuple[Cone, ...]:
    """Validated cones from a sequence of :class:`Cone` or ``(kind, size)`` pairs.

    Raises
    ------
    InputError
        An unknown kind, a size that is not a whole number, a second-order cone of size < 1
        or a negative size.
    """
    if isinstance(cones, (str, bytes)) or not hasattr(cones, "__iter__"):
        raise InputError(f"cones must be a sequence of (kind, size) pairs, got "
                         f"{type(cones).__name__}")
    out = []
    for j, cone in enumerate(cones):
        if not isinstance(cone, tuple) or len(cone) != 2:
            raise InputError(f"cone {j} must be a (kind, size) pair such as ('soc', 3), got "
                             f"{cone!r}")
        kind, size = cone
        if kind not in CONE_KINDS:
            raise InputError(f"cone {j} has kind {kind!r}; the kinds are "
                             + ", ".join(map(repr, CONE_KINDS)))
        size = as_count(f"the size of cone {j} ({kind})", size,
                        minimum=1 if kind == "soc" else 0)
        out.append(Cone(kind, size))
    return tuple(out)


def friction_cone_rows(mu: np.ndarray, d: int) -> tuple[sp.csc_matrix, list[Cone]]:
    """The map C and the cones with C r ∈ K exactly when every r_c lies in its Coulomb cone
    K_μc = {‖r_T‖ ≤ μ_c r_n} (d components per contact, the normal first; docs/theory.md §9,
    §15): frictionless contacts (μ_c = 0) first, as r_n ≥ 0 then r_T = 0, then one
    second-order cone (μ_c r_n, r_T) per rough contact. Empty cones are left out.
    """
    free, rough = np.flatnonzero(mu == 0.0), np.flatnonzero(mu > 0.0)
    tangents = np.arange(1, d)
    cols = np.concatenate([free * d, (free[:, None] * d + tangents).ravel(),
                           (rough[:, None] * d + np.arange(d)).ravel()])
    vals = np.ones(cols.size)
    vals[cols.size - rough.size * d::d] = mu[rough]
    C = sp.csc_matrix((vals, (np.arange(cols.size), cols)), shape=(cols.size, mu.size * d))
    cones = [Cone("nonnegative", free.size), Cone("zero", free.size * (d - 1))] + \
        [Cone("soc", d)] * rough.size
    return C, [cone for cone in cones if cone.size]


def _asymmetry(P: Any) -> tuple[float, float]:
    """(max |P − Pᵀ|, max |P|); small sparse matrices are compared dense (faster)."""
    if sp.issparse(P):
        if P.shape[0] > 300:
            D = P - P.T
            return (float(np.abs(D.data).max(initial=0.0)),
                    float(np.abs(P.data).max(initial=0.0)))
        P = P.toarray()
    return float(np.abs(P - P.T).max(initial=0.0)), float(np.abs(P).max(initial=0.0))


@dataclass(frozen=True)
class ConeProgram:
    """min ½xᵀPx + cᵀx  s.t.  Ax + s = b, s ∈ K (the cones of :attr:`cones`, in row order).

    The arrays are checked on construction (shapes, finiteness, P symmetric) and kept as
    float arrays, A and P sparse (CSC) when given sparse.

    Attributes
    ----------
    P : (k, k) ndarray or sparse, or None
        Symmetric positive semidefinite; None for a linear objective.
    c : (k,) ndarray
    A : (r, k) ndarray or sparse
    b : (r,) ndarray
    cones : tuple of Cone
        Sizes summing to r.

    Raises
    ------
    ShapeError
        Shapes that do not fit, or cone sizes that do not add up to the rows of A.
    NonFiniteError
        NaN or infinity in P, c, A or b.
    InputError
        A non-symmetric P or a bad cone (see :func:`as_cones`).
    """

    P: Any
    c: np.ndarray
    A: Any
    b: np.ndarray
    cones: tuple[Cone, ...] = field(default=())

    def __post_init__(self) -> None:
        c = as_array("c", self.c, ndim=1)
        A = as_matrix("A", self.A)
        b = as_array("b", self.b, ndim=1)
        cones = as_cones(self.cones)
        if A.ndim != 2 or A.shape[1] != c.size:
            raise ShapeError(f"A must have {c.size} columns (the size of c), got shape "
                             f"{A.shape}")
        if b.size != A.shape[0]:
            raise ShapeError(f"b must have {A.shape[0]} entries (the rows of A), got {b.size}")
        rows = sum(cone.size for cone in cones)
        if rows != A.shape[0]:
            raise ShapeError(f"the cone sizes add up to {rows} rows but A has {A.shape[0]}: "
                             "list one cone for every row, in order")
        P = None if self.P is None else as_matrix("P", self.P)
        if P is not None:
            if P.shape != (c.size, c.size):
                raise ShapeError(f"P must be {c.size} × {c.size}, got {P.shape}")
            asym, scale = _asymmetry(P)
            if asym > 1e-12 * scale:
                raise InputError(f"P must be symmetric (largest |P − Pᵀ| = {asym:.1e})")
        for name, value in (("P", P), ("c", c), ("A", A), ("b", b), ("cones", cones)):
            object.__setattr__(self, name, value)

    @property
    def n_vars(self) -> int:
        """Number of variables k."""
        return int(self.c.size)

    @property
    def n_constraints(self) -> int:
        """Number of rows r of A."""
        return int(self.b.size)

    @property
    def sparse(self) -> bool:
        """True when A or P is a scipy.sparse matrix."""
        return sp.issparse(self.A) or sp.issparse(self.P)

    @cached_property
    def blocks(self) -> dict[str, np.ndarray]:
        """Row indices of each kind: ``"zero"``, ``"nonnegative"`` and ``"soc:k"`` for the
        second-order cones of size k (their rows cone after cone, the axis t first)."""
        found: dict[str, list[int]] = {}
        start = 0
        for cone in self.cones:
            key = cone.kind if cone.kind != "soc" else f"soc:{cone.size}"
            found.setdefault(key, []).extend(range(start, start + cone.size))
            start += cone.size
        return {key: np.array(rows, dtype=np.int64) for key, rows in found.items()}

    @cached_property
    def _At(self) -> Any:
        """Aᵀ, formed once (CSR when A is sparse)."""
        return self.A.T.tocsr() if sp.issparse(self.A) else self.A.T

    @cached_property
    def cone_of_row(self) -> np.ndarray:
        """For each row, the index of its cone in :attr:`cones`."""
        return np.repeat(np.arange(len(self.cones)), [cone.size for cone in self.cones])

    def project(self, s: np.ndarray, *, dual: bool = False) -> np.ndarray:
        """The Euclidean projection of ``s`` onto K (onto K* with ``dual``: a zero cone's
        dual is the whole space). Second-order cones use the one closed form of
        :func:`impactqp.kernels.friction.project_cones` with μ = 1."""
        out = np.array(s, dtype=float)
        for key, rows in self.blocks.items():
            if key == "zero":
                if not dual:
                    out[rows] = 0.0
            elif key == "nonnegative":
                out[rows] = np.maximum(out[rows], 0.0)
            else:
                size = int(key.split(":")[1])
                out[rows] = project_cones(out[rows], np.ones(rows.size // size), size)
        return out

    def objective(self, x: np.ndarray) -> float:
        """½xᵀPx + cᵀx."""
        quad = 0.0 if self.P is None else 0.5 * float(x @ (self.P @ x))
        return quad + float(self.c @ x)

    def certificate(self, x: np.ndarray, z: np.ndarray, tol: float) -> Certificate:
        """The residuals of a primal-dual pair, recomputed from the program (docs/theory.md
        §9), each relative to one plus the size of what it compares:

        * ``primal``: ‖s − P_K(s)‖∞ with s = b − Ax;
        * ``dual``: ‖z − P_K*(z)‖∞;
        * ``stationarity``: ‖Px + c + Aᵀz‖∞;
        * ``complementarity``: maxⱼ |sⱼᵀzⱼ| over the cones other than zero cones, relative
          to one plus the objectives' sizes or to ‖sⱼ‖‖zⱼ‖ when larger (then it is the
          cosine of the angle between sⱼ and zⱼ, meaningful even when the multipliers grow
          without bound, as on a program without a strictly feasible point);
        * ``gap``: primal objective ½xᵀPx + cᵀx minus dual objective −½xᵀPx − bᵀz.
        """
        x = np.asarray(x, dtype=float)
        z = np.asarray(z, dtype=float)
        Ax = np.asarray(self.A @ x).ravel()
        s = self.b - Ax
        Px = np.zeros_like(x) if self.P is None else np.asarray(self.P @ x).ravel()
        Atz = np.asarray(self._At @ z).ravel()
        primal_obj = self.objective(x)
        dual_obj = -0.5 * float(x @ Px) - float(self.b @ z)
        size = 1.0 + abs(primal_obj) + abs(dual_obj)
        rows = self.cone_of_row
        count = len(self.cones)
        per_cone = np.abs(np.bincount(rows, weights=s * z, minlength=count)) / np.maximum(
            size, np.sqrt(np.bincount(rows, weights=s * s, minlength=count)
                          * np.bincount(rows, weights=z * z, minlength=count)))
        per_cone[[cone.kind == "zero" for cone in self.cones]] = 0.0

        def inf(v: np.ndarray) -> float:
            return float(np.abs(v).max()) if v.size else 0.0

        return Certificate({
            "primal": inf(s - self.project(s)) / (1.0 + max(inf(self.b), inf(Ax))),
            "dual": inf(z - self.project(z, dual=True)) / (1.0 + inf(z)),
            "stationarity": inf(Px + self.c + Atz) / (1.0 + max(inf(Px), inf(self.c),
                                                                inf(Atz))),
            "complementarity": float(np.max(per_cone, initial=0.0)),
            "gap": abs(primal_obj - dual_obj) / size,
        }, tol)


@dataclass(frozen=True)
class ConeSolution:
    """A backend's answer to a :class:`ConeProgram`.

    Attributes
    ----------
    x : ndarray
        The primal variables.
    z : ndarray
        The multipliers of the rows (in K*, the dual of each listed cone).
    s : ndarray
        The slacks b − Ax as the backend reports them.
    status : str
        The backend's own status (``"solved"``, ``"solved_inaccurate"``, ``"optimal"``, ...).
    backend : str
        Who solved it (``"clarabel"``, ``"cvxpy:ECOS"``, ...).
    iterations : int or None
    checks : Certificate or None
        The certificate recomputed by :meth:`ConeProgram.certificate`; set by
        :func:`impactqp.qp.cone_solve.solve_cone`, None straight from a backend.
    """

    x: np.ndarray
    z: np.ndarray
    s: np.ndarray
    status: str
    backend: str
    iterations: int | None = None
    checks: Certificate | None = None
