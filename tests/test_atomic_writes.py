"""Every writer is all or nothing: a writer that fails half-way (here made to write some
bytes and then raise) leaves the previous file byte for byte and no temporary file behind;
one that succeeds replaces the file whole."""

from __future__ import annotations

import gc
import os
import stat
from pathlib import Path

import numpy as np
import pytest

import impactqp as iq
from impactqp.base.outputs import atomic_output
from impactqp.io.fclib import load_fclib, save_fclib
from impactqp.model.friction import FrictionContactProblem

OLD = b"the previous file, which must survive\n"


class Interrupted(Exception):
    """The failure a test injects into a writer."""


def previous(path: Path) -> Path:
    path.write_bytes(OLD)
    return path


def assert_untouched(path: Path) -> None:
    assert path.read_bytes() == OLD
    assert sorted(p.name for p in path.parent.iterdir()) == [path.name]


def write_half_then_fail(target: object, *args: object, **kwargs: object) -> None:
    """A writer that gets some bytes out and dies (the fake of a serializer)."""
    with open(os.fspath(target), "wb") as handle:
        handle.write(b"PARTIAL")
    raise Interrupted


def method_writing_half_then_failing(self: object, target: object, *args: object,
                                     **kwargs: object) -> None:
    """The same, as a method (``Figure.savefig``, ``Animation.save``)."""
    write_half_then_fail(target)


def test_atomic_output_replaces_or_keeps(tmp_path: Path) -> None:
    path = previous(tmp_path / "a.txt")
    with pytest.raises(Interrupted), atomic_output(path) as temp:
        assert temp.parent == path.parent and temp.suffix == ".txt" and temp != path
        write_half_then_fail(temp)
    assert_untouched(path)
    with pytest.raises(KeyboardInterrupt), atomic_output(path) as temp:
        temp.write_bytes(b"PARTIAL")
        raise KeyboardInterrupt
    assert_untouched(path)
    with atomic_output(path) as temp:
        temp.write_bytes(b"new")
        assert path.read_bytes() == OLD  # not visible before the block ends
    assert path.read_bytes() == b"new"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.txt"]


def test_atomic_output_keeps_permissions_and_links(tmp_path: Path) -> None:
    path = previous(tmp_path / "a.txt")
    path.chmod(0o640)
    with atomic_output(path) as temp:
        temp.write_bytes(b"new")
    assert stat.S_IMODE(path.stat().st_mode) == 0o640
    mask = os.umask(0)
    os.umask(mask)
    with atomic_output(tmp_path / "fresh.txt") as temp:
        temp.write_bytes(b"new")
    assert stat.S_IMODE((tmp_path / "fresh.txt").stat().st_mode) == 0o666 & ~mask
    link = tmp_path / "link.txt"
    link.symlink_to(path)
    with atomic_output(link) as temp:
        temp.write_bytes(b"through the link")
    assert link.is_symlink() and path.read_bytes() == b"through the link"


def test_atomic_output_refuses_what_is_not_a_regular_file(tmp_path: Path) -> None:
    (tmp_path / "dir.txt").mkdir()
    with pytest.raises(iq.InputError, match="not a regular file"), \
            atomic_output(tmp_path / "dir.txt"):
        pass
    with pytest.raises(iq.InputError, match="cannot write"), \
            atomic_output(tmp_path / "no" / "such" / "a.txt"):
        pass


@pytest.mark.parametrize("suffix", [".json", ".toml"])
def test_save_problem(tmp_path: Path, monkeypatch: pytest.MonkeyPatch, suffix: str) -> None:
    path = previous(tmp_path / f"p{suffix}")
    with monkeypatch.context() as patch:
        patch.setattr(Path, "write_text", write_half_then_fail)
        with pytest.raises(Interrupted):
            iq.save_problem(iq.newtons_cradle(3), path)
    assert_untouched(path)
    iq.save_problem(iq.newtons_cradle(3), path)
    np.testing.assert_array_equal(iq.load_problem(path).problem.u_minus, [1.0, 0.0, 0.0])
    assert sorted(p.name for p in tmp_path.iterdir()) == [path.name]


