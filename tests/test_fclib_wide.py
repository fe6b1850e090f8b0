"""The widened FCLib/Siconos set of the friction benchmark (benchmarks/data/fclib): every file
loads with the contacts, d and μ its README states, finite, and is byte for byte the original
whose sha256 the README records; a few small ones are certified and checked against a natural
map written here; the readings the set needed (Siconos' compressed-sparse W and its old flag
after μ) and the benchmark's record of a problem nothing certifies."""

from __future__ import annotations

import gzip
import hashlib
import re
from pathlib import Path

import numpy as np
import pytest
import scipy.sparse as sp

import impactqp as iq
from benchmarks import friction, friction_data, friction_report
from impactqp.errors import ProblemFileError
from impactqp.model.friction import certify_friction

README = friction_data.BENCH_FCLIB / "README.md"


def _tables() -> list[dict[str, str]]:
    """The rows of the README's tables, as header → cell."""
    rows, header = [], None
    for line in README.read_text().splitlines():
        if not line.startswith("|"):
            header = None
            continue
        cells = [c.strip() for c in line.strip("|").split("|")]
        if header is None:
            header = cells
        elif not set(cells[0]) <= {"-"}:
            rows.append(dict(zip(header, cells, strict=True)))
    return rows


def _original_bytes(path: Path) -> bytes:
    data = path.read_bytes()
    return gzip.decompress(data) if path.name.endswith(".gz") else data


def _wide_rows() -> dict[str, dict[str, str]]:
    return {r["file here"]: r for r in _tables() if "d" in r}


def test_readme_sha256_matches_every_file() -> None:
    rows = _tables()
    listed = {r["file here"] for r in rows}
    on_disk = {p.name for p in friction_data.BENCH_FCLIB.iterdir() if p.name != "README.md"}
    assert listed == on_disk  # every file documented, no row without its file
    for r in rows:
        digest = next(v for k, v in r.items() if k.startswith("sha256"))
        assert re.fullmatch(r"[0-9a-f]{16}|[0-9a-f]{64}", digest), r
        data = _original_bytes(friction_data.BENCH_FCLIB / r["file here"])
        assert hashlib.sha256(data).hexdigest().startswith(digest), r["file here"]
        if r["file here"].endswith(".gz"):
            assert r["file here"][:-3] == r["original"]


def test_the_widened_set_is_the_files_and_the_suite() -> None:
    wide = _wide_rows()
    assert len(wide) == 31 and len(friction_data.WIDE) == 33
    assert {p.name for p in friction_data.WIDE.values()} >= set(wide)
    assert all(p.is_file() for p in friction_data.ALL.values())
    assert friction.PROBLEMS["fclib-wide"] == list(friction_data.ALL)
    # the suites CI and the reference run keep their problems
    assert friction.PROBLEMS["quick"] == ["LMGC-00046"]
    assert friction.PROBLEMS["friction"] == list(friction_data.FILES) and len(
        friction_data.FILES) == 9
    from benchmarks import families, runner

    assert "fclib-wide" in families.SUITES and "fclib-wide" in runner.TIMING
    assert friction.SUITE_IQ_METHODS["fclib-wide"] == (friction.DEFAULT,)


@pytest.mark.parametrize("name", list(friction_data.WIDE))
def test_every_added_problem_loads_as_documented(name: str) -> None:
    path = friction_data.WIDE[name]
    case = friction_data.load(name)
    p = case.problem
    d, m = p.contact_dim, p.n_contacts
    n = d * m
    values = p.W.data if sp.issparse(p.W) else np.asarray(p.W)  # 7,002 contacts: not dense
    assert p.W.shape == (n, n) and np.asarray(p.q).shape == (n,)
    assert np.isfinite(values).all() and np.isfinite(p.q).all() and np.abs(values).max() > 0
    mu = np.asarray(p.mu)
    assert mu.shape == (m,) and (mu >= 0).all()
    row = _wide_rows().get(path.name)
    if row is None:  # one of tests/data/fclib's two text files, documented there
        assert path.parent == friction_data.TESTS_FCLIB
        return
    assert (m, d) == (int(row["contacts"]), int(row["d"]))
    assert np.allclose(mu, float(row["μ"]), rtol=1e-12)


