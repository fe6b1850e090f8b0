"""Malformed and hostile problem files through the command line, each in a fresh process:
exit 2, one line on stderr, no traceback, within seconds."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import impactqp as iq

TIMEOUT = 60  # generous for a loaded 2-core machine; each case takes about a second


def run(*args: str, cwd: Path | None = None) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "impactqp", *args], capture_output=True,
                          text=True, timeout=TIMEOUT, cwd=cwd, stdin=subprocess.DEVNULL)


def assert_refused(out: subprocess.CompletedProcess, *words: str) -> None:
    assert out.returncode == 2, (out.returncode, out.stdout, out.stderr)
    assert "Traceback" not in out.stderr
    lines = out.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("impactqp: error:"), out.stderr
    for word in words:
        assert word in lines[0], lines[0]


def write(path: Path, text: str) -> Path:
    path.write_text(text, encoding="utf-8")
    return path


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="named pipes need a POSIX system")
def test_fifo_does_not_hang(tmp_path: Path) -> None:
    fifo = tmp_path / "pipe.json"
    os.mkfifo(fifo)
    assert_refused(run("solve", str(fifo)), "not a regular file")


@pytest.mark.skipif(not Path("/dev/zero").exists(), reason="needs /dev/zero")
def test_device_does_not_exhaust_memory(tmp_path: Path) -> None:
    link = tmp_path / "zero.json"
    link.symlink_to("/dev/zero")
    assert_refused(run("verify", str(link), "--u-plus", "0,0,1"), "not a regular file")


def test_directory_missing_file_and_binary(tmp_path: Path) -> None:
    (tmp_path / "dir.json").mkdir()
    assert_refused(run("solve", str(tmp_path / "dir.json")), "not a regular file")
    assert_refused(run("solve", str(tmp_path / "absent.json")), "cannot read")
    (tmp_path / "bin.json").write_bytes(b"\xff\xfe\x00garbage")
    assert_refused(run("solve", str(tmp_path / "bin.json")), "UTF-8")


def test_oversized_file(tmp_path: Path) -> None:
    big = tmp_path / "big.json"
    with big.open("w") as f:
        f.write('{"u_minus": [' + ",".join(["0"] * 6_000_000) + "]}")
    assert_refused(run("solve", str(big)), "limit")


def test_huge_integers_and_deep_nesting(tmp_path: Path) -> None:
    huge = "9" * 400
    assert_refused(run("solve", str(write(tmp_path / "huge.json",
                                          f'{{"masses": [1, 1], "u_minus": [{huge}, 0]}}'))),
                   "too large")
    assert_refused(run("solve", str(write(tmp_path / "huge.toml",
                                          f"masses = [1, 1]\nu_minus = [{huge}, 0]\n"))))
    deep = "[" * 100_000 + "]" * 100_000
    assert_refused(run("solve", str(write(tmp_path / "deep.json", f'{{"u_minus": {deep}}}'))))


def test_work_is_bounded_before_solving(tmp_path: Path) -> None:
    # 10⁴ copies of one contact in a small file: a dense 10⁴ × 10⁴ Delassus matrix
    W = [[-1.0] * 10_000, [1.0] * 10_000]
    path = write(tmp_path / "dup.json", json.dumps({"M": [[1.0, 0.0], [0.0, 1.0]], "W": W,
                                                     "u_minus": [1.0, 0.0]}))
    assert path.stat().st_size < 200_000
    assert_refused(run("solve", str(path)), "contacts")


def test_unwritable_output(tmp_path: Path) -> None:
    out = run("plot", "sectors", "--out", str(tmp_path / "no" / "such" / "dir" / "s.png"))
    if "matplotlib" in out.stderr:
        pytest.skip("the plot extra is not installed")
    assert_refused(out)


def test_negative_candidate_without_equals_sign(tmp_path: Path) -> None:
    path = tmp_path / "cradle.json"
    iq.save_problem(iq.newtons_cradle(3), path)
    out = run("verify", str(path), "--u-plus", "-1,0,0")
    assert out.returncode == 1 and "kinetic" in out.stdout  # parsed, and not in S
    assert run("verify", str(path), "--u-plus", "0,0,1").returncode == 0


@pytest.mark.parametrize("scale", [1e-200, 1e-16, 1e30, 1e200])
def test_verify_verdict_does_not_depend_on_units(tmp_path: Path, scale: float) -> None:
    path = tmp_path / "cradle.json"
    iq.save_problem(iq.newtons_cradle(3, v=scale), path)
    good = ",".join(repr(float(x)) for x in np.array([0.0, 0.0, 1.0]) * scale)
    gain = ",".join(repr(float(x)) for x in np.array([-7.0, 0.0, 8.0]) * scale)  # 49× the energy
    assert run("verify", str(path), "--u-plus", good).returncode == 0
    out = run("verify", str(path), "--u-plus", gain)
    assert out.returncode == 1 and "energetic" in out.stdout


# --- FCLib (HDF5) files that reach outside themselves or declare more than they hold ---------

LOAD_EACH = """
import json, sys, time
from impactqp.errors import ProblemFileError
from impactqp.io.fclib import load_fclib
for path in sys.argv[1:]:
    print(json.dumps({"file": path, "started": True}), flush=True)
    start = time.perf_counter()
    try:
        load_fclib(path)
        outcome = {"error": None, "message": ""}
    except ProblemFileError as exc:
        outcome = {"error": type(exc).__name__, "message": str(exc)}
    except Exception as exc:
        outcome = {"error": "bare " + type(exc).__name__, "message": str(exc)}
    outcome.update(file=path, seconds=time.perf_counter() - start)
    print(json.dumps(outcome), flush=True)
