"""Many impacts of one problem structure at once (k pre-impact velocities, rows of a matrix),
through the same law objects as single impacts.

The route comes from the planner that :func:`impactqp.solve` asks too
(:func:`impactqp.laws.planner.plan`, mode ``"batch"``): dense impacts of the laws of a
compiled family run the compiled impact row by row, certificate included; Moreau's family
on a short chain runs in compiled passes over blocks of rows; closed-form laws run on all
rows at once; other program laws run on a fast-path backend that solves many linear terms
at once (isotonic regression for chains, the active-set search); rows they cannot settle,
and every row of other structures, go through :func:`impactqp.solve`. Every row's
certificate is recomputed by the law; a row that fails it is solved again on its own, which
raises if no backend certifies it, so a returned batch is certified row by row.
"""

from __future__ import annotations

from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..base.arrays import as_array, as_count
from ..base.checks import DEFAULT_TOL, BatchCertificate, certified_rows
from ..errors import BackendUnsuitableError, CertificateError, InputError, ShapeError
from ..kernels.impact import solve_impact_rows
from ..kernels.jit import read_only
from ..kernels.residuals import RESIDUALS
from ..model.problem import ImpactProblem
from ..qp import backends
from ..qp.certified import FAST_PATHS
from . import batch_out, small
from .base import MOREAU_FAMILY, ImpactLaw
from .batch_out import Buffers
from .chain_rows import ChainRows
from .moreau import Moreau
from .pipeline import solve
from .planner import check_problem, plan, validate
from .sector import SectorLaw


@dataclass(frozen=True)
class BatchResult:
    """k impacts of one structure.

    Attributes
    ----------
    u_plus : (k, n) ndarray
    impulses : (k, m) ndarray
    residuals : dict of (k,) ndarrays
        The certificate's residuals per row (keys as :attr:`Certificate.residuals`).
    backend : str
        The path used for most rows (``"isotonic"``, ``"kernel"`` or a QP backend).
    resolved : int
        How many rows the vectorised path left to the single-impact law.
    tol : float
    """

    u_plus: np.ndarray
    impulses: np.ndarray
    residuals: dict
    backend: str
    resolved: int
    tol: float

    @property
    def ok(self) -> np.ndarray:
        """Per-row verdict of the certificate (all True in a returned batch)."""
        return self.certificate.ok

    @property
    def certificate(self) -> BatchCertificate:
        """The per-row residuals as a certificate (``.ok`` per row, ``.worst``)."""
        return BatchCertificate(self.residuals, self.tol)

    status = "solved"

    @property
    def message(self) -> str:
        name, value = self.certificate.worst
        return (f"{len(self.u_plus)} impacts by {self.backend} ({self.resolved} re-solved one "
                f"by one); worst {name} = {value:.1e}")


def as_rows(problem: ImpactProblem, U_minus: Any) -> np.ndarray:
    """Validate a (k, n) matrix of pre-impact velocities."""
    U = as_array("U_minus", U_minus, copy=False)  # only read
    if U.ndim != 2 or U.shape[1] != problem.n_dof:
        raise ShapeError(f"U_minus must have shape (k, {problem.n_dof}), got {U.shape}")
    return U


def _fast_path(problem: ImpactProblem, law: ImpactLaw, backend: str):
    """(backend name, form, program) of a vectorised fast path for ``law``, or None."""
    if problem.n_contacts == 0:
        return None
    names = FAST_PATHS if backend == "auto" else (backend,) if backend in FAST_PATHS else ()
    reasons = []
    for name in names:
        entry = backends.REGISTRY[name]
        for form in law.preferred_forms(problem):
            if form not in backends.FORMS:  # rows of a frictional problem go one by one
                continue
            qp = law.program(problem, form)
            reason = backends.unsuitable(entry, qp, form)
            if reason is None:
                return name, form, qp
            reasons.append(reason)
    if backend in FAST_PATHS:
        raise BackendUnsuitableError("; ".join(reasons) or
                                     f"{law.title} has no program for {backend!r}")
    return None


CHUNK_ROWS = 1 << 14
"""Rows per chunk: the columns of a chunk's temporaries stay in the L2 cache and memory
beyond input and output stays bounded (measured on the 3-ball cradle from 2¹¹ to 2¹⁷ rows:
2¹⁴ is fastest, 2¹¹ 40 % and 2¹⁷ 10 % slower; 10⁷ rows in one piece spend half their time
in page faults)."""


def _spans(k: int, size: int) -> list[tuple[int, int]]:
    return [(a, min(a + size, k)) for a in range(0, k, size)]


def _in_chunks(k: int, work, n_jobs: int) -> np.ndarray:
    """Run ``work(start, stop)`` over the chunks of k rows, the first alone (it may allocate
    what the others fill), the rest on ``n_jobs`` threads (numpy releases the GIL inside its
    array operations); return the rows the chunks report, in order."""
    spans = _spans(k, CHUNK_ROWS)
    if not spans:
        return np.arange(0)
    found = [work(*spans[0])]
    if n_jobs == 1 or len(spans) < 3:
        found += [work(*span) for span in spans[1:]]
    else:
        with ThreadPoolExecutor(max_workers=n_jobs) as pool:
            found += pool.map(lambda span: work(*span), spans[1:])
    return np.concatenate(found)


