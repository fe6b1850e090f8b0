"""Motion: the bouncing ball and the cradle on pendulums
=====================================================

Simulate a bouncing ball and Newton's cradle with impactqp and draw the gallery's figures.

Run it as::

    python examples/simulate_cradle.py               # into a new temporary folder
    python examples/simulate_cradle.py --out DIR     # into DIR (created if needed)
    python examples/simulate_cradle.py --docs        # regenerate docs/figures of the clone

Writes bouncing_ball_energy.png (event-driven, Newton e = 0.9: the ball comes to rest at the
accumulation time), cradle_positions.png and cradle.gif (a 5-ball cradle on pendulums under
the sector law: the motion passes whole from the first ball to the last and back). Needs
matplotlib (pip install 'impactqp[plot]'). Writes these three files and nothing else, into
the folder it prints last.
"""

from __future__ import annotations

import argparse
import tempfile
from pathlib import Path

from impactqp.figures.motion import animate_cradle, plot_energy, plot_positions
from impactqp.laws.complementarity import Newton
from impactqp.laws.sector import SectorLaw
from impactqp.simulation.builders import bouncing_ball, cradle_system
from impactqp.simulation.simulate import simulate

DOCS = Path(__file__).resolve().parents[1] / "docs" / "figures"


def main(outdir: Path) -> None:
    ball = simulate(bouncing_ball(), Newton(0.9), 10.0, scheme="event-driven", h=0.01)
    print(ball.summary())
    plot_energy(ball, outdir / "bouncing_ball_energy.png",
                title="Bouncing ball, Newton e = 0.9, event-driven: at rest after t∞ ≈ 8.58")
    cradle = simulate(cradle_system(5, length=0.3, amplitude=0.07), SectorLaw(), 2.2,
                      scheme="event-driven", h=0.005)
    print(cradle.summary())
    plot_positions(cradle, outdir / "cradle_positions.png",
                   title="5-ball cradle on pendulums, sector law: qᵢ(t)")
    animate_cradle(cradle, outdir / "cradle.gif", length=0.3, radius=0.03, frames=110, fps=50)
    for name in ("bouncing_ball_energy.png", "cradle_positions.png", "cradle.gif"):
        print(outdir / name, (outdir / name).stat().st_size, "bytes")
    print(f"figures written to {outdir}")


def output_folder(argv: list[str] | None = None) -> Path:
    """The folder of ``--out``, the clone's docs/figures with ``--docs``, else a new
    temporary folder; created if needed."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    where = parser.add_mutually_exclusive_group()
    where.add_argument("--out", type=Path, help="output folder (default: a new temporary one)")
    where.add_argument("--docs", action="store_true",
                       help=f"regenerate the committed figures in {DOCS}")
    args = parser.parse_args(argv)
    folder = DOCS if args.docs else args.out
    if folder is None:
        return Path(tempfile.mkdtemp(prefix="impactqp-figures-"))
    folder.mkdir(parents=True, exist_ok=True)
    return folder


if __name__ == "__main__":
    main(output_folder())