"""


def load_each(paths: list[Path]) -> dict[str, dict]:
    """Each file through iq.load_fclib in one fresh process, timed there; a file that hangs
    fails the test at the timeout (naming it) instead of hanging the suite."""
    try:
        out = subprocess.run([sys.executable, "-c", LOAD_EACH, *map(str, paths)],
                             capture_output=True, text=True, timeout=TIMEOUT,
                             stdin=subprocess.DEVNULL)
    except subprocess.TimeoutExpired as exc:
        pytest.fail(f"load_fclib hung; last lines: {exc.stdout!r}")
    assert out.returncode == 0, out.stderr
    rows = [json.loads(line) for line in out.stdout.splitlines()]
    return {Path(r["file"]).name: r for r in rows if "started" not in r}


def fclib_file(path: Path) -> Path:
    from impactqp.io.fclib import save_fclib
    from impactqp.model.friction import FrictionContactProblem

    problem = FrictionContactProblem(np.eye(3), np.array([-1.0, 0.5, 0.0]), 0.3)
    return save_fclib(problem, path)


def replace_q(path: Path, **dataset: object) -> Path:
    """The problem file at ``path`` with /fclib_local/vectors/q made again with ``dataset``
    (h5py.Group.create_dataset's keywords)."""
    import h5py

    fclib_file(path)
    with h5py.File(path, "a") as handle:
        del handle["fclib_local/vectors/q"]
        handle["fclib_local/vectors"].create_dataset("q", **dataset)
    return path


@pytest.fixture
def hostile(tmp_path: Path) -> dict[str, tuple[Path, str]]:
    """Each hostile file and a word its refusal must name."""
    import h5py

    fifo = tmp_path / "pipe"
    os.mkfifo(fifo)
    files: dict[str, tuple[Path, str]] = {}

    path = fclib_file(tmp_path / "link_root.hdf5")
    with h5py.File(path, "a") as handle:
        del handle["fclib_local"]
        handle["fclib_local"] = h5py.ExternalLink(str(fifo), "/fclib_local")
    files["link_root"] = (path, "external link")

    path = fclib_file(tmp_path / "link_q.hdf5")
    with h5py.File(path, "a") as handle:
        del handle["fclib_local/vectors/q"]
        handle["fclib_local/vectors/q"] = h5py.ExternalLink(str(fifo), "/q")
    files["link_q"] = (path, "external link")

    path = fclib_file(tmp_path / "soft.hdf5")
    with h5py.File(path, "a") as handle:
        handle["elsewhere"] = h5py.ExternalLink(str(fifo), "/q")
        del handle["fclib_local/vectors/q"]
        handle["fclib_local/vectors/q"] = h5py.SoftLink("/elsewhere")
    files["soft"] = (path, "soft link")

    for name, target in (("zero", "/dev/zero"), ("raw_fifo", str(fifo))):
        path = replace_q(tmp_path / f"{name}.hdf5", shape=(3,), dtype=float,
                         external=[(target, 0, 24)])
        files[name] = (path, "external raw file")

    source = tmp_path / "source.hdf5"
    with h5py.File(source, "w") as handle:
        handle["q"] = np.array([-1.0, 0.5, 0.0])
    layout = h5py.VirtualLayout(shape=(3,), dtype=float)
    layout[:] = h5py.VirtualSource(str(source), "q", shape=(3,))
    path = fclib_file(tmp_path / "virtual.hdf5")
    with h5py.File(path, "a") as handle:
        del handle["fclib_local/vectors/q"]
        handle["fclib_local/vectors"].create_virtual_dataset("q", layout)
    files["virtual"] = (path, "virtual dataset")

    path = replace_q(tmp_path / "huge.hdf5", shape=(10**10,), dtype=float, chunks=(2**16,),
                     compression="gzip")
    files["huge"] = (path, "has 10000000000 entries, expected 3")
    # W's values in a compressed dataset declaring 10¹⁰ (80 GB) where 3 are needed (the
    # values may outnumber the entries, as with FCLib's nzmax): refused by the size cap
    path = fclib_file(tmp_path / "huge_x.hdf5")
    with h5py.File(path, "a") as handle:
        group = handle["fclib_local/W"]
        del group["p"], group["i"], group["x"]
        group["p"] = np.array([0, 1, 2, 3], dtype=np.int64)
        group["i"] = np.array([0, 1, 2], dtype=np.int64)
        group.create_dataset("x", shape=(10**10,), dtype=float, chunks=(2**16,),
                             compression="gzip")
    files["huge_x"] = (path, "fclib_local/W/x: declares 80000000000 bytes")
    # three entries, one 2 GiB chunk: reading them would decompress it all
    path = replace_q(tmp_path / "huge_chunk.hdf5", shape=(3,), maxshape=(None,),
                     dtype=float, chunks=(2**28,), compression="gzip")
    files["huge_chunk"] = (path, "chunks of 2147483648 bytes")
    return files


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="named pipes need a POSIX system")
def test_hostile_fclib_files_are_refused_by_name_within_a_second(hostile) -> None:
    for path, _ in hostile.values():
        assert path.stat().st_size < 100_000  # small files, whatever they declare
    results = load_each([path for path, _ in hostile.values()])
    for name, (path, word) in hostile.items():
        row = results[path.name]
        assert row["error"] == "ProblemFileError", (name, row)
        assert word in row["message"] and str(path) in row["message"], (name, row)
        assert row["seconds"] < 1.0, (name, row)


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="named pipes need a POSIX system")
def test_hostile_fclib_file_through_the_command_line(hostile) -> None:
    assert_refused(run("fclib", str(hostile["link_root"][0])), "external link")
    assert_refused(run("fclib", str(hostile["zero"][0])), "external raw file")


