"""The friction suite in the reports: its table, its targets, its performance profile.

Works on the aggregated rows of :func:`benchmarks.report.aggregate` (or of a results.csv
read back by :func:`benchmarks.report.read_rows`): one row per ``friction:<problem>`` family
and method. A method solved a problem when its row's status is ``ok`` (ABH error ≤ 1e-8,
recomputed by impactqp); its time is the row's median, the time spent where it failed.
"""

from __future__ import annotations

import math
from pathlib import Path

from . import perf_profile
from .friction import BASELINE, DEFAULT, METHODS, TOL
from .measure import fmt_time, missed_by

PREFIX = "friction:"
PROFILE_PNG = "friction_profile.png"
#: the issue's targets: the default's geometric mean of ratios to NSGS at most this
GEOMEAN_TARGET = 0.3
#: problems of fewer contacts may take NSGS's time plus this many seconds (more: ≤ NSGS)
SMALL_CONTACTS, SMALL_SLACK = 5, 10e-6
#: the default within this factor of the fastest solver on every problem (Dolan–Moré)
WITHIN = 2.0


def problems(rows: list[dict]) -> list[str]:
    """The friction problems of ``rows``, smallest first (by contacts)."""
    fam = {r["family"]: r["size"] for r in rows if r["family"].startswith(PREFIX)}
    return sorted(fam, key=lambda f: (fam[f], f))


def _by(rows: list[dict]) -> dict[tuple[str, str], dict]:
    return {(r["family"], r["method"]): r for r in rows if r["family"].startswith(PREFIX)}


def solved(r: dict | None) -> bool:
    """Did the row's method reach the tolerance on its problem?"""
    return r is not None and r["status"] == "ok" and r["median_s"] is not None


def profile_times(rows: list[dict]) -> dict[str, list[float]]:
    """Per method that ran on every friction problem (not skipped): its time per problem,
    ∞ where it failed — the input of :func:`benchmarks.perf_profile.profile`."""
    fams, by = problems(rows), _by(rows)
    out: dict[str, list[float]] = {}
    for method in METHODS:
        cells = [by.get((f, method)) for f in fams]
        if not fams or any(c is None or c["status"] == "skipped" for c in cells):
            continue
        out[method] = [c["median_s"] if solved(c) else math.inf for c in cells]
    return out


def default_ratios(rows: list[dict]) -> dict[str, tuple[float, bool, bool]]:
    """Per problem: (time of the default / time of NSGS, default solved, NSGS solved), the
    NSGS time being its time spent where it failed; problems lacking either time left out."""
    by = _by(rows)
    out = {}
    for fam in problems(rows):
        mine, base = by.get((fam, DEFAULT)), by.get((fam, BASELINE))
        if mine and base and mine["median_s"] and base["median_s"]:
            out[fam] = (mine["median_s"] / base["median_s"], solved(mine), solved(base))
    return out


def short(fam: str) -> str:
    """The problem's name without the family prefix."""
    return fam[len(PREFIX):]


def peers_unsolved(rows: list[dict]) -> list[str]:
    """Problems on which Siconos ran and none of its solvers reached the tolerance."""
    by = _by(rows)
    out = []
    for fam in problems(rows):
        peer = [r for (f, m), r in by.items() if f == fam and m.startswith("siconos:")]
        if peer and all(r["status"] != "skipped" for r in peer) and not any(map(solved, peer)):
            out.append(fam)
    return out


def _not_certified(rows: list[dict]) -> list[tuple[str, dict | None]]:
    by = _by(rows)
    return [(f, by.get((f, DEFAULT))) for f in problems(rows) if not solved(by.get((f, DEFAULT)))]


def carries_best(r: dict | None) -> bool:
    """Did the default's failed run end in a CertificateError carrying its best answer (its
    ABH error recomputed into the row)?"""
    return (r is not None and "CertificateError" in r["message"]
            and "best answer ABH" in r["message"] and r["max_error"] is not None)


def _slow(rows: list[dict]) -> list[tuple[str, float]]:
    """(problem, default / NSGS) where the default misses its time target: > NSGS on problems
    of ≥ :data:`SMALL_CONTACTS` contacts, > NSGS + :data:`SMALL_SLACK` below."""
    by, out = _by(rows), []
    for fam, (value, _, _) in default_ratios(rows).items():
        mine, base = by[(fam, DEFAULT)], by[(fam, BASELINE)]
        limit = base["median_s"] + (SMALL_SLACK if mine["size"] < SMALL_CONTACTS else 0.0)
        if mine["median_s"] > limit:
            out.append((fam, value))
    return out


