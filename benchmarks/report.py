"""Aggregate records into one row per family × size × method; write CSV, JSON, Markdown, PNG."""

from __future__ import annotations

import csv
import json
from collections import defaultdict
from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from . import friction_report  # noqa: E402
from .families import RUN_FAMILIES, SIZE_LABEL  # noqa: E402
from .measure import fmt_time, missed_by  # noqa: E402

COLUMNS = ["family", "size", "method", "group", "instances", "ran", "ok", "success_rate",
           "median_s", "p90_s", "max_error", "peak_mb", "output_mb", "status", "message",
           "reference", "note"]


def aggregate(records: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """One row per (family, size, method): pooled median/p90 time over instances and
    repeats, worst relative error, success rate among the runs that were not skipped."""
    groups: dict[tuple, list[dict]] = defaultdict(list)
    for rec in records:
        groups[(rec["family"], rec["size"], rec["method"])].append(rec)
    rows = []
    for (family, size, method), recs in groups.items():
        ran = [r for r in recs if r["status"] != "skipped"]
        times = [t for r in ran for t in r["times"]]
        errors = [r["error"] for r in ran if r["error"] is not None]
        peaks = [r["peak_mb"] for r in ran if r["peak_mb"] is not None]
        outputs = [r.get("output_mb") for r in ran if r.get("output_mb") is not None]
        statuses = sorted({r["status"] for r in recs})
        ok = sum(r["status"] == "ok" for r in ran)
        rows.append({
            "family": family, "size": size, "method": method, "group": recs[0]["group"],
            "instances": len(recs), "ran": len(ran), "ok": ok,
            "success_rate": ok / len(ran) if ran else None,
            "median_s": float(np.median(times)) if times else None,
            "p90_s": float(np.percentile(times, 90)) if times else None,
            "max_error": max(errors) if errors else None,
            "peak_mb": max(peaks) if peaks else None,
            "output_mb": max(outputs) if outputs else None,
            "status": statuses[0] if len(statuses) == 1 else "mixed",
            "message": next((r["message"] for r in recs if r["message"]), ""),
            "reference": recs[0]["reference"], "note": recs[0]["note"],
        })
    order = {f: i for i, f in enumerate(SIZE_LABEL)}
    rows.sort(key=lambda r: (order.get(r["family"], 99), r["size"]))
    return rows


NUMERIC = ("size", "instances", "ran", "ok", "success_rate", "median_s", "p90_s",
           "max_error", "peak_mb", "output_mb")


def read_rows(path: Path) -> list[dict[str, Any]]:
    """The rows of a results.csv written by :func:`write_all` (numbers as floats, empty cells
    as None), e.g. to redraw :func:`plot` from ``benchmarks/reference/results.csv``."""
    with open(path, newline="") as fh:
        rows = list(csv.DictReader(fh))
    for row in rows:
        for key in NUMERIC:
            row[key] = float(row[key]) if row.get(key) not in (None, "") else None
    return rows


def _median(rows: list[dict], family: str, size: int | None, method: str) -> dict | None:
    found = [r for r in rows if r["family"] == family and r["method"] == method
             and (size is None or r["size"] == size) and r["median_s"] is not None]
    return max(found, key=lambda r: r["size"]) if found else None


def targets(rows: list[dict]) -> list[tuple[str, str, str]]:
    """(target, measured, verdict) for the issue's four speed targets, where measured."""
    out: list[tuple[str, str, str]] = []
    iq5, raw5 = _median(rows, "cradle", 100_000, "iq:auto"), _median(rows, "cradle", 100_000,
                                                                    "raw:clarabel")
    if iq5 and raw5:
        ratio = raw5["median_s"] / iq5["median_s"]
        exact = iq5["max_error"] is not None and iq5["max_error"] <= 1e-12
        out.append(("chain N=10⁵: iq:auto ≥ 100× faster than raw Clarabel, error ≤ 1e-12",
                    f"{ratio:.0f}× ({fmt_time(iq5['median_s'])} vs {fmt_time(raw5['median_s'])}),"
                    f" error {iq5['max_error']:.1e}",
                    "met" if ratio >= 100 and exact else "MISSED"))
    iq6 = _median(rows, "cradle", 1_000_000, "iq:auto")
    if iq6:
        out.append(("chain N=10⁶ well under 1 s", fmt_time(iq6["median_s"]),
                    "met" if iq6["median_s"] < 0.5 else "MISSED" if iq6["median_s"] >= 1 else
                    "under 1 s, not well under"))
    iq3, lemke = _median(rows, "cradle", 3, "iq:auto"), _median(rows, "cradle", 3,
                                                                "siconos:lemke")
    if iq3 and lemke:
        ratio = iq3["median_s"] / lemke["median_s"]
        beside = []
        for m in (4, 10):
            a, b = _median(rows, "random", m, "iq:auto"), _median(rows, "random", m,
                                                                   "siconos:lemke")
            if a and b:
                beside.append(f"m = {m}: {a['median_s'] / b['median_s']:.1f}× "
                              f"({fmt_time(a['median_s'])} vs {fmt_time(b['median_s'])})")
        out.append(("3-ball cradle: iq.moreau ≤ 1.5× Siconos Lemke (incl. construction)",
                    f"{ratio:.1f}× ({fmt_time(iq3['median_s'])} vs "
                    f"{fmt_time(lemke['median_s'])})"
                    + (f"; random impacts {'; '.join(beside)}" if beside else ""),
                    _at_most(ratio, 1.5)))
    lemke10 = _median(rows, "random", 10, "siconos:lemke")
    for method, limit, what in (("iq:auto", 3, "repeat solve"),
                                ("iq:fresh", 20, "built fresh + solved")):
        r = _median(rows, "random", 10, method)
        if r and lemke10:
            ratio = r["median_s"] / lemke10["median_s"]
            out.append((f"random dense m = 10, {what}: ≤ {limit}× Siconos Lemke",
                        f"{ratio:.1f}× ({fmt_time(r['median_s'])} vs "
                        f"{fmt_time(lemke10['median_s'])})", _at_most(ratio, limit)))
    for family, method, limit, what in (
            ("cradle", "iq:auto", 3, "warm"), ("chain-random", "iq:auto", 3, "random u⁻, warm"),
            ("cradle", "iq:cold", 10, "cold build + solve")):
        r = _median(rows, family, 1_000_000, method)
        floor = _median(rows, family, 1_000_000, "raw:isotonic_regression")
        if r and floor:
            ratio = r["median_s"] / floor["median_s"]
            out.append((f"chain N=10⁶, {what}: ≤ {limit}× isotonic_regression",
                        f"{ratio:.1f}× ({fmt_time(r['median_s'])} vs "
                        f"{fmt_time(floor['median_s'])})", _at_most(ratio, limit)))
    for method in ("iq:moreau_batch", "iq:moreau_batch:out", "iq:sector_law_batch"):
        b = _median(rows, "batch", None, method)
        if b:
            rate = b["size"] / b["median_s"]
            goal = 1e7 if "moreau" in method and b["size"] >= 10**7 else 1e6
            out.append((f"batch {method}: ≥ {goal:.0e} three-ball impacts/s, certified, one "
                        f"thread (k = {b['size']:g})", f"{rate:.3g} impacts/s",
                        "met" if rate >= goal else missed_by(goal / rate)))
            if b.get("peak_mb") is not None and b.get("output_mb") is not None \
                    and b["size"] >= 10**6 and not method.endswith(":out"):
                # (below 10⁶ rows fixed costs dominate; with out= the output is not new)
                extra = (b["peak_mb"] - b["output_mb"]) * 2**20 / b["size"]
                out.append((f"batch {method}: memory beyond input and output ≤ 100 B/impact",
                            f"{extra:.0f} B/impact (tracemalloc peak {b['peak_mb']:.0f} MB, "
                            f"output {b['output_mb']:.0f} MB)",
                            "met" if extra <= 100 else "MISSED"))
    sweeps = {int(r["method"].rsplit("=", 1)[1]): r for r in rows
              if r["family"] == "sweep" and r["median_s"] is not None}
    jobs = max(sweeps, default=1)
    if 1 in sweeps and jobs > 1:
        one, many = sweeps[1], sweeps[jobs]
        speedup = one["median_s"] / many["median_s"]
        same = one["status"] == many["status"] == "ok"
        goal = "≥ 1.7× faster than 1" if jobs == 2 else "against 1 (the target is for 2)"
        out.append((f"sweep on {jobs} local processes {goal}, identical results",
                    f"{speedup:.2f}× ({fmt_time(one['median_s'])} vs "
                    f"{fmt_time(many['median_s'])}), {'identical' if same else 'DIFFERENT'}",
                    ("met" if speedup >= 1.7 and same else "MISSED") if jobs == 2
                    else "identical" if same else "MISSED"))
    for r in rows:
        if r["family"] == "discs" and r["size"] >= 1000 and r["method"] == "iq:clarabel":
            raw = _median(rows, "discs", r["size"], "raw:clarabel")
            if raw and r["median_s"]:
                ratio = r["median_s"] / raw["median_s"]
                out.append((f"discs m={r['size']}: iq clarabel within 1.3× of raw Clarabel",
                            f"{ratio:.2f}× ({fmt_time(r['median_s'])} vs "
                            f"{fmt_time(raw['median_s'])})",
                            "met" if ratio <= 1.3 else missed_by(ratio / 1.3)))
    out += _run_targets(rows)
    out += friction_report.targets(rows)
    return out


def _at_most(ratio: float, limit: float) -> str:
    return "met" if ratio <= limit else missed_by(ratio / limit)


#: simulations against Siconos: (family, size, what, largest ratio impactqp / Siconos,
#: largest trajectory difference for the verdict or None)
SIM_TARGETS = (("sim-ball", 2000, "Siconos' BouncingBallTS, 2000 steps, same trajectory "
                "(≤ 1e-12)", 1.0, 1e-12),
               ("sim-cradle", 5, "5-ball cradle on pendulums, Moreau–Jean, 1000 steps", 1.0,
                None),
               ("sim-column", 100, "100-bead column, 1000 steps", 0.3, None))
#: per impact: (family, size, what, most seconds per impact)
IMPACT_TARGETS = (("event-ball", 10, "event-driven bouncing ball, T = 10 s", 0.5e-3),
                  ("lzb", 10, "LZB 10-ball steel chain", 2e-3),
                  ("lzb", 100, "LZB 100-ball steel chain", 30e-3))


def _run_targets(rows: list[dict]) -> list[tuple[str, str, str]]:
    """Targets of the runs of benchmarks/dynamics.py: simulations beside Siconos, per-impact
    times, the first calls of a fresh process."""
    out: list[tuple[str, str, str]] = []
    for family, size, what, limit, agree in SIM_TARGETS:
        mine = _median(rows, family, size, "iq:simulate")
        peer = _median(rows, family, size, "siconos:MoreauJeanOSI")
        if not (mine and peer):
            continue
        ratio = mine["median_s"] / peer["median_s"]
        diff = mine["max_error"]
        verdict = _at_most(ratio, limit)
        if agree is not None and (diff is None or diff > agree):
            verdict = ("MISSED" if verdict == "met" else verdict) + " (trajectories differ)"
        shown = "—" if diff is None else f"{diff:.1e}"
        out.append((f"{what}: ≤ {limit:g}× Siconos MoreauJeanOSI",
                    f"{ratio:.2f}× ({fmt_time(mine['median_s'])} vs "
                    f"{fmt_time(peer['median_s'])} per run), max |Δq|, |Δv| = {shown}",
                    verdict))
    for family, size, what, limit in IMPACT_TARGETS:
        r = _median(rows, family, size, "iq:event-driven" if family == "event-ball"
                    else "iq:lzb")
        if r:
            out.append((f"{what}: ≤ {fmt_time(limit)} per impact",
                        f"{fmt_time(r['median_s'])} per impact ({r['reference']})",
                        _at_most(r["median_s"] / limit, 1.0)))
    first = _median(rows, "startup", None, "iq:first calls")
    if first:
        out.append(("first calls in a fresh process, numba cache filled: ≤ 1 s extra",
                    f"{fmt_time(first['median_s'])} extra ({first['reference']})",
                    _at_most(first["median_s"], 1.0)))
    return out


WHY_FRICTION = {
    "LMGC-00046": "a call of a few µs of compiled solve beside posing the problem in its "
                  "contacts' units, certifying the answer by formulas of its own (cone, dual "
                  "cone, complementarity) and the certified loop's bookkeeping in Python, "
                  "against one C call of NSGS; where NSGS takes near 100 µs the ratio moves "
                  "by ±30 % from run to run",
    "NESpheres-10": "the same as LMGC-00046: the certified route around a short compiled "
                    "solve, against one C call",
    "KaplasTower": "its first sweeps predict they finish within a few thousand more, and "
                   "the sweeps themselves (over a thousand) are each a little dearer than "
                   "NSGS's, a Newton step (sparse LU of size 1710) saving fewer of them than "
                   "it costs",
    "TwoRods1-condensed": "its three contacts go to Newton's dense steps, each about as "
                          "dear as NSGS's whole C call of two sweeps",
    "Rover4396": "a sliding 3-D contact is solved by Newton, whose dense steps cost as much "
                 "as NSGS's sweeps on two contacts",
    "FC2D-00394": "NSGS ends in one sweep of about a µs, which the Python call around "
                  "impactqp's compiled one costs alone",
    "FC2D-00031": "NSGS ends in one or two sweeps of a µs or two, about the cost of the "
                  "Python call around impactqp's compiled one",
    "FC2D-00374": "NSGS ends in a few sweeps of a few µs, about the cost of the Python call "
                  "around impactqp's compiled one",
    "FC2D-00071": "the sweeps, about as many as NSGS's, each cost more than NSGS's",
    "FC2D-00727": "the sweeps, about as many as NSGS's, each cost more than NSGS's",
    "Granular2D-667": "‖q‖ is round-off (4e-18): NSGS's one sweep answers r ≈ 0, right in "
                      "absolute terms but 0.1 in ABH error relative to ‖q‖, while impactqp "
                      "certifies 1e-8 relative",
}
"""Why the default can be slower than NSGS on a problem, by name: the mechanism, no figure (a
summary gives the figures of its own run, :func:`why_missed`)."""


def why_missed(key: str, rows: list[dict]) -> str:
    """The explanation of the missed target ``key``, from the figures of ``rows`` and speaking
    only of problems in them."""
    if key != "friction":
        return WHY_MISSED[key]
    slow = friction_report.slow(rows)
    parts = []
    if slow:
        parts.append(f"impactqp's default is slower than Siconos' NSGS (beyond its allowance) "
                     f"on {len(slow)} problem{'s' if len(slow) > 1 else ''}: "
                     + "; ".join(f"{name} ({contacts} contacts, {ratio:.2f}×)"
                                 + (f": {WHY_FRICTION[name]}" if name in WHY_FRICTION else "")
                                 for name, contacts, ratio in slow) + ".")
    winners = friction_report.fastest_others(rows)
    if winners:
        parts.append("Beside it, the fastest solver is " + ", ".join(
            f"{method} on {count}" for method, count in winners) + " of the problems.")
    return " ".join(parts)


WHY_3_BALL = (
        "one impact through iq.solve is one compiled call with ~1 µs of Python around it "
        "(the route planned in short, a thin result read off the call's buffer): for a "
        "cradle the chain's isotonic regression and certificate, for other dense impacts "
        "the active-set search and dense certificate, whose helpers are separate kernel "
        "calls (~2 µs of the ~7 µs on 4 contacts); Siconos' Lemke is one call into C "
        "returning bare arrays (~2.4 µs). Many impacts belong in the batch API.")
#: per target (its text before the first colon): why it is missed, shown when it is
WHY_MISSED = {
    "Siconos' BouncingBallTS, 2000 steps, same trajectory (≤ 1e-12)": (
        "the compiled Moreau–Jean loop takes ~1 ms; a slower run means a loaded machine, or "
        "a trajectory that differs (then the verdict says so)."),
    "5-ball cradle on pendulums, Moreau–Jean, 1000 steps": (
        "the compiled Moreau–Jean loop takes ~0.7 ms; a slower run means a loaded machine."),
    "100-bead column, 1000 steps": (
        "the compiled loop solves each run of touching beads by the isotonic projection; a "
        "slower run means a loaded machine."),
    "random dense m = 10, repeat solve": WHY_3_BALL,
    "random dense m = 10, built fresh + solved": (
        "ImpactProblem(M, W, u⁻) validates its arrays and packs its structure before the "
        "solve; Siconos' LCP gets the Delassus matrix ready-made."),
    "event-driven bouncing ball, T = 10 s": (
        "the flights are exact and each impact takes the compiled path (~0.1 ms per impact "
        "measured); a slower run means a loaded machine."),
    "LZB 10-ball steel chain": (
        "the compiled LZB integration takes 1.4–2.6 ms on the shared two-core machine (221 "
        "DOP853 steps; the row gives the CPU time); a slower run means a loaded machine."),
    "LZB 100-ball steel chain": (
        "the wave through 100 balls takes ~1,840 DOP853 steps over ~290 pieces, each step "
        "costing in proportion to the ~11 contacts it covers: 12–22 ms measured on the "
        "shared two-core machine (the row gives the CPU time), more when other processes "
        "hold both cores."),
    "first calls in a fresh process, numba cache filled": (
        "the first calls load numba's cached kernels and fill impactqp's caches (see the "
        "per-case first-call times in the measured column)."),
    "chain N=10⁶, random u⁻, warm": (
        "as for the warm cradle below: the projection with its impulses and the "
        "certificate's pass each read the 8 MB arrays, on top of isotonic_regression's one "
        "pass."),
    "3-ball cradle": WHY_3_BALL,
    "chain N=10⁶, warm": (
        "isotonic_regression is one pass in C (~3.4 ms) that returns neither impulses nor a "
        "certificate; impactqp's one compiled call runs the projection with its impulses "
        "(PAVA, the blocks' values, compensated sums) and then its O(N) certificate pass "
        "(momentum, signs, complementarity, energy balance, duality gap), which reads u⁺, Λ, "
        "the masses, their inverses and the scales again, and it writes a fresh 16 MB "
        "output. Fusing the certificate into the projection's pass would check the answer "
        "with the numbers that produced it, which a certificate must not do."),
    "chain N=10⁶, cold build + solve": (
        "the problem validates and copies the masses and u⁻ (finite, positive) and its first "
        "solve computes the contact scales, on top of the warm solve."),
    "batch iq": (
        "a 3-ball row costs ~15–25 ns of solve (one compiled pass over blocks of 256 rows: "
        "the min–max formula and anchored sums), ~26–35 ns of certificate (the one "
        "compiled chain pass, reading u⁻, u⁺ and Λ as returned) and ~4–6 ns of verdict; a "
        "fresh result is 88 bytes a row, and at 10⁷ rows its 0.9 GB of new pages cost the "
        "system ~0.2 s of page faults and zeroing per call (at 10⁶ rows the allocator "
        "reuses the freed u⁺ and Λ) and far more on a loaded machine; "
        "iq:moreau_batch:out writes into the previous result (out=) and pays none of it."),
}
EXPLAINED = {*WHY_MISSED, "friction"}
"""The targets (text before the first colon) whose misses the summary explains."""


def _cell(r: dict) -> str:
    if r["status"] == "skipped":
        return "skip"
    if r["median_s"] is None:
        return "FAIL"
    err = "—" if r["max_error"] is None else f"{r['max_error']:.0e}"
    flag = "" if r["success_rate"] == 1 else f" ✗{r['ok']}/{r['ran']}"
    return f"{fmt_time(r['median_s'])} ({err}){flag}"


def summary_markdown(rows: list[dict], meta: dict) -> str:
    """Targets, then per family a table: methods × sizes, cells 'median (max error)'."""
    lines = [f"# impactqp benchmark — suite `{meta['suite']}`", "",
             f"Run time {meta['seconds']} s; per method and case one untimed warm-up, then "
             f"timed repeats for up to {meta['timing_budget_s']} s (≤ {meta['max_repeats']}). "
             "Times are medians of the solve only; error = max ‖u⁺ − u⁺_ref‖_M / ‖u⁻‖_M; "
             f"✗k/n = only k of n runs succeeded (error ≤ {meta['accurate_below']:g}, no "
             "exception). `skip` = size cap or not applicable (see results.csv). peak_mb in "
             "results.csv (cases with max(n, m) or k ≥ 10⁴): tracemalloc peak of the warm-up "
             "run, Python/numpy allocations only (native solver memory is not seen).", ""]
    if meta.get("friction_seconds"):
        lines += [f"The friction suite took {meta['friction_seconds']} s of it.", ""]
    if meta.get("refreshed"):
        fresh = meta["refreshed"]
        lines += [f"Rows of {', '.join(fresh['families'])} refreshed since by a "
                  f"`{fresh['suite']}` run of {fresh['seconds']} s.", ""]
    lines += ["## Targets", "", "| target | measured | verdict |", "|---|---|---|"]
    found = targets(rows)
    lines += [f"| {t} | {m} | {v} |" for t, m, v in found]
    missed = dict.fromkeys(t.split(":")[0] for t, _, v in found
                           if v.startswith("MISSED") and t.split(":")[0] in EXPLAINED)
    if missed:
        lines += ["", "Why the missed targets are missed:", ""]
        lines += [f"- *{key}*: {why_missed(key, rows)}" for key in missed]
    lines += friction_report.markdown(rows)
    for family, label in SIZE_LABEL.items():
        fam = [r for r in rows if r["family"] == family]
        if not fam:
            continue
        sizes = sorted({r["size"] for r in fam})
        refs = sorted({r["reference"] for r in fam})
        lines += ["", f"## {family}", "", f"Exact answer from: {'; '.join(refs)}.", "",
                  "| method | " + " | ".join(f"{label}={s:g}" for s in sizes) + " |",
                  "|---|" + "---|" * len(sizes)]
        for method in dict.fromkeys(r["method"] for r in fam):
            by_size = {r["size"]: r for r in fam if r["method"] == method}
            if all(r["status"] == "skipped" for r in by_size.values()):
                continue
            cells = [_cell(by_size[s]) if s in by_size else "" for s in sizes]
            lines.append(f"| {method} | " + " | ".join(cells) + " |")
    failures = [r for r in rows if r["status"] in ("failed", "mixed", "inaccurate")]
    if failures:
        lines += ["", "## Failures and inaccurate answers", ""]
        lines += [f"- {r['family']} {SIZE_LABEL.get(r['family'], 'contacts')}={r['size']:g} "
                  f"{r['method']}: "
                  f"{r['message']}" for r in failures]
    notes = sorted({(r["method"], r["note"]) for r in rows if r["note"]})
    lines += ["", "## What the timer covers beyond the solve", ""]
    lines += [f"- {m}: {n}" for m, n in notes]
    return "\n".join(lines) + "\n"


#: the columns of the figure: which method groups share a panel
PANELS = (("impactqp's own algorithms", ("impactqp", "batch")),
          ("impactqp through a QP solver", ("impactqp",)),
          ("raw solvers and the Siconos peer", ("raw", "peer")))
"""Columns of the plot: a title and the method groups it draws (:func:`_panel` splits the
impactqp group between the first two)."""
VIA_SOLVER = ("clarabel", "osqp", "cvxpy", "qpsolvers")
"""Names that mark an impactqp method as going through an external QP solver."""
SOLVER_COLORS = {"clarabel": "C0", "osqp": "C1", "cvxpy": "C2", "daqp": "C3", "piqp": "C4",
                 "highs": "C5", "isotonic": "C6", "lemke": "C7", "pgs": "C8", "enum": "C9"}
"""One colour per solver, the same in every column (iq:clarabel and raw:clarabel alike)."""
OWN_COLORS = ["black", "darkgoldenrod", "saddlebrown", "teal", "slateblue", "olivedrab",
              "firebrick", "dimgray"]
"""Colours of impactqp's own algorithms, in order of appearance (none is a solver's)."""
MARKERS = "os^vDPX*h<>p"
LINESTYLES = {"impactqp": "-", "batch": "-", "raw": "--", "peer": ":"}
REFERENCE = "iq:auto"  # also drawn in the raw-solver panels, for comparison


def _size_label(size: float) -> str:
    """Compact tick label: 3, 50, 1000, 10⁴, 10⁵, 2·10⁵."""
    if size < 10_000:
        return f"{size:g}"
    exponent = int(np.floor(np.log10(size)))
    mantissa = size / 10**exponent
    power = f"10$^{{{exponent}}}$"
    return power if abs(mantissa - 1) < 1e-9 else f"{mantissa:g}·{power}"


def _panel(method: str, group: str) -> int | None:
    """The column of :data:`PANELS` that draws a method, None for groups not plotted."""
    if group in ("raw", "peer"):
        return 2
    if group == "impactqp" and any(name in method for name in VIA_SOLVER):
        return 1
    return 0 if group in ("impactqp", "batch") else None


def _styles(rows: list[dict]) -> dict[str, dict[str, Any]]:
    """Colour, marker and line style per method: the colour names the solver (the same in
    every column), the line style the kind (solid impactqp, dashed raw, dotted peer), and
    no two methods share colour and marker."""
    group_of = {r["method"]: r["group"] for r in rows}
    styles: dict[str, dict[str, Any]] = {}
    taken: set[tuple[str, str]] = set()
    own = iter(OWN_COLORS * (len(group_of) // len(OWN_COLORS) + 1))
    for i, method in enumerate(group_of):
        color = next((c for name, c in SOLVER_COLORS.items() if name in method), None) \
            or next(own)
        k = i
        while (color, MARKERS[k % len(MARKERS)]) in taken and k < i + len(MARKERS):
            k += 1
        marker = MARKERS[k % len(MARKERS)]
        taken.add((color, marker))
        styles[method] = {"color": color, "marker": marker,
                          "ls": LINESTYLES.get(group_of[method], "-")}
    return styles


def plot(rows: list[dict], path: Path) -> None:
    """Write :func:`plot_figure` of ``rows`` to ``path`` (PNG)."""
    fig = plot_figure(rows)
    fig.savefig(path, dpi=90)
    plt.close(fig)


def plot_figure(rows: list[dict]) -> Any:
    """Log-log median time vs size: one row per family, one column per kind of method
    (:data:`PANELS`: impactqp's own algorithms, impactqp through a QP solver, raw solvers
    and the Siconos peer, with iq:auto repeated there for comparison). Each column has its
    own legend above it, naming only its methods; a solver has one colour in every column;
    ticks only at the measured sizes. Returns the pyplot Figure (the caller closes it).
    """
    from matplotlib.ticker import FixedLocator, NullFormatter, NullLocator

    fams = [f for f in SIZE_LABEL if f not in RUN_FAMILIES and any(r["family"] == f
                                                                   for r in rows)]
    if not fams:
        fig = plt.figure(figsize=(6, 1.5))
        fig.text(0.5, 0.5, "no measurements", ha="center", va="center")
        return fig
    styles = _styles(rows)
    fig, axes = plt.subplots(len(fams), len(PANELS), figsize=(15, 2.9 * len(fams) + 0.4),
                             squeeze=False, layout="constrained")
    handles: list[dict[str, Any]] = [{} for _ in PANELS]
    for row, family in enumerate(fams):
        fam = [r for r in rows if r["family"] == family and r["median_s"] is not None]
        sizes = sorted({r["size"] for r in fam})
        for col, (title, _) in enumerate(PANELS):
            ax = axes[row, col]
            methods = [m for m in dict.fromkeys(r["method"] for r in fam)
                       if _panel(m, next(r["group"] for r in fam if r["method"] == m)) == col]
            if not methods:
                ax.axis("off")
                continue
            if col == 2 and any(r["method"] == REFERENCE for r in fam):
                methods.append(REFERENCE)
            for method in methods:
                pts = sorted((r["size"], r["median_s"], r["success_rate"]) for r in fam
                             if r["method"] == method)
                x, y, _ = zip(*pts)
                style = dict(styles[method])
                reference = method == REFERENCE and col == 2
                if reference:
                    style.update(lw=2.5, alpha=0.35, ls="-")
                (line,) = ax.plot(x, y, markersize=4, **style)
                handles[col].setdefault(f"{method} (for comparison)" if reference else method,
                                        line)
                bad = [(a, b) for a, b, s in pts if s != 1]
                if bad:
                    ax.plot(*zip(*bad), "x", color=style["color"], markersize=9, mew=1.5)
            ax.set(xscale="log", yscale="log", ylabel="median time [s]",
                   title=f"{family}: {title}")
            ax.xaxis.set_major_locator(FixedLocator(sizes))
            ax.xaxis.set_minor_locator(NullLocator())
            ax.xaxis.set_major_formatter(NullFormatter())
            ax.set_xticks(sizes, [_size_label(s) for s in sizes],
                          rotation=30 if len(sizes) > 5 else 0)
            low, high = ax.get_ylim()
            if np.floor(np.log10(high)) > np.ceil(np.log10(low)):  # ≥ 2 labelled decades
                ax.yaxis.set_minor_formatter(NullFormatter())
            ax.grid(True, which="major", alpha=0.3)
            ax.set_xlabel(SIZE_LABEL[family])
    for col, ((title, _), col_handles) in enumerate(zip(PANELS, handles)):
        if col_handles:  # above the column's first panel, naming only the column's methods
            top = next(ax for ax in axes[:, col] if ax.axison)
            top.legend(list(col_handles.values()), list(col_handles), loc="lower center",
                       bbox_to_anchor=(0.5, 1.12), ncol=2, fontsize=8, title=title,
                       title_fontsize=9, frameon=False)
    fig.suptitle("Moreau impact: median solve time (× = some runs failed or inaccurate)\n"
                 "colour: the solver, the same in every column; line: solid impactqp, dashed "
                 "raw solver, dotted peer")
    return fig


def write_all(records: list[dict], out_dir: Path, meta: dict) -> list[dict]:
    """Write results.csv, results.json, summary.md and plot.png into ``out_dir`` (and
    friction_profile.png when there are friction rows)."""
    out_dir.mkdir(parents=True, exist_ok=True)
    rows = aggregate(records)
    with open(out_dir / "results.csv", "w", newline="") as fh:
        writer = csv.DictWriter(fh, fieldnames=COLUMNS)
        writer.writeheader()
        writer.writerows(rows)
    raw = [{k: v for k, v in r.items()} for r in records]
    (out_dir / "results.json").write_text(json.dumps({"meta": meta, "rows": rows,
                                                      "records": raw}, indent=1))
    (out_dir / "summary.md").write_text(summary_markdown(rows, meta))
    plot(rows, out_dir / "plot.png")
    if not friction_report.plot(rows, out_dir / friction_report.PROFILE_PNG):
        (out_dir / friction_report.PROFILE_PNG).unlink(missing_ok=True)  # not a stale one
    return rows
