"""Figures of any system
=====================

A sphere's motion by kind of coordinate, its contact states and its animation; S of a 4-ball
cradle with a heavy ball; the sector law's cones of four balls.

    python examples/figures.py               # into a new temporary folder
    python examples/figures.py --out DIR     # into DIR (created if needed)

A sphere thrown sliding at 2 m/s without spin on a floor with Coulomb friction μ = 0.3 slides
until 2v₀/(7μg) ≈ 0.19 s, then rolls: sphere_positions.png draws x, y (metres) and φ
(radians) on axes of their own, sphere_contacts.png the contact's state (slide, then stick),
sphere.gif the sphere with a mark that turns with it. S_heavy_cradle.png is the section of S
through u⁻ of the cradle (1, 1, 1, 3) kg struck at both ends, u⁻ = (1, 0, 0, −0.5) m/s
(three contacts; no sector law for unequal masses, the legend says why), with Moreau's
half-line and the outcomes of elastic collisions taken leftmost or rightmost first, which
differ (the second off the plane, drawn projected); sectors_4_balls.png
the cones of the sector law of four equal balls cut by the plane of γ⁻ and γ⁺. Needs
matplotlib (pip install 'impactqp[plot]'). Writes these five files and nothing else, into
the folder it prints last.
"""

from __future__ import annotations

import argparse
import tempfile
from pathlib import Path

import impactqp as iq
from impactqp.simulation import rolling_sphere
from impactqp.simulation.contact_states import contact_states
from impactqp.tables.reflection_group import elastic_collisions

FILES = ("sphere_positions.png", "sphere_contacts.png", "sphere.gif", "S_heavy_cradle.png",
         "sectors_4_balls.png")


def main(outdir: Path) -> None:
    sphere = iq.simulate(rolling_sphere(velocity=2.0, gap=-1e-9), iq.Coulomb(0.3, 0.0), 0.5,
                         h=0.001)
    print(sphere.summary())
    codes, names = contact_states(sphere)
    rolling = sphere.t[codes[:, 0] == names.index("stick")][0]
    closed_form = 2 * 2.0 / (7 * 0.3 * 9.81)
    print(f"the sphere rolls from t = {rolling:.3f} s (2v₀/(7μg) = {closed_form:.3f} s)")
    sphere.plot("positions", outdir / "sphere_positions.png",
                title="Sphere thrown sliding at 2 m/s, μ = 0.3: x, y and φ")
    sphere.plot("contacts", outdir / "sphere_contacts.png",
                title="Its contact: slide, then stick (rolling)")
    sphere.animate(outdir / "sphere.gif", frames=40, fps=20)

    heavy = iq.chain([1.0, 1.0, 1.0, 3.0], [1.0, 0.0, 0.0, -0.5])
    # elastic collisions one at a time: their outcome depends on the order (docs/theory.md §10)
    left, _, n_left = elastic_collisions(heavy, "left")
    right, _, n_right = elastic_collisions(heavy, "right")
    iq.plot_admissible(heavy.admissible_set(), outdir / "S_heavy_cradle.png",
                       candidates={f"{n_left} collisions, leftmost first": left,
                                   f"{n_right} collisions, rightmost first": right},
                       title="4-ball cradle, masses (1, 1, 1, 3), u⁻ = (1, 0, 0, −0.5) m/s:\n"
                             "S cut by the plane of Moreau's half-line and the first outcome")
    print("S of the heavy 4-ball cradle: 3 contacts, drawn through u⁻")
    iq.plot_sectors(iq.newtons_cradle(4), outdir / "sectors_4_balls.png")
    print("sector law of 4 equal balls: cones cut by the plane of γ⁻ and γ⁺")
    for name in FILES:
        print(outdir / name, (outdir / name).stat().st_size, "bytes")
    print(f"figures written to {outdir}")


def output_folder(argv: list[str] | None = None) -> Path:
    """The folder of ``--out``, else a new temporary folder; created if needed."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, help="output folder (default: a new temporary one)")
    args = parser.parse_args(argv)
    if args.out is None:
        return Path(tempfile.mkdtemp(prefix="impactqp-figures-"))
    args.out.mkdir(parents=True, exist_ok=True)
    return args.out


if __name__ == "__main__":
    main(output_folder())