def _chunk_rows(problem: ImpactProblem, law: ImpactLaw, U: np.ndarray, out: Buffers, fast,
                tol: float):
    """``work(a, b)`` for :func:`_in_chunks`: solve rows a..b into the buffers' U⁺ and Λ,
    write their residuals into the buffers' residuals (by name; the chain's pass writes the
    columns of their table, or of a scratch block copied into them) and return the indices
    of the rows that are not certified."""
    st, k = problem.structure, U.shape[0]
    Up, Lam, res, columns = out
    named = bool(res)  # the residuals' names were known before the first chunk
    module = None
    if fast == "chain":
        rows = ChainRows(st, law.eps)
    elif fast == "compiled":
        moreau = law.family == MOREAU_FAMILY
        compiled = (st.kernel_pack, small.restitution_for(law, st.m),
                    law.eps if moreau else 0.0, moreau)
    elif fast is not None:
        module = backends.load(backends.REGISTRY[fast[0]])

    def work(a: int, b: int) -> np.ndarray:
        Ua, done = U[a:b], None
        if fast == "chain":
            rows.solve(Ua, Up[a:b], Lam[a:b])
            block = np.empty((len(res), b - a)) if columns is None else columns[:, a:b]
            rows.residuals(Ua, Up[a:b], Lam[a:b], block)
            for key, value in zip(res, block) if columns is None else ():  # out's own arrays
                res[key][a:b] = value
        elif fast == "compiled":  # each chunk warm-starts from its own cold support
            packed, E, eps, moreau = compiled
            Up[a:b], Lam[a:b], table, done = solve_impact_rows(
                packed, read_only(np.ascontiguousarray(Ua)), E, eps, moreau, tol,
                np.zeros(st.m, dtype=bool))
            for i, key in enumerate(res):
                res[key][a:b] = table[:, i]
        else:
            if module is None:
                Up[a:b], Lam[a:b] = law.closed_form_rows(problem, Ua)
            else:
                _, form, qp = fast
                X, Y, done = module.solve_many(qp, law.linear_terms(problem, Ua, form))
                Up[a:b], Lam[a:b] = law.recover_rows(problem, form, Ua, X, Y)
            values = law.residuals(st, Ua, Up[a:b], Lam[a:b])
            if named and tuple(values) != tuple(res):  # out= of another law
                raise InputError(f"out holds the residuals {tuple(res)}, this batch writes "
                                 f"{tuple(values)}")
            for key, value in values.items():
                if key not in res:  # the first chunk runs alone
                    res[key] = np.empty(k)
                res[key][a:b] = value
        ok = certified_rows({key: v[a:b] for key, v in res.items()}, tol)
        return a + np.flatnonzero(~ok if done is None else ~(ok & done))

    return work


