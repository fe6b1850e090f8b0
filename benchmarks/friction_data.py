"""The friction suite's problems: FCLib HDF5 files and Siconos' text files of local problems.

Both are read by :func:`impactqp.load_fclib`: HDF5 files (global ones reduced to local ones
by W = Hᵀ M⁻¹ H, q = Hᵀ M⁻¹ f + w) and Siconos' text files (``*.dat``, kept gzip-compressed,
byte-identical once decompressed; see benchmarks/data/fclib/README.md), whose layout
:mod:`impactqp.io.siconos_text` reads and writes.

:data:`FILES` are the nine problems of the ``friction`` suite; :data:`WIDE` the further public
problems of Siconos' test data that the ``fclib-wide`` suite runs beside them: 2-D and 3-D,
one global, 1 to 7,002 contacts, μ from 0.01 to 1, W from well-conditioned to rank-deficient
with cond(W) ~ 1e19.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import impactqp as iq

ROOT = Path(__file__).resolve().parents[1]
TESTS_FCLIB = ROOT / "tests" / "data" / "fclib"
BENCH_FCLIB = Path(__file__).resolve().parent / "data" / "fclib"

#: short name → file (tests/data/fclib or benchmarks/data/fclib)
FILES: dict[str, Path] = {
    "LMGC-00046": TESTS_FCLIB / "LMGC_GlobalFrictionContactProblem00046.hdf5",
    "NESpheres-10": BENCH_FCLIB / "NESpheres_10_1.dat.gz",
    "BoxesStack1": BENCH_FCLIB / "BoxesStack1-i100000-32.hdf5.dat.gz",
    "PerioBox": TESTS_FCLIB / "LMGC_100_PR_PerioBox-i00361-60-03000.hdf5",
    "Box_Stacks": TESTS_FCLIB / "Box_Stacks-i0122-82-5.hdf5",
    "spheres-in-a-box": TESTS_FCLIB / "spheres-in-a-box-98-i10000-256-10.hdf5",
    "Capsules": TESTS_FCLIB / "Capsules-i125-1213.hdf5",
    "Spheres": BENCH_FCLIB / "Spheres-i099-356-679.hdf5",
    "KaplasTower": BENCH_FCLIB / "KaplasTower-i1061-4.hdf5.dat.gz",
}

_WIDE_FILES = {  # short name → file name in benchmarks/data/fclib
    "FC3D-RR-1c": "FrictionContact3D_RR_1c.dat.gz",
    "Rover11035": "Rover11035.dat.gz",
    "Rover11211": "Rover11211.dat.gz",
    "CubeH8": "CubeH8.hdf5",
    "Rover4396": "Rover4396.dat.gz",
    "FC3D-Example1": "FC3D_Example1_SBM.dat.gz",
    "TwoRods1-condensed": "GFC3D_TwoRods1-condensed.dat.gz",
    "Confeti-ex13-4c": "Confeti-ex13-4contact-Fc3D-SBM.dat.gz",
    "Rover1039": "Rover1039.dat.gz",
    "Rover4144": "Rover4144.dat.gz",
    "Rover1040": "Rover1040.dat.gz",
    "Rover9770": "Rover9770.dat.gz",
    "OneObject-138": "OneObject-i1028-138.hdf5.dat.gz",
    "OneObject-499": "OneObject-i100000-499.hdf5.dat.gz",
    "OneObject-316": "OneObject-i100000-316.hdf5.dat.gz",
    "NESpheres-30": "NESpheres_30_1.dat.gz",
    "Confeti-ex03": "Confeti-ex03-Fc3D-SBM.dat.gz",
    "Confeti-ex13": "Confeti-ex13-Fc3D-SBM.dat.gz",
    "Capsules-404": "Capsules-i101-404.dat.gz",
    "Capsules-1617": "Capsules-i122-1617.dat.gz",
    "RockPile": "RockPile_tob1.dat.gz",
    "FC2D-SliderCrank-1": "FC2D_SliderCrankLagrangian00001.dat.gz",
    "FC2D-00394": "FrictionContactProblem00394.dat.gz",
    "FC2D-00031": "FrictionContactProblem00031.dat.gz",
    "FC2D-00374": "FrictionContactProblem00374.dat.gz",
    "FC2D-00071": "FrictionContactProblem00071.dat.gz",
    "FC2D-00727": "FrictionContactProblem00727.dat.gz",
    "FC2D-00237": "FrictionContactProblem00237.dat.gz",
    "Granular2D-667": "fc2d_granularflowonwall_00667_00000.dat.gz",
    "Granular2D-2020": "fc2d_granularflowonwall_02020_00213.dat.gz",
    "Granular2D-7002": "fc2d_granularflowonwall_07002_00801.dat.gz",
}
#: the ``fclib-wide`` suite's further problems: short name → file (the two Siconos text files
#: of tests/data/fclib, the rest added to benchmarks/data/fclib for it)
WIDE: dict[str, Path] = {
    "FC3D-1c": TESTS_FCLIB / "FrictionContact3D_1c.dat",
    "FC2D-SliderCrank-0": TESTS_FCLIB / "FC2D_SliderCrankLagrangian00000.dat",
    **{name: BENCH_FCLIB / file for name, file in _WIDE_FILES.items()}}
ALL: dict[str, Path] = {**FILES, **WIDE}
"""Every problem: the ``friction`` suite's and the widened set's."""


@dataclass
class FrictionCase:
    """One problem of the friction suite, loaded before any timer starts.

    Attributes
    ----------
    name : str
        Short name (a key of :data:`ALL`).
    path : Path
        Where it was read from.
    problem : FrictionContactProblem
        W, q, μ as impactqp reads them (the same arrays go to Siconos).
    """

    name: str
    path: Path
    problem: iq.FrictionContactProblem

    @property
    def n_contacts(self) -> int:
        return self.problem.n_contacts

    @property
    def family(self) -> str:
        """The family of its rows in results.csv (one per problem)."""
        return f"friction:{self.name}"


def load(name: str) -> FrictionCase:
    """Read the problem ``name`` (a key of :data:`ALL`)."""
    path = ALL[name]
    return FrictionCase(name, path, iq.load_fclib(path))
