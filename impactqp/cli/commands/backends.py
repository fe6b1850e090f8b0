"""``impactqp backends``: every backend of the registry, whether it is installed, the program
forms and laws it serves, and what to install for those that are not (the solvers reached
through cvxpy and qpsolvers included, each with the extra of impactqp that brings it)."""

from __future__ import annotations

import argparse
from typing import Any

from ...laws.catalogue import available_backends
from ...qp import backends as registry
from ..report import to_json


def listing() -> list[dict[str, Any]]:
    """One dict per backend and per sub-solver: ``name``, ``installed``, ``forms``, ``laws``
    (the names of the laws it serves), ``install`` (what to install, "" when installed) and
    ``via`` (the family of a sub-solver, "" for a registry entry)."""
    rows = []
    for item in available_backends():
        laws = [law for law, forms in item["laws"].items() if forms]
        rows.append({"name": item["name"], "installed": item["installed"],
                     "forms": list(item["forms"]), "laws": laws,
                     "install": "" if item["installed"] else item["install"], "via": ""})
        for sub in registry.sub_solvers(registry.REGISTRY[item["name"]]):
            rows.append({"name": sub["name"], "installed": sub["installed"],
                         "forms": list(item["forms"]), "laws": laws,
                         "install": "" if sub["installed"] else sub["install"],
                         "via": item["name"]})
    return rows


def format_listing(rows: list[dict[str, Any]]) -> str:
    """The listing as a text table; a sub-solver is indented under its family and serves what
    its family serves."""
    table = [("backend", "installed", "forms", "laws")]
    notes = []
    for row in rows:
        name = f"  {row['name']}" if row["via"] else row["name"]
        same = bool(row["via"])
        table.append((name, "yes" if row["installed"] else "no",
                      "″" if same else ", ".join(row["forms"]),
                      "″" if same else ", ".join(row["laws"]) or "–"))
        notes.append(row["install"])
    widths = [max(len(r[i]) for r in table) for i in range(3)]
    lines = []
    for cells, note in zip(table, ["", *notes]):
        text = "  ".join([*(c.ljust(w) for c, w in zip(cells, widths)), cells[3]])
        lines.append(f"{text}   install: {note}" if note else text)
    installed = sum(r["installed"] for r in rows)
    lines += ["", f"{installed} of {len(rows)} installed; ″ = as its family above. "
              "Closed-form laws (sector, reflection, lzb) are evaluated by 'auto'; "
              "`impactqp bench FILE` compares the backends on a problem."]
    return "\n".join(lines)


def run(args: argparse.Namespace) -> int:
    rows = listing()
    print(to_json({"backends": rows}) if args.json else format_listing(rows))
    return 0


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("backends", help="list the backends: installed or not, what each "
                                        "serves, what to install")
    p.add_argument("--json", action="store_true", help="print the list as JSON")
    p.set_defaults(func=run)