def test_fclib_file_in_its_own_storage_still_loads(tmp_path: Path) -> None:
    # the same problem, q chunked and compressed in the file itself: read as before
    path = replace_q(tmp_path / "plain.hdf5", data=np.array([-1.0, 0.5, 0.0]), chunks=(2,),
                     compression="gzip")
    from impactqp.io.fclib import load_fclib

    problem = load_fclib(path)
    np.testing.assert_array_equal(problem.q, [-1.0, 0.5, 0.0])
    np.testing.assert_array_equal(problem.W.toarray(), np.eye(3))


def test_fclib_memory_error_is_named(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    from impactqp.errors import ProblemFileError
    from impactqp.io import fclib

    def no_memory(*args: object, **kwargs: object) -> None:
        raise MemoryError

    monkeypatch.setattr(fclib, "_local", no_memory)
    with pytest.raises(ProblemFileError, match="memory"):
        fclib.load_fclib(fclib_file(tmp_path / "p.hdf5"))


@pytest.mark.parametrize("dataset, word", [
    ("fclib_local/vectors/q", "must be a vector of numbers"),
    ("fclib_local/W/m", "must hold one integer")])
def test_fclib_dataset_without_a_shape_is_named(tmp_path: Path, dataset: str, word: str) -> None:
    import h5py

    from impactqp.errors import ProblemFileError
    from impactqp.io.fclib import load_fclib

    path = fclib_file(tmp_path / "empty.hdf5")
    with h5py.File(path, "a") as handle:  # a null dataspace: no shape, no data
        dtype = handle[dataset].dtype
        del handle[dataset]
        handle.create_dataset(dataset, data=h5py.Empty(dtype))
    with pytest.raises(ProblemFileError, match=f"/{dataset}: {word}.*shape None"):
        load_fclib(path)