def _natural_map(p: iq.FrictionContactProblem, r: np.ndarray) -> float:
    """‖r − P_K(r − ũ)‖ / max(1, ‖q‖), with ũ = u + μ‖u_t‖ e_n (De Saxcé) and K the Coulomb
    cone: the projection written here, apart from impactqp's."""
    d = p.contact_dim
    W = p.W.toarray() if sp.issparse(p.W) else np.asarray(p.W)
    u = (W @ r + p.q).reshape(-1, d)
    R = r.reshape(-1, d)
    mu = np.broadcast_to(np.asarray(p.mu, dtype=float), (R.shape[0],))
    F = np.zeros_like(R)
    for k in range(R.shape[0]):
        ut = u[k].copy()
        ut[0] += mu[k] * np.linalg.norm(u[k, 1:])
        z = R[k] - ut
        zn, zt = z[0], np.linalg.norm(z[1:])
        if zt <= mu[k] * zn:
            proj = z
        elif mu[k] * zt <= -zn:
            proj = np.zeros(d)
        else:
            a = (zn + mu[k] * zt) / (1 + mu[k] ** 2)
            proj = np.r_[a, mu[k] * a * z[1:] / zt]
        F[k] = R[k] - proj
    return float(np.linalg.norm(F) / max(1.0, np.linalg.norm(p.q)))


@pytest.mark.parametrize("name", ["Rover1040", "FC2D-00031", "CubeH8"])
def test_small_added_problems_are_certified(name: str) -> None:
    p = friction_data.load(name).problem
    res = iq.solve_friction(p, tol=1e-8)
    assert res.ok and res.error <= 1e-8
    again = certify_friction(p, res.r, tol=1e-8)
    assert again.ok and again.error == pytest.approx(res.error, rel=1e-6, abs=1e-15)
    assert _natural_map(p, np.asarray(res.r)) <= 1e-7  # the map written above agrees


# --- the readings the widened set needed ------------------------------------------------------

def _csparse(W: sp.spmatrix, kind: str) -> str:
    """W as Siconos writes a compressed-sparse matrix (origin, then CSparse's print)."""
    n0, n1 = W.shape
    lines = ["CSparse Version 3.1.9, May 4, 2016.  Copyright (c) Timothy A. Davis, 2006-2016"]
    if kind == "triplet":
        T = sp.coo_matrix(W)
        lines.append(f"triplet: {n0}-by-{n1}, nzmax: {T.nnz} nnz: {T.nnz}")
        lines += [f"    {i} {j} : {x:g}" for i, j, x in zip(T.row, T.col, T.data, strict=True)]
        return "\n".join(["1", *lines])
    C = sp.csc_matrix(W) if kind == "csc" else sp.csr_matrix(W)
    word, prefix = ("col", "") if kind == "csc" else ("row", "csr: ")
    lines.append(f"{prefix}{n0}-by-{n1}, nzmax: {C.nnz} nnz: {C.nnz}, 1-norm: 7")
    for j in range(C.shape[1] if kind == "csc" else C.shape[0]):
        a, b = C.indptr[j], C.indptr[j + 1]
        lines.append(f"    {word} {j} : locations {a} to {b - 1}")
        lines += [f"      {i} : {x:g}" for i, x in zip(C.indices[a:b], C.data[a:b], strict=True)]
    return "\n".join(["2" if kind == "csc" else "3", *lines])


W4 = np.array([[4.0, 1.0, 0.0, -0.5], [1.0, 3.0, 0.0, 0.0], [0.0, 0.0, 2.0, 0.25],
               [-0.5, 0.0, 0.25, 5.0]])


def _file(tmp_path: Path, body: str, tail: str = "") -> Path:
    path = tmp_path / "p.dat"
    path.write_text(f"2\n2\n2\n4\n4\n{body}\n-1 0.2 -2 0.1\n0.5 0.3\n{tail}")
    return path


