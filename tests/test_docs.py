"""Every public name has a numpydoc docstring with the sections it needs, the API page of the
documentation lists every public name, the gallery has every example, and the built site
shows what it promises: typeset formulas, section links that resolve, the examples run with
their figures."""

from __future__ import annotations

import argparse
import ast
import builtins
import html
import importlib
import importlib.util
import inspect
import os
import re
import subprocess
import sys
import warnings
from pathlib import Path

import pytest

import impactqp as iq

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "docs" / "_ext"))
from dotted_names import exists  # noqa: E402  (the docs' extensions are not a package)

API = Path(__file__).resolve().parents[1] / "docs" / "api.rst"

def _names(entries: list) -> set[str]:
    """Documented names; ``a, b : float`` documents both a and b."""
    return {part.strip() for entry in entries for part in entry.name.split(",")}


def _arguments(obj) -> list[str]:
    try:
        sig = inspect.signature(obj)
    except (TypeError, ValueError):
        return []
    return [p.name for p in sig.parameters.values()
            if p.kind not in (p.VAR_POSITIONAL, p.VAR_KEYWORD) and p.name != "self"
            and not p.name.startswith("_")]


def problems(where: str, name: str) -> list[str]:
    """What the docstring of ``<where>.<name>`` lacks (``where`` is impactqp or a public
    submodule)."""
    from numpydoc import docscrape  # in the test extra
    obj = getattr(importlib.import_module(where), name)
    if not inspect.getdoc(obj):
        return ["no docstring"]
    if inspect.isclass(obj) and issubclass(obj, BaseException):
        return []  # an exception takes its message; its docstring says when it is raised
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # numpydoc warns on unknown sections
        if inspect.isclass(obj):
            doc = docscrape.ClassDoc(obj, config={"show_class_members": False})
        else:
            doc = docscrape.FunctionDoc(obj)
    found = []
    arguments = _arguments(obj)
    documented = _names(doc["Parameters"]) | (_names(doc["Attributes"])
                                              if inspect.isclass(obj) else set())
    missing = [a for a in arguments if a not in documented]
    if missing:
        found.append(f"arguments without a Parameters (or Attributes) entry: {missing}")
    if not inspect.isclass(obj):
        returns = inspect.signature(obj).return_annotation
        if returns not in (None, "None") and not (doc["Returns"] or doc["Yields"]):
            found.append("no Returns section")
    return found


def public_names() -> set[tuple[str, str]]:
    """(module, name) of every public name, each at one place: the top level's own, then the
    names each public submodule adds."""
    found = {("impactqp", n) for n in iq.__all__}
    for sub in iq.SUBMODULES:
        module = importlib.import_module(f"impactqp.{sub}")
        found |= {(module.__name__, n) for n in module.__all__ if n not in iq.__all__}
    return found


DOCUMENTED = sorted((where, n) for where, n in public_names()
                    if callable(getattr(importlib.import_module(where), n)))


@pytest.mark.parametrize("where,name", DOCUMENTED)
def test_public_docstring_has_its_sections(where: str, name: str) -> None:
    assert problems(where, name) == [], name


def api_page_entries(text: str) -> set[tuple[str, str]]:
    """(current module, name) of every autoclass, autofunction and data entry of the page."""
    found, module = set(), None
    for line in text.splitlines():
        if m := re.match(r"^\.\. (?:py:)?(?:current)?module:: ([\w.]+)$", line):
            module = m[1]
        elif m := re.match(r"^\.\. (?:autoclass|autofunction|data):: (\w+)$", line):
            found.add((module, m[1]))
    return found


def test_api_page_lists_every_public_name() -> None:
    text = API.read_text(encoding="utf-8")
    assert api_page_entries(text) == public_names()
    assert f":value: {iq.results.DEFAULT_TOL!r}" in text


# Cross-references of docstrings: Sphinx checks those on the pages it renders (nitpicky in CI);
# this checks every one in the sources, rendered or not, so a name left behind by a move fails.
ROLE = re.compile(r":(?:py:)?(func|class|mod|data|attr|meth|exc|obj):`([^`<]+?)(?:\s*<([^>]+)>)?`")
PACKAGE = Path(iq.__file__).resolve().parent
PUBLIC = {name for _, name in public_names()}  # a bare name may be any public one


