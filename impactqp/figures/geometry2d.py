"""The data of the figures, without drawing: S in its plane (docs/theory.md §2–§5) and the
sector cones (docs/theory.md §6).

With two independent contacts, ``u⁻ + N`` and hence S lie in the 2-D affine plane
``u⁻ + range(M⁻¹W)`` (for the 3-ball cradle: the momentum-conserving velocities
u₁ + u₂ + u₃ = v). Coordinates in that plane are taken in an M-orthonormal basis, so
Euclidean lengths and angles of the picture are the kinetic ones of docs/theory.md §1: the
energy ball becomes a true circle and the angle α of docs/theory.md §4 is the angle seen on
paper. The sector law's plane of contact velocities γ is drawn likewise in coordinates
orthonormal for its kinetic metric G⁻¹ (:func:`sector_frame`), where its cones are 60°.
Everything here is arrays; :mod:`impactqp.figures.plots` draws them.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike

from ..base.arrays import as_dense, as_vector
from ..errors import InputError
from ..model.problem import ImpactProblem
from ..tables.sector_table import sector_gamma_map, sector_law_table

MOREAU_EPS = (0.0, 0.5, 1.0)
"""Restitutions marked on Moreau's half-line."""


@dataclass(frozen=True)
class Candidate:
    """A post-impact velocity drawn in the plane, with its angle α to Moreau's half-line
    (docs/theory.md §4).

    ``arc`` is a circular arc around u⁻ from Moreau's direction to the candidate's; the
    k-th candidate's arc has radius (0.3 + 0.08 k) times the energy circle's, so that the
    arcs of two candidates never lie on top of each other.
    """

    label: str
    point: np.ndarray
    alpha_deg: float
    arc: np.ndarray