@pytest.mark.parametrize("kind", ["triplet", "csc", "csr"])
def test_compressed_sparse_w_is_read(tmp_path: Path, kind: str) -> None:
    p = iq.load_fclib(_file(tmp_path, _csparse(sp.csr_matrix(W4), kind)))
    np.testing.assert_array_equal(p.W.toarray(), W4)
    np.testing.assert_array_equal(p.q, [-1, 0.2, -2, 0.1])
    np.testing.assert_array_equal(p.mu, [0.5, 0.3])


def test_compressed_sparse_triplet_duplicates_add(tmp_path: Path) -> None:
    text = _csparse(sp.csr_matrix(W4), "triplet").replace("nnz: 10", "nnz: 11") \
        + "\n    0 0 : 1"
    assert iq.load_fclib(_file(tmp_path, text)).W[0, 0] == 5.0


@pytest.mark.parametrize("edit, message", [
    (lambda t: "4" + t[1:], r"4 \(half triplet\) is not read"),
    (lambda t: "3" + t[1:], "prints compressed columns, the origin says compressed rows"),
    (lambda t: t.replace("4-by-4,", "4-by-5,"), "4-by-5 is not W's 4-by-4"),
    (lambda t: t.replace("col 2 :", "col 3 :"), r"expected 'col 2 : locations a to b'"),
    (lambda t: t.replace("locations 5 to 6", "locations 6 to 6"),
     "locations 6 to 6 do not follow entry 4"),
    (lambda t: t.replace("      3 : 5", "      4 : 5"), r"4 is outside \[0, 3\]"),
    (lambda t: t.replace("      3 : 5", "      3 : nan"), "non-finite"),
    (lambda t: t.replace("      3 : 5", "      3 ; 5"), "expected ':'"),
    (lambda t: t.replace("CSparse Version", "Sparse Version"), "expected CSparse's banner"),
    (lambda t: t.replace("nzmax:", "nz:"), "expected 'nzmax:'"),
])
def test_hostile_compressed_sparse_files(tmp_path: Path, edit, message: str) -> None:
    text = _csparse(sp.csr_matrix(W4), "csc")
    with pytest.raises(ProblemFileError, match=message):
        iq.load_fclib(_file(tmp_path, edit(text)))


def test_granular_flow_file_line_by_line() -> None:
    # the first column as the file prints it: 0 : 856.713, 649 : -454.43; nnz 3822
    p = friction_data.load("Granular2D-667").problem
    assert p.W.nnz == 3822 and p.W[0, 0] == 856.713 and p.W[649, 0] == -454.43
    assert p.W[1, 1] == 2559.98 and p.W[648, 1] == 454.43
    # every entry, read here line by line from the text: "col j : …" then "i : x" lines
    text = gzip.decompress(friction_data.WIDE["Granular2D-667"].read_bytes()).decode()
    W = np.zeros((1334, 1334))
    col = -1
    for line in text.splitlines()[7:]:
        if head := re.match(r"\s+col (\d+) : locations", line):
            col = int(head[1])
        elif entry := re.fullmatch(r"\s+(\d+) : (\S+)", line):
            W[int(entry[1]), col] = float(entry[2])
        elif col >= 0:
            break  # q and μ follow
    assert col == 1333
    np.testing.assert_array_equal(p.W.toarray(), W)


def test_siconos_old_flag_after_mu(tmp_path: Path) -> None:
    body = _csparse(sp.csr_matrix(W4), "csc")
    for flag in ("0", "1"):  # Siconos wrote isComplete there before 2010 and skips it
        np.testing.assert_array_equal(iq.load_fclib(_file(tmp_path, body, flag)).W.toarray(),
                                      W4)
    for extra in ("2", "0 0", "0.5"):
        with pytest.raises(ProblemFileError, match="left over"):
            iq.load_fclib(_file(tmp_path, body, extra))


# --- the benchmark's record of what is not certified ------------------------------------------

