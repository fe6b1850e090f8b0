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
        assert numba.config.CACHE_DIR == "/somewhere/else"
    assert numba.config.CACHE_DIR == "/somewhere/else"
