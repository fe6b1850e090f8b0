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
