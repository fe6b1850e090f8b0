"""The derivative of the sector law u⁺ = sort(u⁻) (docs/theory.md §6, §19).

Away from ties u⁺ = Pu⁻ for the sorting permutation P, and Λ_k = m Σ_{j≤k}(u⁻_j − u⁺_j) is
linear in u⁻ too. Where entries of u⁻ tie, the map is a kink: the one-sided derivative
along du sorts du inside each tied block, and the limiting Jacobians are the permutations
that reorder the tied blocks.
"""

from __future__ import annotations

import itertools
from typing import Any

import numpy as np

from .local import Kink, LocalMap


class SortMap(LocalMap):
    """The sector law's local map at u⁻ (equal masses ``mass``).

    Parameters
    ----------
    mass : float
        The common ball mass (Λ scales with it).
    u_minus : (n,) ndarray
    kink_tol : float
        Neighbours in sorted order closer than kink_tol·‖u⁻‖ are tied.
    order : (n,) ndarray of int, optional
        The permutation to use (a limiting piece); the stable sort of u⁻ by default.
    """

    def __init__(self, mass: float, u_minus: np.ndarray, *, kink_tol: float,
                 order: np.ndarray | None = None) -> None:
        self.mass, self.u = float(mass), np.asarray(u_minus, dtype=float)
        n = self.u.size
        self.inputs = {"u_minus": (n,)}
        self.order = np.argsort(self.u, kind="stable") if order is None else order
        gaps = np.diff(self.u[self.order])
        scale = float(np.linalg.norm(self.u)) or 1.0
        tied = gaps <= kink_tol * scale
        starts = np.concatenate([[0], np.flatnonzero(~tied) + 1, [n]])
        self.blocks = [np.arange(a, b) for a, b in zip(starts[:-1], starts[1:], strict=True)
                       if b - a > 1]
        free = gaps[~tied]
        self.reach = float(free.min() / np.sqrt(2.0) / scale) if free.size else np.inf
        self.margin = self.reach
        if self.blocks and order is None:
            self.status = "kink"
            self.kink = Kink(np.sort(self.order[np.concatenate(self.blocks)]),
                             float(gaps[tied].max() / scale))
            self.margin = 0.0

    def values(self) -> dict[str, Any]:
        return {"u_minus": self.u}

    def _impulses(self, du: np.ndarray, dup: np.ndarray) -> np.ndarray:
        return self.mass * np.cumsum(du - dup, axis=-1)[..., :-1]

    def jvp(self, tangents: dict[str, np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
        du = np.asarray(tangents.get("u_minus", np.zeros(self.u.size)), dtype=float)
        dup = du[self.order]
        return dup, self._impulses(du, dup)

    def directional(self, tangents: dict[str, np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
        du = np.asarray(tangents.get("u_minus", np.zeros(self.u.size)), dtype=float)
        dup = du[self.order]
        for block in self.blocks:
            dup[block] = np.sort(dup[block])
        return dup, self._impulses(du, dup)

    def vjp(self, u_bar: np.ndarray, lam_bar: np.ndarray) -> dict[str, np.ndarray]:
        # Λ = m C(u⁻ − Pu⁻) with (Cx)_k = Σ_{j≤k} x_j, k < n − 1
        c = np.zeros_like(u_bar)
        if lam_bar.shape[1]:
            c[:, :-1] = self.mass * np.cumsum(lam_bar[:, ::-1], axis=1)[:, ::-1]
        out = c.copy()
        out[:, self.order] += u_bar - c
        return {"u_minus": out}

    def pieces(self, cap: int) -> list[LocalMap]:
        choices = [itertools.permutations(self.order[b]) for b in self.blocks]
        out: list[LocalMap] = []
        for combo in itertools.product(*choices):
            order = self.order.copy()
            for block, perm in zip(self.blocks, combo, strict=True):
                order[block] = perm
            out.append(SortMap(self.mass, self.u, kink_tol=0.0, order=order))
            if len(out) >= cap:
                break
        return out

    def evaluate(self, data: dict[str, Any]) -> tuple[np.ndarray, np.ndarray]:
        u = np.asarray(data["u_minus"], dtype=float)
        up = np.sort(u)
        return up, self._impulses(u, up)
