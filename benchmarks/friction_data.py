"""The friction suite's problems: FCLib HDF5 files and Siconos' text files of local problems.

Both are read by :func:`impactqp.load_fclib`: HDF5 files (global ones reduced to local ones
by W = Hᵀ M⁻¹ H, q = Hᵀ M⁻¹ f + w) and Siconos' text files (``*.dat``, kept gzip-compressed,
byte-identical once decompressed; see benchmarks/data/fclib/README.md), whose layout
:mod:`impactqp.io.siconos_text` reads and writes.
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


@dataclass
class FrictionCase:
    """One problem of the friction suite, loaded before any timer starts.

    Attributes
    ----------
    name : str
        Short name (a key of :data:`FILES`).
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
    """Read the suite's problem ``name`` (a key of :data:`FILES`)."""
    path = FILES[name]
    return FrictionCase(name, path, iq.load_fclib(path))