def test_a_problem_not_certified_keeps_its_best_answer(monkeypatch: pytest.MonkeyPatch) -> None:
    case = friction_data.load("Rover4144")
    short = "iq:nsgs-short-tight"
    monkeypatch.setitem(friction.IQ_METHODS, short,
                        lambda p: iq.solve_friction(p, backend="nsgs-short", tol=1e-18))
    (row,) = friction.run_impactqp(case, budget=0.0, max_repeats=1, methods=(short,),
                                   limit=60.0)
    assert row["status"] == "failed" and "CertificateError" in row["message"]
    with pytest.raises(iq.CertificateError) as caught:
        iq.solve_friction(case.problem, backend="nsgs-short", tol=1e-18)
    best = caught.value.best
    assert row["error"] == pytest.approx(certify_friction(case.problem, best.r).error,
                                         rel=1e-9)
    assert f"best answer ABH {row['error']:.1e} (recomputed)" in row["message"]
    agg = {"family": "friction:x", "size": 4, "method": friction.DEFAULT,
           "status": "failed", "median_s": 1e-3, "max_error": row["error"],
           "message": row["message"]}
    assert friction_report.carries_best(agg)
    assert not friction_report.carries_best({**agg, "message": "stopped after 30 s",
                                             "max_error": None})


def _frow(problem: str, method: str, status: str, median: float | None, size: int = 10,
          message: str = "", error: float | None = 1e-9) -> dict:
    return {"family": f"friction:{problem}", "size": size, "method": method,
            "group": "peer" if method.startswith("siconos") else "impactqp",
            "status": status, "median_s": median, "max_error": error, "message": message}


def test_widened_report_by_hand() -> None:
    best = "best answer ABH 3.0e-05 (recomputed) after 4 attempts; CertificateError: no"
    rows = [_frow("tiny", "iq:auto", "ok", 15e-6, size=1),  # NSGS 6 µs + 10 µs: within
            _frow("tiny", "siconos:NSGS", "ok", 6e-6, size=1),
            _frow("tiny", "siconos:PROX", "ok", 1e-3, size=1),
            _frow("hard", "iq:auto", "ok", 3e-3),  # no Siconos solver reaches 1e-8
            _frow("hard", "siconos:NSGS", "failed", 1e-2),
            _frow("hard", "siconos:PROX", "failed", 1e-1),
            _frow("slow", "iq:auto", "ok", 5e-3),  # 2.5× NSGS, the fastest
            _frow("slow", "siconos:NSGS", "ok", 2e-3),
            _frow("slow", "siconos:PROX", "failed", 1e-2),
            _frow("pile", "iq:auto", "failed", 2.0, message=best, error=3e-5),
            _frow("pile", "siconos:NSGS", "failed", 5.0),
            _frow("pile", "siconos:PROX", "failed", None, error=None)]
    assert friction_report.peers_unsolved(rows) == ["friction:hard", "friction:pile"]
    targets = friction_report.targets(rows)
    found = {t.split(",")[0]: (m, v) for t, m, v in targets if "within" not in t}
    assert found["friction: a problem not certified ends in CertificateError carrying the "
                 "best answer and its ABH error"] == (
        "1 of 1 (pile: CertificateError, best ABH 3.0e-05, 2 s)", "met")
    assert found["friction: problems no Siconos solver brings to 1e-08"] == ("1 of 2",
                                                                             "MISSED")
    # tiny: 15 µs ≤ 6 + 10 µs; slow 2.5× on 10 contacts; pile: 0.4× (NSGS failed)
    assert found["friction: iq:auto time ≤ siconos:NSGS on each problem of ≥ 5 contacts"] \
        == ("3 of 4 (slower: slow)", "MISSED")
    assert found["friction: Dolan–Moré"] == ("fastest on 1 of 4 (ρ(1) = 0.25)", "MISSED")
    within = [(m, v) for t, m, v in targets if "within 2×" in t]
    assert within == [("on 1 of 4 (ρ(2) = 0.25)", "MISSED")]  # hard is the fastest: 1
    text = "\n".join(friction_report.markdown(rows))
    assert "Not certified: pile (CertificateError, best ABH 3.0e-05" in text
    assert "No Siconos solver reaches 1e-08 on 2: hard, pile; iq:auto certifies 1 of them " \
           "(hard)." in text
    assert "not the fastest on 3 of 4: tiny 2.5×, pile failed, slow 2.5×; not within 2× of " \
           "the fastest on 3: tiny, pile, slow." in text
