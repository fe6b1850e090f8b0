"""Rigid laws against the dispersive LZB model
===========================================

Rigid impact laws against the dispersive LZB model on chains of steel balls, and the
gallery's figure.

Run it as::

    python examples/lzb_comparison.py                # into a new temporary folder
    python examples/lzb_comparison.py --out DIR      # into DIR (created if needed)
    python examples/lzb_comparison.py --docs         # regenerate docs/figures of the clone

Moreau's law (ε = 0 and ε = 1), the sector law and LZB (Hertz contacts, e = 1) for 3 and 10
touching steel balls of radius 1 cm, the first arriving at 1 m/s: prints one table per chain
(u⁺ of every ball, T⁺/T⁻, whether u⁺ lies in S) and draws both chains side by side. Needs
matplotlib (pip install 'impactqp[plot]'). Writes lzb_comparison.png and nothing else, into
the folder it prints last.
"""

from __future__ import annotations

import argparse
import tempfile
from pathlib import Path

from impactqp.figures.compare_plot import plot_comparison
from impactqp.model.physical_chains import monodisperse_chain
from impactqp.verification.compare import compare_chain

DOCS = Path(__file__).resolve().parents[1] / "docs" / "figures"


def main(outdir: Path) -> None:
    out = outdir / "lzb_comparison.png"
    comparisons = []
    for n in (3, 10):
        c = compare_chain(monodisperse_chain(n, radius=0.01))  # steel, striker at 1 m/s
        record = c.lzb.result.certificate.record
        print(f"{n} balls, u⁻ = (1, 0, …, 0) m/s; LZB: {record.primary_switches} primary "
              f"switches, {record.steps} steps, certificate "
              f"{c.lzb.result.certificate.summary()}")
        print(c.table(), end="\n\n")
        comparisons.append(c)
    path = plot_comparison(comparisons, out, titles=[
        "3 steel balls, R = 1 cm, Hertz contacts, striker at 1 m/s",
        "10 steel balls (Siconos' chain of balls), striker at 1 m/s"])
    print(path, path.stat().st_size, "bytes")
    print(f"figures written to {outdir}")


def output_folder(argv: list[str] | None = None) -> Path:
    """The folder of ``--out``, the clone's docs/figures with ``--docs``, else a new
    temporary folder; created if needed."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    where = parser.add_mutually_exclusive_group()
    where.add_argument("--out", type=Path, help="output folder (default: a new temporary one)")
    where.add_argument("--docs", action="store_true",
                       help=f"regenerate the committed figure in {DOCS}")
    args = parser.parse_args(argv)
    folder = DOCS if args.docs else args.out
    if folder is None:
        return Path(tempfile.mkdtemp(prefix="impactqp-figures-"))
    folder.mkdir(parents=True, exist_ok=True)
    return folder


if __name__ == "__main__":
    main(output_folder())
