"""sphinx-gallery hooks that show the figures the examples write to files.

sphinx-gallery runs a script's code in a module of its own without ``__file__`` and with an
empty ``__doc__``; :func:`run_as_script` gives it both, as ``python examples/NAME.py`` would
(the scripts find the repository's test data beside them and describe their options with
their docstring), and no arguments.

The scripts of ``examples/`` draw through impactqp's figure functions, which save a file and
close the figure (nothing is left for sphinx-gallery's matplotlib scraper); run without
arguments, as sphinx-gallery runs them, each writes into a new temporary folder
(``tempfile.mkdtemp``). :func:`private_tempdir` points :mod:`tempfile` at a fresh folder of
its own around each example, :func:`scrape_written_files` hands the images that appeared
there after each code block to the gallery (figures, thumbnails), and the folder is removed
when the example is done: a build writes nothing into the clone but its own output.

All three are named in ``sphinx_gallery_conf`` of docs/conf.py by their import path, so the
configuration stays picklable (Sphinx caches it).
"""

from __future__ import annotations

import ast
import shutil
import tempfile
from pathlib import Path

IMAGES = (".png", ".gif", ".jpg", ".jpeg", ".svg")
_run: dict[str, object] = {}  # the current example's folder and the images already shown


def run_as_script(gallery_conf: dict, script_vars: dict) -> list[str]:
    """``reset_argv`` hook: the script's ``__file__`` and ``__doc__`` as Python sets them
    for ``python examples/NAME.py``; the arguments, none."""
    source = Path(script_vars["src_file"])
    script_vars["example_globals"].update(
        __file__=str(source),
        __doc__=ast.get_docstring(ast.parse(source.read_text(encoding="utf-8")), clean=False))
    return []


def private_tempdir(gallery_conf: dict, fname: str | None, when: str) -> None:
    """``reset_modules`` hook: before an example, a fresh folder becomes :mod:`tempfile`'s
    default; after it, the folder is removed and the default restored."""
    root = _run.pop("root", None)
    if root is not None:
        tempfile.tempdir = _run.pop("previous", None)
        shutil.rmtree(root, ignore_errors=True)
    _run.pop("shown", None)
    if when == "before" and fname is not None:
        _run["previous"] = tempfile.tempdir
        _run["root"] = Path(tempfile.mkdtemp(prefix="impactqp-gallery-"))
        _run["shown"] = set()
        tempfile.tempdir = str(_run["root"])


def scrape_written_files(block, block_vars: dict, gallery_conf: dict) -> str:
    """Image scraper: the images the example wrote under its folder since the last block,
    oldest first, copied to the gallery's image paths; their reST."""
    from sphinx_gallery.scrapers import figure_rst

    root, shown = _run.get("root"), _run.get("shown")
    if root is None or shown is None:
        return ""
    new = sorted((p for p in Path(root).rglob("*")
                  if p.suffix.lower() in IMAGES and p not in shown),
                 key=lambda p: (p.stat().st_mtime_ns, p.name))
    paths = []
    for image, target in zip(new, block_vars["image_path_iterator"]):
        target = Path(target).with_suffix(image.suffix.lower())
        shutil.copyfile(image, target)
        shown.add(image)
        paths.append(str(target))
    return figure_rst(paths, gallery_conf["src_dir"])
