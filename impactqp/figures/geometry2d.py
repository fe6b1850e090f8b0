"""The data of the figures of S, without drawing: its section through u⁻ by a plane
(docs/theory.md §2–§5); the cones of the sector law are in
:mod:`impactqp.figures.cone_section`.

S is drawn by its section through u⁻ with a plane, for any number of contacts. With two
independent contacts, ``u⁻ + N`` and hence S lie in the 2-D affine plane
``u⁻ + range(M⁻¹W)`` (for the 3-ball cradle: the momentum-conserving velocities
u₁ + u₂ + u₃ = v), the default plane. Coordinates in a plane are taken in an M-orthonormal
basis, so Euclidean lengths and angles of the picture are the kinetic ones of docs/theory.md §1: the
energy ball becomes a true circle and the angle α of docs/theory.md §4 is the angle seen on
paper. Everything here is arrays; :mod:`impactqp.figures.plots` draws them.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from ..base.arrays import as_dense, as_vector
from ..errors import InputError
from ..laws.functions import moreau
from ..model.problem import ImpactProblem
from .plane_cone import PlaneCone, kinetic_frame, reaction_trace

MOREAU_EPS = (0.0, 0.5, 1.0)
"""Restitutions marked on Moreau's half-line."""


@dataclass(frozen=True)
class Candidate:
    """A post-impact velocity drawn in the plane, with its angle α to Moreau's half-line
    (docs/theory.md §4).

    ``arc`` is a circular arc around u⁻ from Moreau's direction to the candidate's; the
    k-th candidate's arc has radius (0.3 + 0.08 k) times the energy circle's, so that the
    arcs of two candidates never lie on top of each other. ``off_plane`` is the kinetic
    distance of the candidate from the plane, relative to ‖u⁻‖ (0 when it lies in it;
    ``point`` is then its projection); α is always the angle in velocity space.
    """

    label: str
    point: np.ndarray
    alpha_deg: float
    arc: np.ndarray
    off_plane: float = 0.0


@dataclass(frozen=True)
class PlanePicture:
    """S and its ingredients in plane coordinates (docs/theory.md §2–§4).

    A velocity u of the plane is ``origin + basis @ x``; ``origin`` is the point of the plane
    nearest to 0 in the kinetic metric, so the energy sphere cuts the plane in the circle
    ``|x| = radius``. Polygons are (k, 2) arrays clipped to the square ``|x|∞ ≤ half_width``;
    ``admissible`` is the section of S (two points when it is a segment). ``halfplanes``
    are the exact constraints ``normal · x ≥ offset`` of the section besides the energy
    disc |x| ≤ radius (those of T_C and of the trace of u⁻ + N); ``moreau_line`` and
    ``moreau_marks`` are empty when Moreau's half-line leaves the plane.
    """

    origin: np.ndarray
    basis: np.ndarray
    radius: float
    half_width: float
    u_minus: np.ndarray
    z: np.ndarray
    circle: np.ndarray
    reaction_cone: np.ndarray
    tangent_cone: np.ndarray
    admissible: np.ndarray
    moreau_line: np.ndarray
    moreau_marks: dict[float, np.ndarray]
    candidates: list[Candidate] = field(default_factory=list)
    halfplanes: list[tuple[np.ndarray, float]] = field(default_factory=list)
    reaction_trace: PlaneCone | None = None

    def lift(self, x: ArrayLike) -> np.ndarray:
        """Velocities of plane points: (2,) → (n,), (k, 2) → (k, n)."""
        return self.origin + np.asarray(x, dtype=float) @ self.basis.T


def clip(polygon: np.ndarray, normal: np.ndarray, offset: float) -> np.ndarray:
    """Sutherland–Hodgman: the part of a convex polygon where ``normal · x ≥ offset``."""
    out: list[np.ndarray] = []
    k = len(polygon)
    for i in range(k):
        a, b = polygon[i], polygon[(i + 1) % k]
        sa, sb = normal @ a - offset, normal @ b - offset
        if sa >= 0:
            out.append(a)
        if (sa >= 0) != (sb >= 0):
            out.append(a + (sa / (sa - sb)) * (b - a))
    return np.array(out).reshape(-1, 2)