def test_save_fclib(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    import h5py

    problem = FrictionContactProblem(np.eye(3), np.array([-1.0, 0.5, 0.0]), 0.3)
    path = previous(tmp_path / "p.hdf5")
    create = h5py.Group.create_dataset

    def fail_at_mu(self: h5py.Group, name: str, *args: object, **kwargs: object) -> object:
        if name == "mu":  # W and q are in the file by now
            raise Interrupted
        return create(self, name, *args, **kwargs)

    with monkeypatch.context() as patch:
        patch.setattr(h5py.Group, "create_dataset", fail_at_mu)
        with pytest.raises(Interrupted):
            save_fclib(problem, path)
    assert_untouched(path)
    assert save_fclib(problem, str(path)) == path
    np.testing.assert_array_equal(load_fclib(path).q, problem.q)
    assert sorted(p.name for p in tmp_path.iterdir()) == [path.name]


@pytest.fixture(scope="module")
def trajectory() -> iq.Trajectory:
    return iq.simulate(iq.simulation.bouncing_ball(), iq.Newton(0.9), 0.5, h=0.01)


@pytest.mark.parametrize("suffix, writer", [(".npz", "savez_compressed"), (".csv", "savetxt")])
def test_trajectory_save(tmp_path: Path, monkeypatch: pytest.MonkeyPatch, trajectory,
                         suffix: str, writer: str) -> None:
    path = previous(tmp_path / f"run{suffix}")
    with monkeypatch.context() as patch:
        patch.setattr(np, writer, write_half_then_fail)
        with pytest.raises(Interrupted):
            trajectory.save(path)
    assert_untouched(path)
    trajectory.save(path)
    assert path.read_bytes() != OLD
    names = sorted(p.name for p in tmp_path.iterdir())
    assert names == ([path.name] if suffix == ".npz" else [path.name, "run.events.csv"])
    if suffix == ".npz":
        np.testing.assert_array_equal(np.load(path)["t"], trajectory.t)


def test_figures(tmp_path: Path, monkeypatch: pytest.MonkeyPatch, trajectory) -> None:
    pytest.importorskip("matplotlib")
    from matplotlib.figure import Figure

    from impactqp.figures.compare_plot import plot_comparison
    from impactqp.figures.sections import plot_sectors

    path = previous(tmp_path / "s.png")
    with monkeypatch.context() as patch:
        patch.setattr(Figure, "savefig", method_writing_half_then_failing)
        with pytest.raises(Interrupted):
            plot_sectors(path=path)
        with pytest.raises(Interrupted):
            trajectory.plot("energy", path)
        with pytest.raises(Interrupted):
            plot_comparison([iq.verification.compare_chain(iq.chains.monodisperse_chain(3))], path)
    assert_untouched(path)
    plot_sectors(path=path)
    assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["s.png"]


@pytest.mark.filterwarnings("ignore:Animation was deleted without rendering")
def test_animation(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    pytest.importorskip("matplotlib")
    from matplotlib.animation import Animation

    cradle = iq.simulate(iq.simulation.cradle_system(3), iq.SectorLaw(), 1.0, scheme="event-driven",
                         h=0.05)
    path = previous(tmp_path / "c.gif")
    with monkeypatch.context() as patch:
        patch.setattr(Animation, "save", method_writing_half_then_failing)
        with pytest.raises(Interrupted):
            cradle.animate(path, frames=3, fps=3)
    gc.collect()  # the unsaved animation warns when collected: here, not in a later test
    assert_untouched(path)
    cradle.animate(path, frames=3, fps=3)
    assert path.read_bytes()[:6] == b"GIF89a"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["c.gif"]


KILLED_MID_WRITE = """
import os, signal, sys
from pathlib import Path
import impactqp as iq

def die_half_way(self, text, *args, **kwargs):
    with open(self, "w") as handle:
        handle.write(text[: len(text) // 2])
    os.kill(os.getpid(), signal.SIGKILL)

Path.write_text = die_half_way
iq.save_problem(iq.newtons_cradle(3), sys.argv[1])
"""


@pytest.mark.skipif(not hasattr(os, "kill") or os.name != "posix", reason="needs SIGKILL")
def test_a_writer_killed_half_way_leaves_the_old_file(tmp_path: Path) -> None:
    import signal
    import subprocess
    import sys

    path = previous(tmp_path / "p.toml")
    out = subprocess.run([sys.executable, "-c", KILLED_MID_WRITE, str(path)], timeout=120,
                         capture_output=True, text=True)
    assert out.returncode == -signal.SIGKILL, out.stderr
    assert path.read_bytes() == OLD
    # the killed process could not clean up: its half-written temporary is all that is left
    strays = [p for p in tmp_path.iterdir() if p != path]
    assert len(strays) == 1 and strays[0].name.startswith(".p.")
    assert strays[0].name.endswith(".part.toml")
