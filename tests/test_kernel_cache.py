"""Compiled kernels are cached in the user's cache directory, never beside the installed
sources (where ``pip uninstall`` would leave a folder that hides a later editable install)."""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap

import numba

from impactqp.kernels import jit


def test_the_cache_directory_follows_xdg(monkeypatch, tmp_path):
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path))
    assert jit.cache_dir() == str(tmp_path / "impactqp" / "numba")
    monkeypatch.delenv("XDG_CACHE_HOME")
    assert jit.cache_dir().endswith(os.path.join(".cache", "impactqp", "numba"))


def test_kernels_cache_outside_their_sources_and_leave_numba_as_it_was(tmp_path):
    source = tmp_path / "src"
    source.mkdir()
    (source / "mod.py").write_text(textwrap.dedent("""
        from impactqp.kernels.jit import kernel

        @kernel
        def plus_one(x):
            return x + 1.0
    """))
    script = textwrap.dedent("""
        import numba, mod
        assert mod.plus_one(1.0) == 2.0
        assert numba.config.CACHE_DIR == "", numba.config.CACHE_DIR
    """)
    env = {k: v for k, v in os.environ.items() if not k.startswith("NUMBA_")}
    env.update(XDG_CACHE_HOME=str(tmp_path / "cache"), PYTHONPATH=str(source))
    done = subprocess.run([sys.executable, "-c", script], env=env, capture_output=True,
                          text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    cached = list((tmp_path / "cache" / "impactqp" / "numba").rglob("mod.plus_one*"))
    assert cached, "no cache file in the user's cache directory"
    assert not list(source.rglob("*.nb*")), "a cache file beside the sources"


def test_a_cache_directory_the_user_chose_is_kept(monkeypatch):
    monkeypatch.setattr(numba.config, "CACHE_DIR", "/somewhere/else")
    with jit._cached_in_user_dir():
        assert numba.config.CACHE_DIR == f"/somewhere/else/sources-{jit._STAMP}"
    assert numba.config.CACHE_DIR == "/somewhere/else"


def _kernel_files(folder, monkeypatch):
    for name in ("a.py", "b.py"):
        (folder / name).write_text("x = 1\n")
    (folder / "notes.txt").write_text("not a source")
    monkeypatch.setattr(jit, "_HERE", str(folder))


def test_the_stamp_changes_with_any_kernel_source(tmp_path, monkeypatch):
    # numba keeps a caller's cached code when a kernel it calls changes in another file, so
    # the cache folder must change with every kernel source, not only the caller's own
    _kernel_files(tmp_path, monkeypatch)
    first = jit.sources_stamp()
    assert jit.sources_stamp() == first
    (tmp_path / "notes.txt").write_text("edited, but not a source")
    assert jit.sources_stamp() == first
    (tmp_path / "b.py").write_text("x = 2\n")  # same size: the modification time tells
    os.utime(tmp_path / "b.py", ns=(1, 1))
    second = jit.sources_stamp()
    assert second != first
    (tmp_path / "a.py").write_text("x = 10\n")
    assert jit.sources_stamp() not in (first, second)


def test_an_edited_callee_is_not_loaded_from_its_callers_cache(tmp_path):
    # the hazard itself: a cached caller would keep the old callee's code after the edit
    package = tmp_path / "src" / "kern"
    package.mkdir(parents=True)
    (package / "__init__.py").write_text("")
    (package / "callee.py").write_text(textwrap.dedent("""
        from impactqp.kernels.jit import kernel

        @kernel
        def step(x):
            return x + 1.0
    """))
    (package / "caller.py").write_text(textwrap.dedent("""
        from impactqp.kernels.jit import kernel
        from .callee import step

        @kernel
        def twice(x):
            return 2.0 * step(x)
    """))
    script = textwrap.dedent("""
        import os, sys
        from impactqp.kernels import jit
        jit._HERE = os.path.join(sys.argv[1], "kern")  # these files are the kernel sources
        jit._STAMP = jit.sources_stamp()
        from kern.caller import twice
        print(twice(1.0))
    """)
    env = {k: v for k, v in os.environ.items() if not k.startswith("NUMBA_")}
    env.update(XDG_CACHE_HOME=str(tmp_path / "cache"), PYTHONPATH=str(tmp_path / "src"))

    def run() -> str:
        done = subprocess.run([sys.executable, "-c", script, str(tmp_path / "src")], env=env,
                              capture_output=True, text=True, timeout=120)
        assert done.returncode == 0, done.stderr
        return done.stdout.strip()

    assert run() == "4.0"
    (package / "callee.py").write_text((package / "callee.py").read_text()
                                       .replace("x + 1.0", "x + 2.0"))
    assert run() == "6.0"
    # a folder for impactqp's own kernels and one for each state of these sources
    assert len(list((tmp_path / "cache" / "impactqp" / "numba").glob("sources-*"))) == 3


def test_folders_of_old_sources_are_pruned(tmp_path, monkeypatch):
    for i in range(jit.KEPT_SOURCES + 2):
        old = tmp_path / f"sources-old{i}"
        old.mkdir()
        os.utime(old, (i, i))
    (tmp_path / "unrelated").mkdir()
    assert jit._sources_folder(str(tmp_path), "new") == str(tmp_path / "sources-new")
    left = sorted(p.name for p in tmp_path.iterdir())
    assert left == [*(f"sources-old{i}" for i in range(2, jit.KEPT_SOURCES + 2)), "unrelated"]
