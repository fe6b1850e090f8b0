"""The autodiff adapters are never imported unless asked (docs/interop.rst): ``import
impactqp`` (and its derivatives, and ``impactqp.interop`` itself) leaves jax and torch out
of ``sys.modules``, and a missing framework is a named error that says which extra to
install. Run in fresh interpreters, so what this session imported does not count. Also what
the jax and torch tests share: the page's snippets, and a user's law with a derivative hook."""

from __future__ import annotations

import re
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest

import impactqp as iq
from impactqp.results import LinearPiece


def run(code: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          timeout=300)


def test_import_impactqp_imports_no_framework() -> None:
    code = ("import sys\n"
            "import impactqp as iq\n"
            "import impactqp.interop, impactqp.interop.core\n"
            "d = iq.derivative(iq.newtons_cradle(3), iq.Moreau(0.5))\n"
            "assert d.status == 'smooth'\n"
            "print(sorted(m for m in sys.modules if m.split('.')[0] in ('jax', 'jaxlib', "
            "'torch')))\n")
    out = run(code)
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip() == "[]"


@pytest.mark.parametrize("framework", ["jax", "torch"])
def test_a_missing_framework_names_its_extra(framework: str) -> None:
    code = ("import sys\n"
            f"sys.modules[{framework!r}] = None  # as if not installed\n"
            "from impactqp.errors import OptionalDependencyError\n"
            "try:\n"
            f"    import impactqp.interop.{framework}\n"
            "except OptionalDependencyError as exc:\n"
            "    assert isinstance(exc, ImportError)\n"
            "    print(exc)\n")
    out = run(code)
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip() == (f"impactqp.interop.{framework} needs {framework}: "
                                  f"pip install 'impactqp[{framework}]'")


def page_snippet(module: str) -> str:
    """The python block of docs/interop.rst that imports ``module`` (the jax and torch tests
    run their page's snippet)."""
    text = (Path(__file__).resolve().parents[1] / "docs" / "interop.rst").read_text(
        encoding="utf-8")
    blocks = re.findall(r"^\.\. code-block:: python\n\n((?:   .*\n|\n)+)", text, flags=re.M)
    found = [textwrap.dedent(b) for b in blocks if f"from {module} import" in b]
    assert len(found) == 1
    return found[0]


class Stop(iq.ImpactLaw):
    """A user's law: u⁺ = (I − wwᵀ/2)u⁻ on one contact w, with a derivative hook whose
    linear solves report ``residual`` (large: a derivative whose certificate fails)."""

    def __init__(self, residual: float = 0.0) -> None:
        self.residual = residual

    def closed_form(self, problem):
        return problem.u_minus - problem.W[:, 0] * (problem.gamma_minus[0] / 2)

    def derivative(self, problem, answer, *, kink_tol):
        w = problem.W[:, 0]
        piece = LinearPiece({"u_minus": np.eye(problem.n_dof) - np.outer(w, w) / 2},
                            {"u_minus": problem.u_minus})
        piece.residual = self.residual
        return piece


STOP = iq.ImpactProblem(np.eye(2), np.array([[1.0], [-1.0]]), [-1.0, 1.0])