def _arc(center: np.ndarray, radius: float, start: np.ndarray, stop: np.ndarray,
         k: int = 40) -> np.ndarray:
    """Points of the shorter circular arc around ``center`` from direction start to stop."""
    a0 = np.arctan2(start[1], start[0])
    turn = np.arctan2(start[0] * stop[1] - start[1] * stop[0], start @ stop)
    t = a0 + np.linspace(0.0, turn, k)
    return center + radius * np.column_stack([np.cos(t), np.sin(t)])


def _ray_exit(p: np.ndarray, d: np.ndarray, h: float) -> np.ndarray:
    """Where the half-line p + t d (t ≥ 0) leaves the square |x|∞ ≤ h (p inside)."""
    with np.errstate(divide="ignore"):
        t = np.where(d != 0, (np.sign(d) * h - p) / d, np.inf)
    return p + np.min(t) * d


def default_plane(problem: ImpactProblem, z: np.ndarray,
                  candidates: list[np.ndarray]) -> list[np.ndarray]:
    """Directions spanning the default plane of the section of S through u⁻: Moreau's
    direction z − u⁻, then the direction to the first candidate off Moreau's half-line,
    then the contact directions M⁻¹wᵢ by decreasing Moreau impulse (kinetic size
    Λᵢ‖M⁻¹wᵢ‖), then the coordinate axes — the first two independent ones are used.

    With two independent contacts every one of these lies in u⁻ + range(M⁻¹W), which is the
    plane drawn. With more, the two contact directions of the largest impulses through u⁻
    can miss S altogether (a 4-ball cradle: S needs all three impulses), which the plane
    through u⁻, Moreau's half-line and a candidate never does.
    """
    st = problem.structure
    u_m = problem.u_minus
    V = st.solve_mass(as_dense(st.W))
    lam = moreau(problem, eps=0.0).impulses
    sizes = lam * np.sqrt(np.einsum("ij,ij->j", V, as_dense(st.M) @ V))
    order = np.argsort(-sizes, kind="stable")
    return [z - u_m, *(c - u_m for c in candidates), *(V[:, i] for i in order),
            *np.eye(st.n)]


def _segment(x_minus: np.ndarray, ray: np.ndarray, halfplanes: list,
             radius: float) -> np.ndarray:
    """The points x⁻ + t·ray (t ≥ 0) in the disc |x| ≤ radius and every half-plane: a
    (2, 2) segment, or (0, 2) when there is none."""
    lo, hi = 0.0, np.inf
    for normal, offset in halfplanes:
        a, b = normal @ ray, offset - normal @ x_minus  # a t ≥ b
        size = float(np.linalg.norm(normal))
        if abs(a) <= 1e-12 * size:  # parallel to the line: all of it or none of it
            if b > 1e-12 * size * radius:
                return np.zeros((0, 2))
        elif a > 0:
            lo = max(lo, b / a)
        else:
            hi = min(hi, b / a)
    # the disc: |x⁻ + t ray|² ≤ r²
    p = x_minus @ ray
    disc = p * p - (x_minus @ x_minus - radius**2)
    if disc < 0:
        return np.zeros((0, 2))
    lo, hi = max(lo, -p - np.sqrt(disc)), min(hi, -p + np.sqrt(disc))
    if lo > hi:
        return np.zeros((0, 2))
    return np.array([x_minus + lo * ray, x_minus + hi * ray])


