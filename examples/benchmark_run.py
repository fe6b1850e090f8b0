"""Run the smoke benchmark suite from Python into a temporary folder and print the head of
its summary.

The benchmark package lives beside impactqp in the repository (``benchmarks/``), so this
script is run from a clone: ``python examples/benchmark_run.py``. The command-line form of
the same run is ``python -m benchmarks run --suite smoke --out DIR``.
"""

from __future__ import annotations

import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))  # the benchmarks package of the repository

from benchmarks.runner import run_suite  # noqa: E402


def main() -> None:
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp)
        # siconos_python="" skips the Siconos peer, which needs Debian's python3-siconos
        records = run_suite("smoke", out, siconos_python="", progress=False)
        print(f"{len(records)} measurements, files: "
              f"{', '.join(sorted(p.name for p in out.iterdir()))}")
        summary = (out / "summary.md").read_text(encoding="utf-8").splitlines()
        print("\n".join(summary[:20]))


if __name__ == "__main__":
    main()
