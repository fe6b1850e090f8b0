"""Siconos' text files of frictional contact problems (.dat, .dat.gz): read by iq.load_fclib
beside FCLib's HDF5 (told apart by content), dense and sparse-block, 2-D and 3-D, written back
bit for bit, solved by ``impactqp fclib``; hostile files are refused by name."""

from __future__ import annotations

import gzip
from pathlib import Path

import numpy as np
import pytest

import impactqp as iq
from impactqp.cli.main import main
from impactqp.errors import InputError, ProblemFileError
from impactqp.io.siconos_text import MAX_TEXT_BYTES, read_siconos_text, write_siconos_text

DATA = Path(__file__).resolve().parent / "data" / "fclib"
PLANAR = DATA / "FC2D_SliderCrankLagrangian00000.dat"
SPATIAL = DATA / "FrictionContact3D_1c.dat"
BENCH = Path(__file__).resolve().parents[1] / "benchmarks" / "data" / "fclib"

# a sparse-block file written out by hand: d = 2, two contacts, blocks (0,0), (0,1), (1,1)
SBM_TEXT = """2
2
1
4
4
3
2
2
2\t4\t
2\t4\t
3
3
0\t2\t3\t
0\t1\t1\t
0
1.0 2.0 3.0 4.0
1
5.0 0.0 0.0 6.0
2
7.0 8.0 9.0 10.0
-1.0 0.5 -2.0 0.25
0.3 0.6
"""


def _by_hand_dense(path: Path) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """W, q, μ of a dense file, read a second way: the numbers in order, W column by column."""
    x = [float(t) for t in path.read_text().split()]
    m, n = int(x[1]), int(x[3])
    W = np.array(x[7:7 + n * n]).reshape((n, n), order="F")
    return W, np.array(x[7 + n * n:7 + n * n + n]), np.array(x[7 + n * n + n:7 + n * n + n + m])


@pytest.mark.parametrize("path, d, m", [(PLANAR, 2, 2), (SPATIAL, 3, 1)])
def test_shipped_dense_files(path: Path, d: int, m: int, tmp_path: Path) -> None:
    W, q, mu = _by_hand_dense(path)
    zipped = tmp_path / (path.name + ".gz")
    zipped.write_bytes(gzip.compress(path.read_bytes()))
    for source in (path, zipped):
        p = iq.load_fclib(source)
        assert p.contact_dim == d and p.n_contacts == m
        np.testing.assert_array_equal(p.dense_W(), W)
        np.testing.assert_array_equal(p.q, q)
        np.testing.assert_array_equal(p.mu, mu)
    if path == SPATIAL:  # the file by eye: 15 -1 -2 / -1 14 1 / -2 1 16, q = (-1, 2, 3)
        assert W.tolist() == [[15, -1, -2], [-1, 14, 1], [-2, 1, 16]] and q.tolist() == [-1, 2, 3]


def test_sparse_block_by_hand(tmp_path: Path) -> None:
    (tmp_path / "p.dat").write_text(SBM_TEXT)
    p = iq.load_fclib(tmp_path / "p.dat")
    assert p.contact_dim == 2 and p.n_contacts == 2
    assert np.array_equal(p.dense_W(), [[1, 3, 5, 0], [2, 4, 0, 6],
                                        [0, 0, 7, 9], [0, 0, 8, 10]])
    assert list(p.q) == [-1.0, 0.5, -2.0, 0.25] and list(p.mu) == [0.3, 0.6]
    for storage in (0, 1):  # both layouts read back bit for bit
        write_siconos_text(p, tmp_path / f"{storage}.dat", storage=storage)
        back = read_siconos_text(tmp_path / f"{storage}.dat")
        assert np.array_equal(back.dense_W(), p.dense_W()) and np.array_equal(back.q, p.q)
        assert np.array_equal(back.mu, p.mu)
    with pytest.raises(InputError, match="storage must be 0"):
        write_siconos_text(p, tmp_path / "2.dat", storage=2)


def test_benchmark_sparse_block_file_agrees_with_dense_rewrite(tmp_path: Path) -> None:
    """BoxesStack1 (52 contacts, sparse-block, gzip) read, written dense, read again."""
    p = iq.load_fclib(BENCH / "BoxesStack1-i100000-32.hdf5.dat.gz")
    assert p.contact_dim == 3 and p.n_contacts == 52 and np.all(p.mu == 0.7)
    back = iq.load_fclib(write_siconos_text(p, tmp_path / "dense.dat", storage=0))
    np.testing.assert_array_equal(back.dense_W(), p.dense_W())


