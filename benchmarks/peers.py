"""The peer: Siconos' LCP solvers, run in Debian's Python through :mod:`siconos_worker`.

impactqp's Python (3.11, pyenv) cannot import siconos; Debian's ``/usr/bin/python3`` can.
The suite writes the impact LCPs (M = G, q = (1+ε)γ⁻) of the small cases to a JSON file,
runs the worker once in a subprocess and reads back times and solutions. When that Python
cannot import siconos, every Siconos row is recorded as skipped, not failed.
"""

from __future__ import annotations

import json
import subprocess
import tempfile
from pathlib import Path
from typing import Any

import numpy as np
import scipy.sparse as sp

from .families import Case
from .measure import ACCURATE, record, relative_error

SICONOS_PYTHON = "/usr/bin/python3"
WORKER = Path(__file__).with_name("siconos_worker.py")
#: largest m each Siconos solver gets (Lemke: O(m³) pivoting on dense G; PGS: thousands of
#: sweeps on chains; ENUM: 2^m active sets)
CAPS = {"lemke": 1000, "pgs": 200, "enum": 12}
NOTE = "sn.LCP construction from numpy + SolverOptions + driver, in /usr/bin/python3"


def siconos_status(python: str = SICONOS_PYTHON) -> str | None:
    """None when ``python`` imports siconos.numerics, else the reason it does not."""
    try:
        done = subprocess.run([python, str(WORKER), "--check"], capture_output=True,
                              text=True, timeout=60)
    except (OSError, subprocess.TimeoutExpired) as exc:
        return f"cannot run {python}: {exc}"
    return None if done.returncode == 0 else (done.stderr.strip() or f"exit {done.returncode}")


def wants(case: Case) -> bool:
    """Does the case go to Siconos at all (a single impact with m within some cap)?"""
    return case.kind != "batch" and case.n_contacts <= max(CAPS.values())


def _lcp(case: Case) -> tuple[np.ndarray, np.ndarray]:
    G = case.problem.delassus
    G = G.toarray() if sp.issparse(G) else np.asarray(G)
    return G, (1.0 + case.eps) * case.problem.gamma_minus


def _u_plus(case: Case, z: np.ndarray) -> np.ndarray:
    st = case.problem.structure
    return case.problem.u_minus + np.asarray(st.Minv_W @ z).ravel()


def _skipped(case: Case, name: str, why: str) -> dict:
    return record(case, f"siconos:{name}", "peer", status="skipped", message=why, note=NOTE)


def run_siconos(cases: list[Case], *, budget: float, max_repeats: int,
                python: str = SICONOS_PYTHON) -> list[dict[str, Any]]:
    """Time Lemke, PGS and ENUM on every case; one record per case and solver."""
    why = siconos_status(python)
    if why is not None:
        return [_skipped(c, s, f"siconos not importable by {python}: {why}")
                for c in cases for s in CAPS]
    problems, skipped = [], []
    for i, case in enumerate(cases):
        G, q = _lcp(case)
        solvers = [s for s, cap in CAPS.items() if case.n_contacts <= cap]
        skipped += [_skipped(case, s, f"needs m ≤ {cap}") for s, cap in CAPS.items()
                    if case.n_contacts > cap]
        problems.append({"id": i, "M": G.tolist(), "q": q.tolist(), "solvers": solvers})
    with tempfile.TemporaryDirectory() as tmp:
        src, dst = Path(tmp) / "in.json", Path(tmp) / "out.json"
        src.write_text(json.dumps({"budget": budget, "max_repeats": max_repeats,
                                   "problems": problems}))
        done = subprocess.run([python, str(WORKER), str(src), str(dst)], capture_output=True,
                              text=True)
        if done.returncode != 0:
            msg = f"siconos worker failed (exit {done.returncode}): {done.stderr.strip()[-300:]}"
            return [record(c, f"siconos:{s}", "peer", status="failed", message=msg, note=NOTE)
                    for c in cases for s in CAPS]
        answer = json.loads(dst.read_text())
    out = list(skipped)
    for prob in answer["problems"]:
        case = cases[prob["id"]]
        for name, res in prob["results"].items():
            out.append(_peer_record(case, name, res))
    return out


def _peer_record(case: Case, name: str, res: dict) -> dict:
    method = f"siconos:{name}"
    if "error" in res:
        return record(case, method, "peer", status="failed", message=res["error"], note=NOTE)
    err = relative_error(case, _u_plus(case, np.asarray(res["z"])))
    if res["info"] != 0:
        status, msg = "failed", f"Siconos info = {res['info']} (not solved to its tolerance)"
    else:
        status = "ok" if err <= ACCURATE else "inaccurate"
        msg = "" if status == "ok" else f"relative error {err:.1e}"
    return record(case, method, "peer", status=status, message=msg, times=res["times"],
                  error=err, note=NOTE)
