"""FCLib and Siconos files whose numbers are well-formed but physically impossible: a global
problem's M that is not positive definite (negative or indefinite masses) and a Delassus
matrix W with a negative diagonal entry are refused by name, never reduced and "certified";
a singular M is reported without the sparse solver's source locations."""

from __future__ import annotations

import shutil
from pathlib import Path

import h5py  # a dependency of impactqp
import numpy as np
import pytest

import impactqp as iq
from impactqp.cli.main import main
from impactqp.errors import ProblemFileError
from impactqp.io.siconos_text import write_siconos_text

DATA = Path(__file__).resolve().parent / "data" / "fclib"
GLOBAL = DATA / "LMGC_GlobalFrictionContactProblem00046.hdf5"
LOCAL = DATA / "LMGC_100_PR_PerioBox-i00361-60-03000.hdf5"


def _edited(src: Path, tmp_path: Path, dataset: str, edit) -> Path:
    dst = tmp_path / f"edited-{src.name}"
    shutil.copy(src, dst)
    with h5py.File(dst, "r+") as f:
        data = f[dataset]
        data[...] = edit(data[...].copy())
    return dst


def _negate_first(x: np.ndarray) -> np.ndarray:
    x[0] = -x[0]
    return x


@pytest.mark.parametrize("edit", [np.negative, _negate_first], ids=["negative", "indefinite"])
def test_a_global_mass_matrix_that_is_not_positive_definite_is_refused(edit, tmp_path):
    # negated, W = Hᵀ M⁻¹ H is negative definite and was "certified" with error 0
    path = _edited(GLOBAL, tmp_path, "fclib_global/M/x", edit)
    with pytest.raises(ProblemFileError, match=r"fclib_global/M.*positive definite") as info:
        iq.load_fclib(path)
    assert str(path) in str(info.value)


def test_the_shipped_global_problems_still_load():
    for name in ("LMGC_GlobalFrictionContactProblem00046.hdf5", "Box_Stacks-i0122-82-5.hdf5"):
        assert iq.load_fclib(DATA / name).n_contacts > 0


def test_a_singular_mass_matrix_is_named_without_solver_internals(tmp_path):
    # nz = 5: M read as a triplet of its first five entries, singular
    path = _edited(GLOBAL, tmp_path, "fclib_global/M/nz", lambda x: np.full_like(x, 5))
    with pytest.raises(ProblemFileError, match="fclib_global/M") as info:
        iq.load_fclib(path)
    assert ".c" not in str(info.value) and "SuperLU" not in str(info.value)


def test_a_negative_diagonal_of_w_is_refused_in_hdf5(tmp_path):
    path = _edited(LOCAL, tmp_path, "fclib_local/W/x", np.negative)
    with pytest.raises(ProblemFileError, match=r"fclib_local/W.*diagonal"):
        iq.load_fclib(path)


@pytest.mark.parametrize("entry", [0, 1], ids=["normal", "tangent"])
def test_a_negative_diagonal_of_w_is_refused_in_siconos_text(entry, tmp_path, capsys):
    W = np.array([[2.0, 0.1, 0.0], [0.1, 1.0, 0.0], [0.0, 0.0, 1.0]])
    W[entry, entry] = -W[entry, entry]
    path = write_siconos_text(iq.FrictionContactProblem(W, [-1.0, 0.5, 0.0], 0.3),
                              tmp_path / "bad.dat")
    with pytest.raises(ProblemFileError, match=r"bad\.dat.*W.*diagonal"):
        iq.load_fclib(path)
    assert main(["fclib", str(path)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "diagonal" in err[0] and "Traceback" not in err[0]