@dataclass(frozen=True)
class PlanePicture:
    """S and its ingredients in plane coordinates (docs/theory.md §2–§4).

    A velocity u of the plane is ``origin + basis @ x``; ``origin`` is the point of the plane
    nearest to 0 in the kinetic metric, so the energy sphere cuts the plane in the circle
    ``|x| = radius``. Polygons are (k, 2) arrays clipped to the square ``|x|∞ ≤ half_width``.
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


def plane_picture(problem: ImpactProblem, candidates: Mapping[str, ArrayLike] | None = None,
                  *, resolution: int = 360, margin: float = 1.3) -> PlanePicture:
    """Compute the picture of S (docs/theory.md §5 generalised) for a problem with two independent
    contacts.

    Parameters
    ----------
    problem : ImpactProblem
        Must have m = 2 contacts with independent directions and a contact that approaches
        (u⁻ ∉ T_C), otherwise S is not a 2-D region.
    candidates : mapping of label → (n,) array_like, optional
        Post-impact velocities to mark (e.g. the sector law's); each must lie in the plane.
    resolution : int
        Vertices of the energy circle.
    margin : float
        Half-width of the view as a multiple of the circle's radius.

    Raises
    ------
    InputError
        When the problem or a candidate cannot be drawn in the plane, saying why.
    """
    st = problem.structure
    if problem.contact_dim > 1:  # its S has friction cones, not the half-spaces drawn here
        raise InputError(f"the picture of S is of frictionless contacts; this problem's are "
                         f"frictional (contact_dim = {problem.contact_dim}): draw "
                         "problem.normal_problem() for the frictionless S")
    W = as_dense(st.W)
    if st.m != 2 or np.linalg.matrix_rank(W) != 2:
        raise InputError(f"the picture of S needs exactly 2 independent contacts (S then lies in "
                         f"the plane u⁻ + range(M⁻¹W)); this problem has n_dof={st.n}, "
                         f"n_contacts={st.m}, rank(W)={np.linalg.matrix_rank(W)}")
    M = as_dense(st.M)
    u_m = problem.u_minus
    z, z_perp = problem.moreau_split
    if problem.norm(z_perp) <= 1e-12 * problem.velocity_scale:
        raise InputError("nothing to draw: u⁻ already lies in T_C (no contact approaches), so "
                         "S = {u⁻}")
    V = st.solve_mass(W)
    basis = V @ np.linalg.inv(np.linalg.cholesky(W.T @ V)).T  # M-orthonormal: basisᵀ M basis = I
    down = -(basis.T @ M @ (z - u_m))
    down /= np.linalg.norm(down)
    basis = basis @ np.column_stack([[down[1], -down[0]], down])  # Moreau's half-line points down
    origin = u_m - basis @ (basis.T @ M @ u_m)

    def coords(u: np.ndarray) -> np.ndarray:
        return basis.T @ M @ (u - origin)

    x_minus, x_z = coords(u_m), coords(z)
    radius = float(np.linalg.norm(x_minus))
    h = margin * radius
    box = np.array([[-h, -h], [h, -h], [h, h], [-h, h]])
    gens = W.T @ basis  # row i: the plane coordinates of M⁻¹Wᵢ (also the normal of T_C's face i)
    cone_rows = np.linalg.inv(gens.T)  # u⁻ + N = {x : cone_rows (x − x⁻) ≥ 0}
    t_offsets = -(W.T @ origin)  # T_C ∩ plane = {x : gens x ≥ −Wᵀ origin}
    halfplanes = [(r, r @ x_minus) for r in cone_rows] + list(zip(gens, t_offsets))
    t = np.linspace(0.0, 2 * np.pi, resolution, endpoint=False)
    circle = radius * np.column_stack([np.cos(t), np.sin(t)])
    polygons = {"reaction": box, "tangent": box, "S": circle}
    for i, (normal, offset) in enumerate(halfplanes):
        key = "reaction" if i < 2 else "tangent"
        polygons[key] = clip(polygons[key], normal, offset)
        polygons["S"] = clip(polygons["S"], normal, offset)
    marks = {eps: coords(u_m + (1.0 + eps) * (z - u_m)) for eps in MOREAU_EPS}
    moreau_dir = x_z - x_minus
    drawn = []
    for i, (label, u) in enumerate((candidates or {}).items()):
        u = as_vector(f"candidate {label!r}", u, st.n)
        x = coords(u)
        off = problem.norm(u - origin - basis @ x) / problem.velocity_scale
        if off > 1e-9:
            raise InputError(f"candidate {label!r} is not in the plane u⁻ + range(M⁻¹W) "
                             f"(relative distance {off:.2g}): it is not kinetically compatible")
        d = x - x_minus
        if np.linalg.norm(d) == 0:
            alpha, arc = float("nan"), np.zeros((0, 2))
        else:
            cos = d @ moreau_dir / (np.linalg.norm(d) * np.linalg.norm(moreau_dir))
            alpha = float(np.degrees(np.arccos(np.clip(cos, -1.0, 1.0))))
            # each candidate's arc on a circle of its own, so that equal angles stay apart
            arc = _arc(x_minus, (0.3 + 0.08 * i) * radius, moreau_dir, d)
        drawn.append(Candidate(label, x, alpha, arc))
    return PlanePicture(origin=origin, basis=basis, radius=radius, half_width=h,
                        u_minus=x_minus, z=x_z, circle=circle,
                        reaction_cone=polygons["reaction"], tangent_cone=polygons["tangent"],
                        admissible=polygons["S"],
                        moreau_line=np.array([x_minus, _ray_exit(x_minus, moreau_dir, h)]),
                        moreau_marks=marks, candidates=drawn)


# --- the sector law in the γ plane (docs/theory.md §6)
# ------------------------------------------------------
@dataclass(frozen=True)
class Wedge:
    """One cone of the 3-ball sector law, drawn as a circular sector of the γ plane.

    All points are in the G⁻¹-orthonormal coordinates y of :func:`sector_picture`
    (γ = ``frame @ y``); ``sample`` is a γ⁻ inside the cone and ``image`` its
    γ⁺ = Q γ⁻, both in those coordinates.
    """

    label: str
    Q: np.ndarray
    text: str
    polygon: np.ndarray
    anchor: np.ndarray
    sample: np.ndarray
    image: np.ndarray
    frame: np.ndarray


def _matrix_text(Q: np.ndarray) -> str:
    return "Q = [" + "; ".join(" ".join(f"{v + 0.0:g}" for v in row) for row in Q) + "]"


def sector_frame(G: ArrayLike) -> np.ndarray:
    """The lower Cholesky factor L of the Delassus matrix G = LLᵀ.

    Coordinates y with γ = L y are orthonormal in the metric G⁻¹ of the γ plane
    (γᵀG⁻¹γ = yᵀy), which is the kinetic metric of the velocities u = M⁻¹WG⁻¹γ: in them
    the angles of the sector law's cones are the true ones (60° for three equal balls) and
    every map γ⁻ ↦ Qγ⁻ is an isometry.

    Parameters
    ----------
    G : (m, m) array_like
        Symmetric positive definite.

    Returns
    -------
    ndarray
        L, shape (m, m).
    """
    return np.linalg.cholesky(np.asarray(G, dtype=float))


def sector_picture(radius: float = 1.0, sample_radius: float = 0.45) -> list[Wedge]:
    """The six cones of the (γ₁⁻, γ₂⁻) plane for three equal balls, each with its Q and
    one sample point mapped by the law (docs/theory.md §6).

    The plane is drawn in G⁻¹-orthonormal coordinates (:func:`sector_frame`), so each cone is
    a 60° circular sector of radius ``radius`` and every image lies as far from the origin as
    its sample.

    Parameters
    ----------
    radius : float
        Radius of the drawn sectors.
    sample_radius : float
        Typical distance of the sample points from the origin, as a fraction of ``radius``
        (each cone's sample lies at an angle and a distance of its own, so that no two images
        coincide).

    Returns
    -------
    list of Wedge
        One per cone, in the order of :func:`~impactqp.tables.sector_law_table`.
    """
    table = sector_law_table(3)
    L = sector_frame(table.G)
    to_y = np.linalg.inv(L)
    wedges = []
    for k, cone in enumerate(table.cones):
        r1, r2 = (to_y @ r for r in cone.rays)
        r1, r2 = r1 / np.linalg.norm(r1), r2 / np.linalg.norm(r2)
        mid = (r1 + r2) / np.linalg.norm(r1 + r2)
        polygon = np.vstack([[0.0, 0.0], _arc(np.zeros(2), radius, r1, r2)])
        # each sample at an angle and a radius of its own, so that no two images coincide
        turn = np.arctan2(r1[0] * r2[1] - r1[1] * r2[0], r1 @ r2)
        angle = np.arctan2(r1[1], r1[0]) + (k + 0.5) / len(table.cones) * turn
        sample = sample_radius * radius * (0.75 + 0.1 * k) * np.array([np.cos(angle),
                                                                      np.sin(angle)])
        wedges.append(Wedge(label=cone.label, Q=cone.Q,
                            text=f"{cone.label}\n{_matrix_text(cone.Q)}", polygon=polygon,
                            anchor=0.72 * radius * mid, sample=sample,
                            image=to_y @ sector_gamma_map(L @ sample), frame=L))
    return wedges
