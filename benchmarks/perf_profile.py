"""Dolan–Moré performance profiles of the friction suite.

For solvers s on problems p with times t_ps (∞ where s failed on p), the ratio to the best
is r_ps = t_ps / min_s t_ps (∞ for every solver on a problem all of them failed), and the
profile ρ_s(τ) = |{p : r_ps ≤ τ}| / |P| is the fraction of problems s solves within a
factor τ of the best solver. ρ_s(1) is the fraction on which s is (one of) the fastest;
ρ_s(τ) for large τ the fraction s solves at all.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402


def ratios(times: Mapping[str, Sequence[float]]) -> dict[str, np.ndarray]:
    """r_ps per solver: each time over the best time on its problem.

    Parameters
    ----------
    times : mapping solver → sequence of seconds
        One entry per problem, the same problems in the same order for every solver;
        ``inf`` (or NaN) where the solver failed.

    Returns
    -------
    dict solver → (n_problems,) ndarray
        ∞ where the solver failed, and for every solver on a problem all failed.
    """
    names = list(times)
    T = np.array([np.asarray(times[s], dtype=float) for s in names], ndmin=2)
    if T.size and T.shape[1] and (T <= 0).any():
        raise ValueError("times must be positive (use inf for a failure)")
    T = np.where(np.isnan(T), np.inf, T)
    best = T.min(axis=0) if T.size else np.zeros(0)
    with np.errstate(invalid="ignore"):
        R = np.where(np.isfinite(best), T / np.where(np.isfinite(best), best, 1.0), np.inf)
    return {s: R[i] for i, s in enumerate(names)}


def profile(times: Mapping[str, Sequence[float]], taus: Sequence[float]) -> dict[str, np.ndarray]:
    """ρ_s(τ) for each τ of ``taus``: the fraction of problems with r_ps ≤ τ (a failure
    never counts, not even at τ = ∞: ρ_s(∞) is the fraction s solves)."""
    taus = np.asarray(taus, dtype=float)
    out = {}
    for s, r in ratios(times).items():
        within = np.isfinite(r)[None, :] & (r[None, :] <= taus[:, None])  # failures never
        out[s] = within.mean(axis=1) if r.size else np.zeros(taus.size)
    return out


def tau_grid(times: Mapping[str, Sequence[float]], points: int = 400) -> np.ndarray:
    """τ from 1 to 1.5× the largest finite ratio (at least 10), log-spaced, every finite
    ratio included so the steps are drawn where they are."""
    finite = np.concatenate([r[np.isfinite(r)] for r in ratios(times).values()] or [[1.0]])
    top = max(10.0, 1.5 * float(finite.max()))
    return np.unique(np.concatenate([np.geomspace(1.0, top, points), finite]))


def plot_profile(times: Mapping[str, Sequence[float]], path: Path, *,
                 title: str = "") -> None:
    """Write the profile of ``times`` (one step line per solver, log τ axis) to ``path``."""
    taus = tau_grid(times)
    rho = profile(times, taus)
    n = len(next(iter(times.values()), []))
    fig, ax = plt.subplots(figsize=(7.5, 4.8), layout="constrained")
    styles = {"iq:": "-", "siconos:": "--"}
    for i, (s, values) in enumerate(rho.items()):
        ls = next((v for k, v in styles.items() if s.startswith(k)), ":")
        ax.step(taus, values, where="post", label=s, ls=ls, lw=2.2 if i == 0 else 1.5,
                color=f"C{i}")
    ax.set(xscale="log", xlim=(1.0, taus[-1]), ylim=(-0.02, 1.02),
           xlabel="τ (time within a factor τ of the fastest)",
           ylabel=f"ρ(τ): fraction of the {n} problems",
           title=title or "Dolan–Moré performance profile")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(loc="lower right", fontsize=9)
    fig.savefig(path, dpi=90)
    plt.close(fig)
