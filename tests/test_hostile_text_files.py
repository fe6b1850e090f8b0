"""Text problem files as editors and users make them: a UTF-8 byte-order mark (what Windows
editors write first) is read as the text it marks, in problem and simulation files alike; an
empty FCLib/Siconos file says it is empty; save_problem refuses coefficients of the wrong kind
by name, never with numpy's own TypeError."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import impactqp as iq
from impactqp.cli.main import main
from impactqp.errors import InputError, ProblemFileError
from impactqp.io.simulation_files import read_simulation

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
BOM = "\ufeff"


@pytest.mark.parametrize("name", ["cradle.toml", "unequal_chain.json"])
def test_a_problem_file_with_a_byte_order_mark_is_read(name, tmp_path, capsys):
    plain = iq.load_problem(EXAMPLES / name)
    marked = tmp_path / name
    marked.write_text(BOM + (EXAMPLES / name).read_text(encoding="utf-8"), encoding="utf-8")
    read = iq.load_problem(marked)
    np.testing.assert_array_equal(read.problem.u_minus, plain.problem.u_minus)
    assert read.law == plain.law
    assert main(["solve", str(marked)]) == 0
    capsys.readouterr()


def test_a_simulation_file_with_a_byte_order_mark_is_read(tmp_path):
    source = EXAMPLES / "bouncing_ball.toml"
    marked = tmp_path / source.name
    marked.write_text(BOM + source.read_text(encoding="utf-8"), encoding="utf-8")
    system, law, options = read_simulation(marked)
    plain = read_simulation(source)
    np.testing.assert_array_equal(system.q0, plain[0].q0)
    assert options == plain[2] and type(law) is type(plain[1])


def test_a_byte_order_mark_elsewhere_is_still_refused(tmp_path):
    bad = tmp_path / "bad.json"
    bad.write_text('{"masses": [1, 1], "u_minus": [1, 0]}' + BOM, encoding="utf-8")
    with pytest.raises(ProblemFileError, match="bad.json"):
        iq.load_problem(bad)


@pytest.mark.parametrize("name", ["empty.hdf5", "empty.dat"])
def test_an_empty_problem_file_says_so(name, tmp_path):
    (tmp_path / name).write_bytes(b"")
    with pytest.raises(ProblemFileError, match=rf"{name}: empty"):
        iq.load_fclib(tmp_path / name)


@pytest.mark.parametrize("coefficients", [{"e": [1.0, 0.5]}, "half", [[1.0], [0.5, 0.2]]])
def test_save_problem_refuses_coefficients_of_the_wrong_kind(coefficients, tmp_path):
    p = iq.load_problem(EXAMPLES / "unequal_chain.json").problem
    with pytest.raises(InputError, match="coefficient 'e'"):
        iq.save_problem(p, tmp_path / "p.toml", law="newton", coefficients=coefficients)
    assert not (tmp_path / "p.toml").exists()


@pytest.mark.parametrize("token", ["1_0", "0.3_0", "-1_0"])
def test_an_underscore_in_a_siconos_number_is_refused(token, tmp_path):
    """Python reads '1_0' as 10 (digit grouping); Siconos' C reader stops at the '_'. A file
    where one appears is damaged, not a W entry of ten."""
    path = tmp_path / "grouped.dat"
    path.write_text(f"3\n1\n0\n3\n3\n3 3\n{token} 0 0\n0 1 0\n0 0 1\n-1 0 0\n0.3\n")
    with pytest.raises(ProblemFileError, match=rf"grouped\.dat.*number 8 of the file.*{token}"):
        iq.load_fclib(path)
