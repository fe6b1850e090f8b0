"""The README's examples run as written: its Python blocks here, its shell blocks in CI's fresh
clone (.ci/run); here, that those name only files the repository has, and that the sample
files they name load and run."""

import re
import shlex
from pathlib import Path

import pytest

from impactqp.cli.main import main
from impactqp.io.files import load_problem

ROOT = Path(__file__).resolve().parents[1]
README = ROOT / "README.md"
EXAMPLES = ROOT / "examples"
OUTPUTS = ("out/", ".venv/", "docs/_build/")
"""Where the README's commands may name paths the repository has not got: what they write."""
SETUP = ("python3", "pip", "source")


def test_readme_python_blocks_run():
    blocks = re.findall(r"```python\n(.*?)```", README.read_text(), flags=re.S)
    assert blocks, "the README should show Python usage"
    namespace: dict = {}  # read top to bottom: later blocks use names from earlier ones
    for block in blocks:
        exec(compile(block, "README.md", "exec"), namespace)


def bash_blocks() -> list[list[str]]:
    """The command lines of every ```bash block (comment and blank lines dropped), as CI
    reads them."""
    blocks = re.findall(r"^```bash\n(.*?)^```$", README.read_text(encoding="utf-8"),
                        flags=re.S | re.M)
    return [[line for line in block.splitlines() if line.strip()
              and not line.lstrip().startswith("#")] for block in blocks]


def test_readme_opens_with_the_two_commands():
    first = bash_blocks()[0]
    assert len(first) == 2  # CI runs exactly these two in a fresh clone
    assert "impactqp demo" in first[0] and "pytest" in first[1]


def paths_named(line: str) -> list[str]:
    """The words of a command line that look like paths (a slash or a file suffix), options
    and the programs of the virtual environment aside."""
    words = shlex.split(line, comments=True)
    return [w for w in words if not w.startswith(("-", ".venv/", "$"))
            and re.fullmatch(r"[\w.\-/]+", w) and ("/" in w or re.search(r"\.\w+$", w))
            and not re.fullmatch(r"\d[\d.,]*", w)]


def test_later_shell_blocks_name_only_files_the_repository_has():
    later = [line for block in bash_blocks()[1:] for line in block]
    assert later, "the README should show the command line"
    named = [p for line in later for p in paths_named(line)]
    assert any(p.startswith("examples/") for p in named)
    missing = [p for p in named if not p.startswith(OUTPUTS) and not (ROOT / p).exists()]
    assert missing == []
    for line in later:
        assert not line.rstrip().endswith("\\"), line  # CI runs one line at a time
        words = shlex.split(line, comments=True)
        assert words[0].startswith(".venv/bin/") or words[0] in ("mkdir",), line  # no bare
        # `impactqp` or `python`: the venv is not activated in CI's clone
        for flag, value in zip(words, words[1:]):
            if flag in ("--out", "--energy-plot"):
                assert value.startswith("out/"), line  # outputs stay out of the sources


def test_paths_named_finds_inputs_and_outputs():
    line = ".venv/bin/impactqp plot S examples/a.json --out out/S.png --force  # x.toml"
    assert paths_named(line) == ["examples/a.json", "out/S.png"]


PROBLEMS = sorted(p for p in EXAMPLES.glob("*.*") if p.suffix in (".toml", ".json")
                  and "[system]" not in p.read_text() and '"system"' not in p.read_text())
SIMULATIONS = sorted(p for p in EXAMPLES.glob("*.*") if p.suffix in (".toml", ".json")
                     and p not in PROBLEMS)


def test_there_are_sample_files_of_both_kinds():
    assert len(PROBLEMS) >= 2 and len(SIMULATIONS) >= 2
    assert {p.suffix for p in PROBLEMS} == {p.suffix for p in SIMULATIONS} == {".toml", ".json"}


@pytest.mark.parametrize("path", PROBLEMS, ids=lambda p: p.name)
def test_sample_problem_files_load_and_solve(path, capsys):
    content = load_problem(path)
    assert content.law is not None  # each sample shows a law with its coefficients
    assert main(["solve", str(path)]) == 0
    assert "certificate: ok" in capsys.readouterr().out
    if content.u_plus is not None:
        assert main(["verify", str(path)]) == 0


@pytest.mark.parametrize("path", SIMULATIONS, ids=lambda p: p.name)
def test_sample_simulation_files_run(path, tmp_path, capsys):
    out = tmp_path / "run.npz"
    assert main(["simulate", str(path), "--quiet", "--out", str(out)]) == 0
    report = capsys.readouterr().out
    assert "certificates: all ok" in report and out.is_file()
