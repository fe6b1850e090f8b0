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

from .families import SIZE_LABEL  # noqa: E402

COLUMNS = ["family", "size", "method", "group", "instances", "ran", "ok", "success_rate",
           "median_s", "p90_s", "max_error", "peak_mb", "status", "message", "reference", "note"]


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
            "status": statuses[0] if len(statuses) == 1 else "mixed",
            "message": next((r["message"] for r in recs if r["message"]), ""),
            "reference": recs[0]["reference"], "note": recs[0]["note"],
        })
    order = {f: i for i, f in enumerate(SIZE_LABEL)}
    rows.sort(key=lambda r: (order.get(r["family"], 99), r["size"]))
    return rows


def fmt_time(seconds: float | None) -> str:
    if seconds is None:
        return "—"
    for unit, scale in (("s", 1.0), ("ms", 1e-3), ("µs", 1e-6)):
        if seconds >= scale:
            return f"{seconds / scale:.3g} {unit}"
    return f"{seconds * 1e9:.3g} ns"


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
        out.append(("3-ball cradle: iq.moreau within 2× of Siconos Lemke (incl. construction)",
                    f"{ratio:.1f}× ({fmt_time(iq3['median_s'])} vs "
                    f"{fmt_time(lemke['median_s'])})",
                    "met" if ratio <= 2 else f"MISSED by {ratio / 2:.0f}×"))
    for method in ("iq:moreau_batch", "iq:sector_law_batch"):
        b = _median(rows, "batch", None, method)
        if b:
            rate = b["size"] / b["median_s"]
            out.append((f"batch {method}: ≥ 10⁶ three-ball impacts/s (k = {b['size']:g})",
                        f"{rate:.3g} impacts/s",
                        "met" if rate >= 1e6 else f"MISSED by {1e6 / rate:.1f}×"))
    for r in rows:
        if r["family"] == "discs" and r["size"] >= 1000 and r["method"] == "iq:clarabel":
            raw = _median(rows, "discs", r["size"], "raw:clarabel")
            if raw and r["median_s"]:
                ratio = r["median_s"] / raw["median_s"]
                out.append((f"discs m={r['size']}: iq clarabel within 1.3× of raw Clarabel",
                            f"{ratio:.2f}× ({fmt_time(r['median_s'])} vs "
                            f"{fmt_time(raw['median_s'])})",
                            "met" if ratio <= 1.3 else f"MISSED by {ratio / 1.3:.1f}×"))
    return out


WHY_MISSED = {
    "3-ball cradle": (
        "the 3-ball call is dominated by Python, not by the algorithm: impactqp recomputes its "
        "certificate (momentum, signs, complementarity, energy balance, duality gap: about 45 "
        "small numpy operations, ~40 µs on a quiet machine), runs the prepared active-set "
        "kernel (~15 µs) and builds a result object, where Siconos runs Lemke in C and "
        "returns bare arrays. Without giving up the per-result certificate, the fast route "
        "for many small impacts is the batch API (see the batch family: ~0.5 µs per impact)."),
}


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
             "run, Python/numpy allocations only (native solver memory is not seen).", "",
             "## Targets", "", "| target | measured | verdict |", "|---|---|---|"]
    found = targets(rows)
    lines += [f"| {t} | {m} | {v} |" for t, m, v in found]
    missed = [WHY_MISSED[t.split(":")[0]] for t, _, v in found
              if v.startswith("MISSED") and t.split(":")[0] in WHY_MISSED]
    if missed:
        lines += ["", "Why: " + " ".join(missed)]
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
        lines += [f"- {r['family']} {SIZE_LABEL[r['family']]}={r['size']:g} {r['method']}: "
                  f"{r['message']}" for r in failures]
    notes = sorted({(r["method"], r["note"]) for r in rows if r["note"]})
    lines += ["", "## What the timer covers beyond the solve", ""]
    lines += [f"- {m}: {n}" for m, n in notes]
    return "\n".join(lines) + "\n"


def plot(rows: list[dict], path: Path) -> None:
    """Log-log median time vs size, one panel per family, one line per method."""
    fams = [f for f in SIZE_LABEL if any(r["family"] == f for r in rows)]
    ncol = min(3, len(fams))
    nrow = -(-len(fams) // ncol)
    fig, axes = plt.subplots(nrow, ncol, figsize=(6 * ncol, 4.5 * nrow), squeeze=False)
    methods = list(dict.fromkeys(r["method"] for r in rows))
    colors = {m: plt.cm.tab20(i % 20) for i, m in enumerate(methods)}
    styles = {"impactqp": "-", "raw": "--", "peer": ":", "batch": "-"}
    for ax, family in zip(axes.flat, fams):
        for method in methods:
            pts = sorted((r["size"], r["median_s"], r["success_rate"]) for r in rows
                         if r["family"] == family and r["method"] == method
                         and r["median_s"] is not None)
            if not pts:
                continue
            x, y, ok = zip(*pts)
            group = next(r["group"] for r in rows if r["method"] == method)
            ax.plot(x, y, styles.get(group, "-"), color=colors[method], label=method, marker="o",
                    markersize=3)
            bad = [(a, b) for a, b, s in pts if s != 1]
            if bad:
                ax.plot(*zip(*bad), "x", color=colors[method], markersize=8)
        ax.set(xscale="log", yscale="log", title=family, xlabel=SIZE_LABEL[family],
               ylabel="median time [s]")
        ax.grid(True, which="major", alpha=0.3)
    for ax in list(axes.flat)[len(fams):]:
        ax.axis("off")
    handles, labels = {}, {}
    for ax in axes.flat:
        for h, lab in zip(*ax.get_legend_handles_labels()):
            handles.setdefault(lab, h)
    labels = list(handles)
    fig.legend([handles[k] for k in labels], labels, loc="lower center", ncol=6, fontsize=8,
               frameon=False)
    fig.suptitle("Moreau impact: median solve time (× = some runs failed or inaccurate)")
    fig.tight_layout(rect=(0, 0.03 + 0.012 * (len(labels) // 6 + 1), 1, 0.97))
    fig.savefig(path, dpi=110)
    plt.close(fig)


def write_all(records: list[dict], out_dir: Path, meta: dict) -> list[dict]:
    """Write results.csv, results.json, summary.md and plot.png into ``out_dir``."""
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
    return rows