def _resolve(dotted: str) -> bool:
    """Does ``a.b.c`` name an importable module or an attribute chain below one? (The
    docs' own test of a dotted name, builtins left out.)"""
    return exists(dotted, builtin=False)


def _members(cls: type) -> set[str]:
    """Names of a class, including the fields and slots a dataclass declares without values."""
    names = set(dir(cls))
    for klass in cls.__mro__:
        names |= set(getattr(klass, "__annotations__", {}))
    return names


def _stale_references(path: Path) -> list[str]:
    module_name = ".".join(path.relative_to(PACKAGE.parent).with_suffix("").parts)
    module_name = module_name.removesuffix(".__init__")
    try:
        module = importlib.import_module(module_name)
    except iq.errors.OptionalDependencyError:  # an adapter of impactqp.interop without its
        return []  # framework: checked where the extra is installed (CI installs jax)
    bad: list[str] = []

    def check(text: str, classes: list[str], line: int) -> None:
        for role, label, explicit in ROLE.findall(text):
            target = (explicit or label).strip().lstrip("~!").strip("()")
            if target.startswith("."):  # relative to this module's package
                target = importlib.util.resolve_name(target, module.__package__)
            if role == "mod" or target.startswith("impactqp."):
                ok = _resolve(target)
            else:
                head, *rest = target.split(".")
                scopes = [getattr(module, c, None) for c in reversed(classes)]
                ok = any(isinstance(c, type) and head in _members(c) for c in scopes) \
                    or hasattr(module, head) or head in PUBLIC or hasattr(builtins, head)
                if ok and rest and hasattr(module, head):
                    ok = _resolve(f"{module_name}.{target}")
                ok = ok or ("." in target and _resolve(target))  # numpy.ndarray, ...
            if not ok:
                bad.append(f"{path.relative_to(PACKAGE.parent)}:{line}: :{role}:`{target}`")

    def walk(node: ast.AST, classes: list[str]) -> None:
        for child in ast.iter_child_nodes(node):
            inner = classes + [child.name] if isinstance(child, ast.ClassDef) else classes
            if isinstance(child, ast.Constant) and isinstance(child.value, str):
                check(child.value, classes, child.lineno)
            walk(child, inner)

    walk(ast.parse(path.read_text(encoding="utf-8")), [])
    return bad


def test_every_docstring_cross_reference_names_an_existing_object() -> None:
    bad = [ref for path in sorted(PACKAGE.rglob("*.py"))
           if path.name != "__main__.py" for ref in _stale_references(path)]
    assert bad == []


DOCS = API.parent


def _included(page: str) -> set[str]:
    text = (DOCS / page).read_text(encoding="utf-8")
    return set(re.findall(r"^\.\. literalinclude:: \.\./(\S+)$", text, flags=re.M))


EXAMPLES = DOCS.parent / "examples"
NOT_RUN = {"benchmark_run.py"}  # the gallery shows it without running it (a benchmark suite)


def _gallery_conf() -> dict:
    """``sphinx_gallery_conf`` of docs/conf.py, read without importing Sphinx."""
    tree = ast.parse((DOCS / "conf.py").read_text(encoding="utf-8"))
    node = next(n for n in tree.body if isinstance(n, ast.Assign)
                and getattr(n.targets[0], "id", "") == "sphinx_gallery_conf")
    return ast.literal_eval(node.value)


def test_every_example_is_a_gallery_page_and_all_but_the_benchmark_run() -> None:
    """sphinx-gallery makes a page of every script of examples/ whose docstring opens with a
    reST title (its first line, underlined by as many "="), and runs those its
    filename_pattern matches: all but the benchmark run."""
    conf = _gallery_conf()
    assert (conf["examples_dirs"], conf["gallery_dirs"]) == ("../examples", "auto_examples")
    scripts = sorted(EXAMPLES.glob("*.py"))
    assert scripts
    for script in scripts:
        doc = ast.get_docstring(ast.parse(script.read_text(encoding="utf-8")), clean=False)
        assert doc is not None, script.name
        title, underline, blank, *_ = doc.split("\n")
        assert title.strip() and underline == "=" * len(title) and not blank, script.name
        runs = re.search(conf["filename_pattern"], str(script)) is not None
        assert runs == (script.name not in NOT_RUN), script.name
    assert (EXAMPLES / "GALLERY_HEADER.rst").is_file()


