"""Simulate a bouncing ball and Newton's cradle with impactqp and draw the README's figures.

    python examples/simulate_cradle.py [OUTDIR]      # default: docs/figures

Writes bouncing_ball_energy.png (event-driven, Newton e = 0.9: the ball comes to rest at the
accumulation time), cradle_positions.png and cradle.gif (a 5-ball cradle on pendulums under
the sector law: the motion passes whole from the first ball to the last and back). Needs
matplotlib (pip install 'impactqp[plot]').
"""

from __future__ import annotations

import sys
from pathlib import Path

from impactqp.figures.motion import animate_cradle, plot_energy, plot_positions
from impactqp.laws.complementarity import Newton
from impactqp.laws.sector import SectorLaw
from impactqp.simulation.builders import bouncing_ball, cradle_system
from impactqp.simulation.simulate import simulate


def main(outdir: Path) -> None:
    outdir.mkdir(parents=True, exist_ok=True)
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


if __name__ == "__main__":
    main(Path(sys.argv[1]) if len(sys.argv) > 1 else Path("docs/figures"))
