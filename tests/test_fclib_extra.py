"""h5py is the ``fclib`` extra, not a core dependency (issue 27: a lighter install): without
it, impactqp imports whole, Siconos' text files are read, and an FCLib (HDF5) file is refused
by name with the extra that installs h5py, from Python and from the command line."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from declared_dependencies import declared

import impactqp as iq
from impactqp.cli import main
from impactqp.errors import OptionalDependencyError
from impactqp.io.hdf5_reader import FCLIB_EXTRA

ROOT = Path(__file__).resolve().parent.parent
DATA = ROOT / "tests" / "data" / "fclib"
HDF5 = DATA / "LMGC_GlobalFrictionContactProblem00046.hdf5"
TEXT = DATA / "FrictionContact3D_1c.dat"
REFUSAL = r"FCLib files \(HDF5\) need h5py: pip install 'impactqp\[fclib\]'"


@pytest.fixture
def without_h5py(monkeypatch: pytest.MonkeyPatch) -> None:
    """``import h5py`` fails, as in an install without the extra."""
    monkeypatch.setitem(sys.modules, "h5py", None)


def test_h5py_is_the_extra_the_refusal_names_and_what_tests_and_docs_install() -> None:
    core, extras = declared()
    assert "h5py" not in core
    assert extras[FCLIB_EXTRA] == {"h5py"}
    assert "h5py" in extras["test"]  # the suite reads FCLib files
    assert "h5py" in extras["docs"]  # the gallery's friction example reads one


def test_an_hdf5_file_is_refused_by_name_without_h5py(without_h5py: None,
                                                       tmp_path: Path) -> None:
    with pytest.raises(OptionalDependencyError, match=REFUSAL):
        iq.load_fclib(HDF5)
    with pytest.raises(ImportError):  # an OptionalDependencyError is an ImportError too
        iq.load_fclib(HDF5)
    problem = iq.FrictionContactProblem(np.eye(3), np.array([-1.0, 0.2, 0.0]), 0.5)
    with pytest.raises(OptionalDependencyError, match=REFUSAL):
        iq.save_fclib(problem, tmp_path / "p.hdf5")
    assert not (tmp_path / "p.hdf5").exists()


def test_a_siconos_text_file_is_read_and_solved_without_h5py(without_h5py: None) -> None:
    problem = iq.load_fclib(TEXT)
    result = iq.solve_friction(problem)
    assert result.certificate.ok and problem.q.size == 3  # one contact in space


def test_the_command_line_names_the_extra_without_h5py(
        without_h5py: None, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["fclib", str(HDF5)]) == 2
    err = capsys.readouterr().err
    assert "impactqp[fclib]" in err and err.count("\n") == 1
    assert main(["fclib", str(TEXT)]) == 0


def test_every_module_imports_without_h5py() -> None:
    code = (
        "import sys, pkgutil, importlib\n"
        "sys.modules['h5py'] = None\n"
        "import impactqp\n"
        "skip = ('impactqp.__main__', 'impactqp.interop.jax', 'impactqp.interop.torch')\n"
        "for m in pkgutil.walk_packages(impactqp.__path__, 'impactqp.'):\n"
        "    if m.name not in skip:\n"
        "        importlib.import_module(m.name)\n"
        "print('ok')\n")
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         cwd=ROOT, timeout=240)
    assert run.returncode == 0 and run.stdout.strip() == "ok", run.stderr