def solve_batch(problem: ImpactProblem, law: ImpactLaw, U_minus: Any, backend: str = "auto",
                *, tol: float = DEFAULT_TOL, n_jobs: int = 1,
                out: BatchResult | None = None) -> BatchResult:
    """``law`` for every row of ``U_minus`` on the structure of ``problem``.

    Rows are processed in chunks of :data:`!CHUNK_ROWS`, so memory beyond the input and the
    output stays bounded. Moreau's law on a short chain (``"auto"`` or ``"isotonic"``) runs
    in compiled passes over blocks of rows (:mod:`!impactqp.laws.chain_rows`).

    Parameters
    ----------
    problem : ImpactProblem
        Supplies M and W (its own u⁻ is not used).
    law : ImpactLaw
        Any law object (``iq.Moreau(eps)``, ``iq.SectorLaw()``, ...).
    U_minus : (k, n) array_like
        Pre-impact velocities, one per row.
    backend : str
        ``"auto"``, a fast path (``"isotonic"``, ``"kernel"``) or any backend (rows one by one).
    tol : float
        Certificate tolerance per row.
    n_jobs : int
        Threads working on chunks at once (results do not depend on it).
    out : BatchResult, optional
        The result of an earlier batch of the same law on the same structure with as many
        rows: its arrays (``u_plus``, ``impulses``, ``residuals``) are overwritten and
        returned in the new result, so a stream of batches writes into memory it has
        already touched (at 10⁷ rows a fresh result is ~0.9 GB of new pages). The old result
        then holds the new numbers; after an error its arrays hold no meaningful values.
        Its arrays must be float64, C-contiguous, writable, of the batch's shapes, hold the
        residuals this batch writes, and share no memory with ``U_minus`` or each other.

    Returns
    -------
    BatchResult
        Certified row by row (with ``out``, holding ``out``'s arrays).

    Raises
    ------
    ShapeError, InputError, UnknownBackendError, BackendUnsuitableError
        Bad input (named); an unusable ``out`` (ShapeError for a shape, InputError for the
        rest, each naming the array and what is wrong).
    CertificateError
        A closed-form law's row fails its certificate, or no backend certifies a row.
    """
    tol = validate(problem, law, backend, "auto", tol)
    U = as_rows(problem, U_minus)
    n_jobs = as_count("n_jobs", n_jobs, minimum=1)
    st = problem.structure
    k = U.shape[0]
    way = plan(problem, law, backend, mode="batch").path
    if way == "chain":
        fast, used = "chain", "isotonic"
    elif way == "compiled" and small.dense(problem, law, backend, "auto"):  # row by row
        fast, used = "compiled", "kernel"
    elif way in ("compiled", "programs"):  # (the chain's call serves single impacts only)
        fast = _fast_path(problem, law, backend)
        used = backend if fast is None else fast[0]
    else:
        fast, used = None, law.closed_form_backend
    names = (RESIDUALS if fast == "chain" or (fast == "compiled" and law.family == MOREAU_FAMILY)
             else RESIDUALS[:4] if fast == "compiled" else None)
    if out is None:
        buffers = batch_out.fresh(U, st.m, names)
    elif not isinstance(out, BatchResult):
        raise InputError(f"out must be the BatchResult of an earlier batch, got "
                         f"{type(out).__name__}")
    else:
        buffers = batch_out.reused(out, U, st.m, names)
    Up, Lam, res, _ = buffers
    if not law.forms or fast is not None:
        rows = _in_chunks(k, _chunk_rows(problem, law, U, buffers, fast, tol), n_jobs)
    else:  # every row goes through the single-impact pipeline
        rows = np.arange(k)
    if not law.forms and rows.size:
        i = int(rows[0])
        raise CertificateError(f"{law.title}: row {i} fails its certificate: "
                               + ", ".join(f"{key}={v[i]:.1e}" for key, v in res.items()))
    for i in rows:
        r = solve(problem.with_u_minus(U[i]), law, "auto" if fast is not None else backend,
                  tol=tol)
        Up[i], Lam[i] = r.u_plus, r.impulses
        used = used if fast is not None else r.backend
    if not res:  # no chunk ran, or every row went through the pipeline
        res = law.residuals(st, U, Up, Lam)
    elif rows.size:
        fixed = law.residuals(st, U[rows], Up[rows], Lam[rows])
        if tuple(fixed) != tuple(res):  # out= of another law
            raise InputError(f"out holds the residuals {tuple(res)}, this batch writes "
                             f"{tuple(fixed)}")
        for key in res:
            res[key][rows] = fixed[key]
    return BatchResult(u_plus=Up, impulses=Lam, residuals=res, backend=used,
                       resolved=int(rows.size if fast is not None else 0), tol=tol)


def moreau_batch(problem: ImpactProblem, U_minus: Any, eps: float = 0.0,
                 backend: str = "auto", *, tol: float = DEFAULT_TOL,
                 n_jobs: int = 1, out: BatchResult | None = None) -> BatchResult:
    """Moreau's law (docs/theory.md §3) for every row of ``U_minus``:
    ``solve_batch(problem, Moreau(eps), U_minus, backend, tol=tol, n_jobs=n_jobs, out=out)``.

    Parameters
    ----------
    problem : ImpactProblem
        Supplies M and W (its own u⁻ is not used).
    U_minus : (k, n) array_like
        Pre-impact velocities, one per row.
    eps : float
        Restitution ε ∈ [0, 1].
    backend : str
        ``"auto"``, a fast path (``"isotonic"``, ``"kernel"``) or a QP backend (rows one by one).
    tol : float
        Certificate tolerance per row.
    n_jobs : int
        Threads working on chunks of rows at once.
    out : BatchResult, optional
        An earlier result whose arrays are overwritten and reused (:func:`solve_batch`).

    Returns
    -------
    BatchResult

    Raises
    ------
    RestitutionError, ShapeError, UnknownBackendError, BackendUnsuitableError, CertificateError
    """
    check_problem(problem)
    return solve_batch(problem, Moreau(eps), U_minus, backend, tol=tol, n_jobs=n_jobs,
                       out=out)


def sector_law_batch(problem: ImpactProblem, U_minus: Any, *, tol: float = DEFAULT_TOL,
                     n_jobs: int = 1, out: BatchResult | None = None) -> BatchResult:
    """The sector law u⁺ = sort(u⁻) (docs/theory.md §6) for every row of ``U_minus`` on an
    equal-mass chain: ``solve_batch(problem, SectorLaw(), U_minus, tol=tol, out=out)``.

    Parameters
    ----------
    problem : ImpactProblem
        A free chain of equal masses (its own u⁻ is not used).
    U_minus : (k, n) array_like
        One pre-impact velocity per row.
    tol : float
        Tolerance of the recomputed certificates.
    n_jobs : int
        Threads working on chunks of rows at once.
    out : BatchResult, optional
        An earlier result whose arrays are overwritten and reused (:func:`solve_batch`).

    Returns
    -------
    BatchResult
        The k post-impact velocities, impulses and per-row certificates.

    Raises
    ------
    SectorLawError
        When the problem is not a free chain of equal masses.
    CertificateError
        When a row fails its recomputed certificate (rounding with wildly mixed magnitudes).
    """
    return solve_batch(problem, SectorLaw(), U_minus, tol=tol, n_jobs=n_jobs, out=out)