def slow(rows: list[dict]) -> list[tuple[str, int, float]]:
    """(problem, contacts, default / NSGS) of the problems where the default misses its time
    target (:func:`_slow`), slowest first."""
    sizes = {r["family"]: r["size"] for r in rows if r["family"].startswith(PREFIX)}
    return sorted(((short(f), int(sizes[f]), v) for f, v in _slow(rows)),
                  key=lambda item: -item[2])


def fastest_others(rows: list[dict]) -> list[tuple[str, int]]:
    """(method, problems it is the fastest on) of the methods other than the default that are
    the fastest on some problem, most first."""
    times = profile_times(rows)
    if DEFAULT not in times:
        return []
    counts: dict[str, int] = {}
    for cells in zip(*times.values(), strict=True):
        best = min(cells)
        if math.isfinite(best) and cells[list(times).index(DEFAULT)] != best:
            winner = list(times)[cells.index(best)]
            counts[winner] = counts.get(winner, 0) + 1
    return sorted(counts.items(), key=lambda item: -item[1])


def _factors(rows: list[dict]) -> dict[str, float]:
    """Per problem: the default's time over the fastest solver's (∞ where it failed)."""
    times = profile_times(rows)
    if DEFAULT not in times:
        return {}
    r = perf_profile.ratios(times)[DEFAULT]
    return dict(zip(problems(rows), r.tolist(), strict=True))


def geomean(values: list[float]) -> float:
    """exp of the mean log (NaN for none)."""
    return math.exp(sum(math.log(v) for v in values) / len(values)) if values else math.nan


def _cell(r: dict | None) -> str:
    if r is None:
        return ""
    if r["status"] == "skipped":
        return "skip"
    if r["message"].startswith("Siconos 4.4 has no 2-D"):
        return "n/a (2-D)"
    if r["median_s"] is None:
        return "FAIL"
    err = "—" if r["max_error"] is None else f"{r['max_error']:.0e}"
    return f"{fmt_time(r['median_s'])} ({err})" + ("" if solved(r) else " ✗")


def markdown(rows: list[dict]) -> list[str]:
    """The friction section of summary.md (no lines without friction rows)."""
    fams = problems(rows)
    if not fams:
        return []
    by, ratio = _by(rows), default_ratios(rows)
    methods = [m for m in METHODS if any((f, m) in by for f in fams)]
    lines = ["", "## friction (FCLib)", "",
             f"Local problems (global ones reduced by W = HᵀM⁻¹H, q = HᵀM⁻¹f + w); every answer "
             f"judged by its ABH error ‖F‖/‖q‖ recomputed by impactqp's certify_friction at "
             f"tol {TOL:g} (Siconos' own error only in results.csv's message). Cells: median "
             f"time (ABH error); ✗ = not solved to {TOL:g}, its time spent. Ratio = "
             f"{DEFAULT} / {BASELINE} time. Profile: {PROFILE_PNG}.", "",
             "| problem | contacts | " + " | ".join(methods) + " | ratio |",
             "|---|---|" + "---|" * (len(methods) + 1)]
    for fam in fams:
        size = next(r["size"] for r in rows if r["family"] == fam)
        cells = [_cell(by.get((fam, m))) for m in methods]
        if fam in ratio:
            value, mine_ok, base_ok = ratio[fam]
            shown = f"{value:.2f}" + ("" if base_ok else " (NSGS failed)") \
                + ("" if mine_ok else " (default failed)")
        else:
            shown = "—"
        lines.append(f"| {fam[len(PREFIX):]} | {size:g} | " + " | ".join(cells)
                     + f" | {shown} |")
    if ratio:
        lines += ["", f"Geometric mean of the ratios over {len(ratio)} problems: "
                      f"{geomean([v for v, _, _ in ratio.values()]):.3f}."]
    times = profile_times(rows)
    if times:
        rho = perf_profile.profile(times, [1.0, math.inf])
        lines += ["", "Dolan–Moré: fastest on (ρ(1)) / solved (ρ(∞)) out of "
                      f"{len(fams)} problems: "
                  + "; ".join(f"{m} {round(v[0] * len(fams))}/{round(v[1] * len(fams))}"
                              for m, v in rho.items()) + "."]
    return lines + _lists(rows)