def plane_picture(problem: ImpactProblem, candidates: Mapping[str, ArrayLike] | None = None,
                  *, plane: Any = None, resolution: int = 360,
                  margin: float = 1.3) -> PlanePicture:
    """Compute the section of S through u⁻ by a plane (docs/theory.md §2, §5), for any
    number of contacts.

    In the plane's M-orthonormal coordinates the section is an exact convex set: the
    half-planes of T_C (one per contact), the trace of u⁻ + N (a wedge, a half-plane, the
    plane or a ray, :func:`~impactqp.figures.plane_cone.reaction_trace`) and the energy
    disc, drawn as a polygon with ``resolution`` vertices on its circle. With two
    independent contacts and the default plane, S lies whole in the plane u⁻ + range(M⁻¹W)
    and the section is S itself.

    Parameters
    ----------
    problem : ImpactProblem
        Frictionless, with a contact that approaches (u⁻ ∉ T_C), otherwise S = {u⁻}.
    candidates : mapping of label → (n,) array_like, optional
        Post-impact velocities to mark (a law's u⁺). Each must be kinetically compatible
        (u − u⁻ ∈ range(M⁻¹W)); one off the plane is marked at its M-orthogonal
        projection and says how far off it lies.
    plane : pair of (n,) array_like, optional
        Two velocity directions d₁, d₂: the section is by u⁻ + span(d₁, d₂). Default
        (:func:`default_plane`): the plane through u⁻ of Moreau's half-line and the first
        candidate off it.
    resolution : int
        Vertices of the energy circle.
    margin : float
        Half-width of the view as a multiple of the circle's radius.

    Raises
    ------
    InputError
        When the problem, the plane or a candidate cannot be drawn, saying why; when the
        plane does not meet S.
    """
    st = problem.structure
    if problem.contact_dim > 1:  # its S has friction cones, not the half-spaces drawn here
        raise InputError(f"the picture of S is of frictionless contacts; this problem's are "
                         f"frictional (contact_dim = {problem.contact_dim}): draw "
                         "problem.normal_problem() for the frictionless S")
    if st.m == 0:
        raise InputError("nothing to draw: the problem has no contact, so S = {u⁻}")
    W, M = as_dense(st.W), as_dense(st.M)
    u_m = problem.u_minus
    z, z_perp = problem.moreau_split
    if problem.norm(z_perp) <= 1e-12 * problem.velocity_scale:
        raise InputError("nothing to draw: u⁻ already lies in T_C (no contact approaches), so "
                         "S = {u⁻}")
    marks = {}
    for label, u in (candidates or {}).items():
        u = as_vector(f"candidate {label!r}", u, st.n)
        fit = np.linalg.lstsq(W, M @ (u - u_m), rcond=None)[0]
        off = problem.norm(u - u_m - st.solve_mass(W @ fit)) / problem.velocity_scale
        if off > 1e-9:
            raise InputError(f"candidate {label!r} is not in the plane u⁻ + range(M⁻¹W) "
                             f"(relative distance {off:.2g}): it is not kinetically compatible")
        marks[label] = u
    if plane is None:
        directions = default_plane(problem, z, list(marks.values()))
    else:
        pair = np.asarray(plane, dtype=float)
        if pair.shape != (2, st.n) or not np.isfinite(pair).all():
            raise InputError(f"plane must be two velocity directions of length n = {st.n}, "
                             f"as a (2, {st.n}) array, got shape {pair.shape}")
        directions = list(pair)
    basis = kinetic_frame(M, directions)
    if basis is None:
        raise InputError("plane: the two directions are parallel (or zero) in the kinetic "
                         "metric; give two independent directions")
    down = -(basis.T @ M @ (z - u_m))
    if np.linalg.norm(down) > 1e-12 * problem.norm(z - u_m):
        down /= np.linalg.norm(down)
        basis = basis @ np.column_stack([[down[1], -down[0]], down])  # Moreau points down
    origin = u_m - basis @ (basis.T @ M @ u_m)

    def coords(u: np.ndarray) -> np.ndarray:
        return basis.T @ M @ (u - origin)

    def off_plane(u: np.ndarray) -> float:
        return problem.norm(u - origin - basis @ coords(u)) / problem.velocity_scale

    x_minus = coords(u_m)
    radius = float(np.linalg.norm(x_minus))
    h = margin * radius
    box = np.array([[-h, -h], [h, -h], [h, h], [-h, h]])
    # T_C ∩ plane: Wᵀ(origin + Bx) ≥ 0, one half-plane per contact whose direction the plane
    # sees; a contact whose M⁻¹wᵢ is M-orthogonal to the plane has a constant γᵢ there
    # (≥ 0 everywhere or nowhere, decided up to round-off)
    tangent = []
    for normal, offset, s in zip(W.T @ basis, -(W.T @ origin), st.contact_scale):
        if np.linalg.norm(normal) > 1e-12 * s:
            tangent.append((normal, offset))
        elif offset > 1e-12 * s * radius:
            raise InputError("S does not meet this plane: a contact approaches everywhere "
                             "on it; give a plane that contains Moreau's direction z − u⁻")
    trace = reaction_trace(problem, basis)
    t = np.linspace(0.0, 2 * np.pi, resolution, endpoint=False)
    circle = radius * np.column_stack([np.cos(t), np.sin(t)])
    tangent_poly = box
    for normal, offset in tangent:
        tangent_poly = clip(tangent_poly, normal, offset)
    if trace.kind in ("ray", "point"):
        ray = trace.first if trace.kind == "ray" else np.zeros(2)
        reaction_poly = np.array([x_minus, _ray_exit(x_minus, ray, h)]) if trace.kind == "ray" \
            else x_minus[None, :]
        admissible = _segment(x_minus, ray, tangent, radius) if trace.kind == "ray" \
            else np.zeros((0, 2))
    else:
        reaction = [(n, n @ x_minus) for n, _ in trace.halfplanes()]
        reaction_poly, admissible = box, circle
        for normal, offset in reaction:
            reaction_poly = clip(reaction_poly, normal, offset)
        for normal, offset in reaction + tangent:
            admissible = clip(admissible, normal, offset)
    if len(admissible) == 0:
        raise InputError("S does not meet this plane (its section through u⁻ is empty); "
                         "give a plane that contains Moreau's direction z − u⁻")
    moreau_dir = coords(z) - x_minus
    on_plane = off_plane(z) <= 1e-9
    drawn = []
    for i, (label, u) in enumerate(marks.items()):
        x = coords(u)
        d, du, dz = x - x_minus, u - u_m, z - u_m
        if problem.norm(du) == 0:
            alpha, arc = float("nan"), np.zeros((0, 2))
        else:  # the angle in velocity space, which the plane shows when u lies in it
            cos = float(du @ M @ dz) / (problem.norm(du) * problem.norm(dz))
            alpha = float(np.degrees(np.arccos(np.clip(cos, -1.0, 1.0))))
            # each candidate's arc on a circle of its own, so that equal angles stay apart
            arc = _arc(x_minus, (0.3 + 0.08 * i) * radius, moreau_dir, d) \
                if on_plane and np.linalg.norm(d) > 0 else np.zeros((0, 2))
        drawn.append(Candidate(label, x, alpha, arc, off_plane(u)))
    return PlanePicture(origin=origin, basis=basis, radius=radius, half_width=h,
                        u_minus=x_minus, z=coords(z), circle=circle,
                        reaction_cone=reaction_poly, tangent_cone=tangent_poly,
                        admissible=admissible,
                        moreau_line=np.array([x_minus, _ray_exit(x_minus, moreau_dir, h)])
                        if on_plane else np.zeros((0, 2)),
                        moreau_marks={eps: coords(u_m + (1.0 + eps) * (z - u_m))
                                      for eps in MOREAU_EPS} if on_plane else {},
                        candidates=drawn, halfplanes=[(n, n @ x_minus) for n, _ in
                                                      trace.halfplanes()] + tangent
                        if trace.kind not in ("ray", "point") else tangent,
                        reaction_trace=trace)