def test_cli_reads_text_and_gzip(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    zipped = tmp_path / "slider.dat.gz"
    zipped.write_bytes(gzip.compress(PLANAR.read_bytes()))
    for source in (PLANAR, zipped):
        assert main(["fclib", str(source)]) == 0
        out = capsys.readouterr().out
        assert "2 contacts, d = 2" in out and "certificate: ok" in out
    bad = tmp_path / "bad.dat"
    bad.write_text(SPATIAL.read_text().replace("0.1", "-0.1"))
    assert main(["fclib", str(bad)]) == 2
    assert "friction coefficients must be ≥ 0" in capsys.readouterr().err


def _tokens_edit(text: str, k: int, value: str | None) -> str:
    """``text`` with its k-th number replaced by ``value`` (removed when None)."""
    tokens = text.split()
    if value is None:
        del tokens[k]
    else:
        tokens[k] = value
    return " ".join(tokens)


@pytest.mark.parametrize("k, value, message", [
    (0, "4", r"d, the dimension of a contact \(number 1 of the file\): 4 is outside \[2, 3\]"),
    (0, "2.5", "'2.5' is not an integer"),
    (1, "3", r"W's rows \(number 4 of the file\): 4 is outside \[6, 6\]"),  # wrong count
    (1, "-1", "the number of contacts .*-1 is outside"),
    (2, "2", r"W's CSparse header \(number 7 of the file\): expected CSparse's banner"),
    (2, "3", r"W's storage \(number 3 of the file\): 3 is outside \[0, 2\]"),
    (5, "4", r"W's length of block-column indices .*3 is outside \[4, 4\]"),
    (9, "3", "block-row ends .*must increase and end at 4"),
    (14, "1", "block-row pointers .*must start at 0"),
    (18, "2", r"W's block-column indices \(number 19 of the file\): 2 is outside \[0, 1\]"),
    (20, "2", r"W's block 0 number \(number 21 of the file\): 2 is outside \[0, 0\]"),
    (21, "nan", r"W's block 0 .*non-finite number\(s\)"),
    (22, "abc", r"W's block 0 \(column by column\) \(number 23 of the file\): 'abc' is not a"),
    (35, "inf", r"q \(number 36 of the file\): holds 1 non-finite"),
    (40, "-0.6", r"μ \(number 41 of the file\): friction coefficients must be ≥ 0, found -0.6"),
    (40, None, "the file ends after 40 numbers"),
])
def test_hostile_sparse_block_files(tmp_path: Path, k: int, value: str | None,
                                    message: str) -> None:
    path = tmp_path / "hostile.dat"
    path.write_text(_tokens_edit(SBM_TEXT, k, value))
    with pytest.raises(ProblemFileError, match=message) as info:
        iq.load_fclib(path)
    assert str(path) in str(info.value)


def test_every_truncation_and_extra_number_is_refused(tmp_path: Path) -> None:
    path = tmp_path / "cut.dat"
    tokens = SPATIAL.read_text().split()
    for keep in range(1, len(tokens)):
        path.write_text(" ".join(tokens[:keep]))
        with pytest.raises(ProblemFileError, match="ends after|outside"):
            iq.load_fclib(path)
    path.write_text(" ".join([*tokens, "2"]))  # not Siconos' old 0/1 flag
    with pytest.raises(ProblemFileError, match=r"1 number\(s\) left over"):
        iq.load_fclib(path)


def test_damaged_bytes_and_gzip(tmp_path: Path) -> None:
    """Garbage after a gzip header, a truncated gzip stream, non-ASCII bytes, an empty file,
    and random byte flips: each is a ProblemFileError or loads finite numbers with μ ≥ 0."""
    path = tmp_path / "p.dat.gz"
    path.write_bytes(b"\x1f\x8b" + bytes(range(200)))
    with pytest.raises(ProblemFileError, match="damaged gzip stream"):
        iq.load_fclib(path)
    packed = gzip.compress(PLANAR.read_bytes())
    path.write_bytes(packed[:len(packed) // 2])
    with pytest.raises(ProblemFileError, match="damaged gzip stream"):
        iq.load_fclib(path)
    path = tmp_path / "p.dat"
    path.write_bytes(b"2\n2\n\xff\xfe")
    with pytest.raises(ProblemFileError, match="byte 4 is not ASCII"):
        iq.load_fclib(path)
    path.write_text(" \n")
    with pytest.raises(ProblemFileError, match="not an HDF5 file"):
        iq.load_fclib(path)
    rng = np.random.default_rng(5)
    source = SBM_TEXT.encode()
    refused = 0
    for _ in range(200):
        data = bytearray(source)
        for _ in range(int(rng.integers(1, 4))):
            data[int(rng.integers(0, len(data)))] = int(rng.choice(list(b"0123456789.-e x")))
        path.write_bytes(bytes(data))
        try:
            p = iq.load_fclib(path)
        except ProblemFileError:
            refused += 1
            continue
        assert np.all(np.isfinite(p.dense_W())) and np.all(np.isfinite(p.q))
        assert np.all(p.mu >= 0)
    assert refused >= 50


def test_too_much_text_is_refused_before_parsing(tmp_path: Path) -> None:
    """A gzip bomb: a few kB that decompress beyond MAX_TEXT_BYTES."""
    path = tmp_path / "bomb.dat.gz"
    with gzip.open(path, "wb") as fh:
        chunk = b"0 " * (1 << 20)
        for _ in range(MAX_TEXT_BYTES // len(chunk) + 1):
            fh.write(chunk)
    assert path.stat().st_size < 1 << 20
    with pytest.raises(ProblemFileError, match="bytes of text once decompressed"):
        iq.load_fclib(path)