def _lists(rows: list[dict]) -> list[str]:
    """The problems behind the targets, by name: not certified (with the best answer's
    error), unsolved by every Siconos solver, not the fastest, not within 2×."""
    fams = problems(rows)
    by = _by(rows)
    out = []
    failed = _not_certified(rows)
    out += ["", f"Certified by {DEFAULT} at ABH ≤ {TOL:g}: {len(fams) - len(failed)} of "
                f"{len(fams)}."
            + (" Not certified: " + "; ".join(
                f"{short(f)} ({_best(r)})" for f, r in failed) + "." if failed else "")]
    none = peers_unsolved(rows)
    if none:
        mine = [short(f) for f in none if solved(by.get((f, DEFAULT)))]
        out += ["", f"No Siconos solver reaches {TOL:g} on {len(none)}: "
                    f"{', '.join(map(short, none))}; {DEFAULT} certifies {len(mine)} of them"
                    + (f" ({', '.join(mine)})" if mine else "") + "."]
    factors = _factors(rows)
    if factors:
        slower = [(f, v) for f, v in factors.items() if v > 1.0]
        far = [(f, v) for f, v in slower if v > WITHIN]
        out += ["", f"{DEFAULT} not the fastest on {len(slower)} of {len(fams)}"
                    + (": " + ", ".join(f"{short(f)} {_times(v)}" for f, v in slower)
                       if slower else "") + "; "
                    f"not within {WITHIN:g}× of the fastest on {len(far)}"
                    + (": " + ", ".join(short(f) for f, _ in far) if far else "") + "."]
    return out


def _best(r: dict | None) -> str:
    if r is None:
        return "no row"
    if carries_best(r):
        return f"CertificateError, best ABH {r['max_error']:.1e}, {fmt_time(r['median_s'])}"
    return (r["message"] or r["status"])[:80]


def _times(value: float) -> str:
    return "failed" if math.isinf(value) else f"{value:.1f}×"


def targets(rows: list[dict]) -> list[tuple[str, str, str]]:
    """(target, measured, verdict) of the issue's friction targets, where measured."""
    fams = problems(rows)
    if not fams:
        return []
    by, ratio = _by(rows), default_ratios(rows)
    out = []
    ok = [f for f in fams if solved(by.get((f, DEFAULT)))]
    missing = [f[len(PREFIX):] for f in fams if f not in ok]
    out.append((f"friction: every FCLib problem certified at ABH ≤ {TOL:g} by the default "
                "solve_friction", f"{len(ok)} of {len(fams)}"
                + (f" (not: {', '.join(missing)})" if missing else ""),
                "met" if not missing else "MISSED"))
    failed = _not_certified(rows)
    if failed:
        named = [f for f, r in failed if carries_best(r)]
        out.append(("friction: a problem not certified ends in CertificateError carrying the "
                    "best answer and its ABH error",
                    f"{len(named)} of {len(failed)} ("
                    + "; ".join(f"{short(f)}: {_best(r)}" for f, r in failed) + ")",
                    "met" if len(named) == len(failed) else "MISSED"))
    none = peers_unsolved(rows)
    if none:
        mine = [f for f in none if solved(by.get((f, DEFAULT)))]
        out.append((f"friction: problems no Siconos solver brings to {TOL:g}, {DEFAULT} "
                    "certifies most", f"{len(mine)} of {len(none)}",
                    "met" if 2 * len(mine) > len(none) else "MISSED"))
    if ratio:
        slower = [short(f) for f, _ in _slow(rows)]
        out.append((f"friction: {DEFAULT} time ≤ {BASELINE} on each problem of ≥ "
                    f"{SMALL_CONTACTS} contacts, ≤ {BASELINE} + {SMALL_SLACK * 1e6:g} µs below "
                    "(NSGS failed: its time spent)", f"{len(ratio) - len(slower)} of "
                    f"{len(ratio)}" + (f" (slower: {', '.join(slower)})" if slower else ""),
                    "met" if not slower else "MISSED"))
        g = geomean([v for v, _, _ in ratio.values()])
        out.append((f"friction: geometric mean of {DEFAULT} / {BASELINE} ≤ {GEOMEAN_TARGET:g}",
                    f"{g:.3f}", "met" if g <= GEOMEAN_TARGET
                    else missed_by(g / GEOMEAN_TARGET)))
    times = profile_times(rows)
    if DEFAULT in times and len(times) > 1:
        fastest = perf_profile.profile(times, [1.0])[DEFAULT][0]
        out.append((f"friction: Dolan–Moré, {DEFAULT} the fastest solver on most problems",
                    f"fastest on {round(fastest * len(fams))} of {len(fams)} "
                    f"(ρ(1) = {fastest:.2f})", "met" if fastest > 0.5 else "MISSED"))
        within = perf_profile.profile(times, [WITHIN])[DEFAULT][0]
        out.append((f"friction: {DEFAULT} within {WITHIN:g}× of the fastest solver on every "
                    "problem (Dolan–Moré)", f"on {round(within * len(fams))} of {len(fams)} "
                    f"(ρ({WITHIN:g}) = {within:.2f})", "met" if within == 1.0 else "MISSED"))
    return out


def plot(rows: list[dict], path: Path) -> bool:
    """Write the performance profile of the friction rows to ``path``; False (and no
    file) when there are none."""
    times = profile_times(rows)
    if not times:
        return False
    perf_profile.plot_profile(times, path, title="Friction suite (FCLib, ABH ≤ "
                                                 f"{TOL:g}): Dolan–Moré performance profile")
    return True
