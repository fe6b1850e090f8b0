"""Rigid impact laws against the dispersive LZB model on chains of steel balls, and the
README's figure.

    python examples/lzb_comparison.py [OUT]      # default: docs/figures/lzb_comparison.png

Moreau's law (ε = 0 and ε = 1), the sector law and LZB (Hertz contacts, e = 1) for 3 and 10
touching steel balls of radius 1 cm, the first arriving at 1 m/s: prints one table per chain
(u⁺ of every ball, T⁺/T⁻, whether u⁺ lies in S) and draws both chains side by side. Needs
matplotlib (pip install 'impactqp[plot]').
"""

from __future__ import annotations

import sys
from pathlib import Path

from impactqp.figures.compare_plot import plot_comparison
from impactqp.model.physical_chains import monodisperse_chain
from impactqp.verification.compare import compare_chain


def main(out: Path) -> None:
    out.parent.mkdir(parents=True, exist_ok=True)
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


if __name__ == "__main__":
    main(Path(sys.argv[1]) if len(sys.argv) > 1 else Path("docs/figures/lzb_comparison.png"))
