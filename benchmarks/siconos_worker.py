"""Time Siconos' LCP and fc3d solvers; runs under Debian's /usr/bin/python3 only.

Usage: ``/usr/bin/python3 siconos_worker.py IN.json OUT.json``. IN holds
``{"budget": seconds, "max_repeats": int, "problems": [{"id", "M", "q", "solvers"}]}``
with the LCP ``0 ≤ z ⟂ Mz + q ≥ 0`` (M = G, q = (1+ε)γ⁻) and solver names among
``lemke``, ``pgs``, ``enum``. Each timed run builds the ``sn.LCP`` object from the numpy
arrays and the solver options, then calls the driver (as a user of Siconos from Python
would). OUT holds per problem and solver the run times, the median, z, and Siconos' info
code (0 = solved). With ``--check`` it only verifies that siconos imports.

Usage: ``/usr/bin/python3 siconos_worker.py --fc3d-serve`` serves frictional contact
problems, one JSON line per request on stdin: ``{"path", "solver", "tol", "max_iter",
"budget", "max_repeats"}`` with ``path`` a local problem in Siconos' text layout (read by
Siconos' own ``frictionContact_new_from_filename``, W stored sparse-block) and ``solver``
among ``NSGS``, ``NSN_AC``, ``PROX`` (:data:`FC3D`; a 2-D problem goes to ``fc2d_driver``,
whose solvers are :data:`FC2D`). Each timed run calls the driver from r = u = 0 with fresh
solver options (tolerance ``SICONOS_DPARAM_TOL``, most iterations
``SICONOS_IPARAM_MAX_ITER``); the problem is read before the timer. The answer, one line
prefixed :data:`ANSWER`, holds the run times, Siconos' info code, its iterations
and its own error (for the record only: the caller recomputes the error), r and u.

This file must stay importable without siconos and self-contained (no impactqp import).
"""

from __future__ import annotations

import json
import statistics
import sys
import time


def _solver_ids(sn) -> dict:
    return {"lemke": sn.SICONOS_LCP_LEMKE, "pgs": sn.SICONOS_LCP_PGS,
            "enum": sn.SICONOS_LCP_ENUM}


#: the fc3d solvers served: name → Siconos' solver id attribute
FC3D = {"NSGS": "SICONOS_FRICTION_3D_NSGS", "NSN_AC": "SICONOS_FRICTION_3D_NSN_AC",
        "PROX": "SICONOS_FRICTION_3D_PROX"}
#: the fc2d solvers served (2-D problems): name → Siconos' solver id attribute
FC2D = {"NSGS": "SICONOS_FRICTION_2D_NSGS"}
#: the prefix of the server's answer lines (anything else on its stdout is Siconos talking)
ANSWER = "@@ "


def run_one(sn, np, M, q, solver_id: int) -> tuple[int, list]:
    """Build the LCP and its options from arrays, solve; return (info, z)."""
    lcp = sn.LCP(M, q)
    z = np.zeros(q.size)
    w = np.zeros(q.size)
    options = sn.SolverOptions(solver_id)
    info = sn.linearComplementarity_driver(lcp, z, w, options)
    return int(info), z.tolist()


def time_solver(sn, np, M, q, solver_id: int, budget: float, max_repeats: int) -> dict:
    """Warm up once, then repeat until ``budget`` seconds or ``max_repeats`` runs."""
    info, z = run_one(sn, np, M, q, solver_id)
    times: list[float] = []
    start = time.perf_counter()
    while len(times) < max_repeats and (not times or time.perf_counter() - start < budget):
        t0 = time.perf_counter()
        run_one(sn, np, M, q, solver_id)
        times.append(time.perf_counter() - t0)
    return {"info": info, "z": z, "times": times, "median": statistics.median(times)}


def fc3d_once(sn, np, problem, solver: str, tol: float, max_iter: int) -> dict:
    """One fc3d_driver (fc2d_driver in 2-D) call from r = u = 0; its seconds, info,
    iterations, own error, r, u."""
    size = problem.dimension * problem.numberOfContacts
    r, u = np.zeros(size), np.zeros(size)
    planar = problem.dimension == 2
    if planar and solver not in FC2D:
        raise ValueError(f"no 2-D {solver} in Siconos (2-D: {sorted(FC2D)})")
    options = sn.SolverOptions(getattr(sn, (FC2D if planar else FC3D)[solver]))
    options.dparam[sn.SICONOS_DPARAM_TOL] = tol
    options.iparam[sn.SICONOS_IPARAM_MAX_ITER] = max_iter
    driver = sn.fc2d_driver if planar else sn.fc3d_driver
    t0 = time.perf_counter()
    info = driver(problem, r, u, options)
    seconds = time.perf_counter() - t0
    return {"seconds": seconds, "info": int(info),
            "iterations": int(options.iparam[sn.SICONOS_IPARAM_ITER_DONE]),
            "siconos_error": float(options.dparam[sn.SICONOS_DPARAM_RESIDU]),
            "r": r.tolist(), "u": u.tolist()}


def fc3d_time(sn, np, job: dict) -> dict:
    """Time one solver on one problem: the first run counts when it alone takes the budget
    (a solve of seconds needs no warm-up), else it is the warm-up and timed repeats follow
    until ``budget`` seconds or ``max_repeats`` runs."""
    problem = sn.frictionContact_new_from_filename(job["path"])
    if problem is None:
        raise RuntimeError(f"siconos cannot read {job['path']}")
    args = (sn, np, problem, job["solver"], job["tol"], job["max_iter"])
    first = fc3d_once(*args)
    times = [first["seconds"]]
    if first["seconds"] < job["budget"]:
        times = []
        start = time.perf_counter()
        while len(times) < job["max_repeats"] and (
                not times or time.perf_counter() - start < job["budget"]):
            times.append(fc3d_once(*args)["seconds"])
    first.pop("seconds")
    return {"times": times, **first}


def fc3d_serve(sn, np) -> int:
    """Answer fc3d requests (see the module doc), one per input line, until EOF."""
    for line in sys.stdin:
        try:
            answer = fc3d_time(sn, np, json.loads(line))
        except Exception as exc:  # reported to the caller, the server goes on
            answer = {"error": f"{type(exc).__name__}: {exc}"}
        sys.stdout.write(ANSWER + json.dumps(answer) + "\n")
        sys.stdout.flush()
    return 0


def main(argv: list[str]) -> int:
    """Entry point; returns the exit status (3 when siconos cannot be imported)."""
    try:
        import numpy as np
        import siconos.numerics as sn
    except ImportError as exc:
        print(f"siconos unavailable: {exc}", file=sys.stderr)
        return 3
    if argv[1:] == ["--check"]:
        return 0
    if argv[1:] == ["--fc3d-serve"]:
        return fc3d_serve(sn, np)
    with open(argv[1]) as fh:
        job = json.load(fh)
    ids = _solver_ids(sn)
    out = []
    for prob in job["problems"]:
        M = np.ascontiguousarray(prob["M"], dtype=float)
        q = np.asarray(prob["q"], dtype=float)
        results = {}
        for name in prob["solvers"]:
            try:
                results[name] = time_solver(sn, np, M, q, ids[name], job["budget"],
                                            job["max_repeats"])
            except Exception as exc:  # a failing solver is a result, not an abort
                results[name] = {"error": f"{type(exc).__name__}: {exc}"}
        out.append({"id": prob["id"], "results": results})
    with open(argv[2], "w") as fh:
        json.dump({"problems": out}, fh)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