def test_file_formats_page_shows_every_sample_file() -> None:
    samples = {f"examples/{p.name}" for p in (DOCS.parent / "examples").glob("*.*")
               if p.suffix in (".toml", ".json")}
    assert _included("files.rst") == samples


def test_every_image_of_the_pages_is_committed() -> None:
    for page in DOCS.glob("*.rst"):
        for image in re.findall(r"^\.\. image:: (\S+)$", page.read_text(encoding="utf-8"),
                                flags=re.M):
            assert (DOCS / image).is_file(), (page.name, image)


def test_command_line_page_shows_the_help_of_every_subcommand() -> None:
    from impactqp.cli.main import build_parser

    def commands(parser: argparse.ArgumentParser, prefix: str) -> set[str]:
        found = {prefix}
        for action in parser._actions:
            if isinstance(action, argparse._SubParsersAction):
                for name, sub in action.choices.items():
                    found |= commands(sub, f"{prefix} {name}".strip())
        return found

    text = (DOCS / "cli.rst").read_text(encoding="utf-8")
    shown = {m.strip() for m in re.findall(r"^\.\. impactqp-help::(.*)$", text, flags=re.M)}
    assert shown == commands(build_parser(), "")


# The built site. CI's docs step builds it (nitpicky, warnings as errors, offline) and runs
# these tests on that build (IMPACTQP_DOCS_HTML); run without it, they build the site into a
# temporary folder the same way (needs the docs extra).
@pytest.fixture(scope="module")
def site(tmp_path_factory) -> Path:
    given = os.environ.get("IMPACTQP_DOCS_HTML")
    if given:
        return Path(given).resolve()
    pytest.importorskip("sphinx_gallery", reason="the docs extra is not installed")
    out = tmp_path_factory.mktemp("html")
    done = subprocess.run([sys.executable, "-m", "sphinx", "-n", "-W", "--keep-going", "-q",
                           "-b", "html", "-d", str(tmp_path_factory.mktemp("doctrees")),
                           str(DOCS), str(out)], capture_output=True, text=True, timeout=900)
    assert done.returncode == 0, done.stderr
    return out


def _page(site: Path, name: str) -> str:
    return (site / name).read_text(encoding="utf-8")


def _ids(html: str) -> set[str]:
    return set(re.findall(r'\bid="([^"]+)"', html))


def test_site_has_the_theme_and_a_copy_button(site: Path) -> None:
    index = _page(site, "index.html")
    assert "pydata-sphinx-theme" in index and "copybutton.js" in index


THEORY_SOURCE = DOCS / "theory.md"
SECTION_SIGN = "\u00a7"  # spelled so, tests/test_citations.py does not read it as a citation


def test_theory_page_typesets_every_displayed_formula(site: Path) -> None:
    """Every $$…$$ block of the note is a math block of the page, which loads MathJax; no
    dollar sign is left over as text."""
    source = THEORY_SOURCE.read_text(encoding="utf-8")
    fences = [line for line in source.splitlines() if line.strip() == "$$"]
    assert len(fences) % 2 == 0 and len(fences) // 2 >= 45
    html = _page(site, "theory.html")
    assert re.search(r'<script[^>]+src="[^"]*mathjax[^"]*"', html, flags=re.I)
    blocks = re.findall(r'<div class="math notranslate nohighlight">\s*\\\[(.*?)\\\]\s*</div>',
                        html, flags=re.S)
    assert len(blocks) == len(fences) // 2
    assert r"\Lambda" in blocks[0] and "$$" not in html


