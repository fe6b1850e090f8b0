"""Running the benchmarks from Python
==================================

Run the smoke benchmark suite from Python into a folder and print the head of its summary.

Run it as::

    python examples/benchmark_run.py                 # into a new temporary folder
    python examples/benchmark_run.py --out DIR       # into DIR (created if needed)

The benchmark package lives beside impactqp in the repository (``benchmarks/``), so this
script is run from a clone. It writes results.csv, results.json, summary.md and plot.png and
nothing else, into the folder it prints last. The command-line form of the same run is
``python -m benchmarks run --suite smoke --out DIR``.
"""

from __future__ import annotations

import argparse
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))  # the benchmarks package of the repository

from benchmarks.runner import run_suite  # noqa: E402


def main(out: Path) -> None:
    # siconos_python="" skips the Siconos peer, which needs Debian's python3-siconos
    records = run_suite("smoke", out, siconos_python="", progress=False)
    print(f"{len(records)} measurements, files: "
          f"{', '.join(sorted(p.name for p in out.iterdir()))}")
    summary = (out / "summary.md").read_text(encoding="utf-8").splitlines()
    print("\n".join(summary[:20]))
    print(f"results written to {out}")


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, help="output folder (default: a new temporary one)")
    out = parser.parse_args().out
    main(Path(tempfile.mkdtemp(prefix="impactqp-bench-")) if out is None else out)