def test_theory_sections_have_stable_anchors_and_every_section_link_resolves(site: Path) -> None:
    """Section N of the note is the element with id sec-N; every link into the theory page,
    from any page, names an id it has; the API page shows no citation as plain text, and links
    every section the public docstrings cite."""
    numbers = {int(n) for n in re.findall(r"^## (\d+)\. ", THEORY_SOURCE.read_text(
        encoding="utf-8"), flags=re.M)}
    theory = _page(site, "theory.html")
    ids = _ids(theory)
    assert {f"sec-{n}" for n in numbers} <= ids
    assert all(re.search(rf'<section id="sec-{n}"', theory) for n in numbers)
    links = 0
    for page in site.rglob("*.html"):
        for anchor in re.findall(r'href="(?:\.\./)*theory\.html#([^"]+)"',
                                 page.read_text(encoding="utf-8")):
            assert anchor in ids, (page.name, anchor)
            links += 1
    api = _page(site, "api.html")
    assert f"docs/theory.md {SECTION_SIGN}" not in re.sub(r"<a [^>]*>.*?</a>", "", api,
                                                          flags=re.S)
    linked = {int(n) for n in re.findall(r'href="theory\.html#sec-(\d+)"', api)}
    cited = {int(n) for where, name in DOCUMENTED
             for n in re.findall(r"docs/theory\.md\s+\u00a7(\d+)", inspect.getdoc(
                 getattr(importlib.import_module(where), name)) or "")}
    assert cited and cited <= linked and links > len(cited)


def test_gallery_runs_the_examples_and_shows_their_figures(site: Path) -> None:
    """A page per script with its thumbnail and downloads; a script that was run shows what
    it printed, and every image it writes (tests/test_examples.py) as a figure, the first as
    its own thumbnail; the benchmark run is shown unrun, with the placeholder."""
    from test_examples import EXPECTED, WRITES

    gallery = site / "auto_examples"
    images = site / "_images"
    placeholder = (images / "sphx_glr_benchmark_run_thumb.png").read_bytes()
    downloads = {p.name for p in (site / "_downloads").rglob("*")}
    for script in sorted(EXAMPLES.glob("*.py")):
        name = script.stem
        page = (gallery / f"{name}.html").read_text(encoding="utf-8")
        thumb = images / f"sphx_glr_{name}_thumb.png"
        assert thumb.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n", name
        assert {f"{name}.py", f"{name}.ipynb"} <= downloads, name
        if script.name in NOT_RUN:
            assert "sphx-glr-script-out" not in page
            continue
        expected = EXPECTED[script.name][0]
        assert html.escape(expected, quote=False) in page, (name, expected)
        drawn = sorted(f for f in WRITES.get(script.name, ())
                       if f.endswith((".png", ".gif")))
        shown = sorted(set(re.findall(rf'src="\.\./_images/(sphx_glr_{name}_\d+\.(?:png|gif))"',
                                      page)))
        assert len(shown) == len(drawn), (name, shown, drawn)
        assert all((images / f).stat().st_size > 1000 for f in shown)
        assert (thumb.read_bytes() != placeholder) == bool(drawn), name


def test_citations_become_links_to_their_sections() -> None:
    """The docstring rewrite of docs/_ext/theory_links.py: every section of a citation group,
    across a line break too, is a reference to its section's label; nothing else changes."""
    sys.path.insert(0, str(DOCS / "_ext"))
    try:
        from theory_links import link_citations
    finally:
        sys.path.remove(str(DOCS / "_ext"))
    s = SECTION_SIGN
    note = "docs/theory.md"
    text = f"exact ({note} {s}14 and {s}15); see {note}\n    {s}3, {s}5 – but not {s}7 alone."
    assert link_citations(text) == (
        f"exact (:ref:`{note} {s}14 <theory-sec-14>` and :ref:`{s}15 <theory-sec-15>`); see "
        f":ref:`{note}\n    {s}3 <theory-sec-3>`, :ref:`{s}5 <theory-sec-5>` – but not {s}7 "
        "alone.")
    assert link_citations(f"no citation here, {s} 3") == f"no citation here, {s} 3"
