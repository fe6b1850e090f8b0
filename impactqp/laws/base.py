"""What an impact law is to impactqp: an object that owns its program, the recovery of u⁺ and
Λ from the program's solution, and its own residuals (docs/theory.md §3, §8).

A law either emits quadratic programs (one per form it has: ``"velocity"`` or
``"impulse"``) that any suitable backend solves, or computes its answer in closed form
(``forms = ()``, e.g. the sector law). The solve pipeline (:func:`impactqp.solve`) does the
rest: validation, backend choice, polishing, the certificate and the result. A new law plugs
in by subclassing :class:`ImpactLaw`.
"""

from __future__ import annotations

from abc import ABC
from typing import Any, ClassVar, NamedTuple

import numpy as np

from ..base.arrays import as_vector
from ..derivatives.local import LocalMap
from ..errors import InputError
from ..model.admissible import AdmissibleSet, best_impulses
from ..model.problem import ImpactProblem
from ..model.programs import preferred_forms
from ..model.residuals import impact_residuals, normalized_rows
from ..model.structure import ImpactStructure
from ..qp.program import QPSolution, QuadraticProgram
from .certificate import Certificate

MOREAU_FAMILY = "moreau"
"""Moreau's family (docs/theory.md §3): ``0 ≤ Λ ⟂ GΛ + (1 + ε)γ⁻ ≥ 0``, u⁺ = (1 + ε)z − εu⁻
with z = prox_{T_C}(u⁻) in the metric M."""

COMPLEMENTARITY_FAMILY = "complementarity"
"""The complementarity family (docs/theory.md §3): ``0 ≤ Λ ⟂ GΛ + (I + E)γ⁻ ≥ 0``."""

FAMILIES = (MOREAU_FAMILY, COMPLEMENTARITY_FAMILY)
"""The compiled families a law may declare as its :attr:`ImpactLaw.family`."""

FAMILY_METHODS = {MOREAU_FAMILY: ("restitution", "projection"),
                  COMPLEMENTARITY_FAMILY: ("restitution",)}
"""The methods a law of each family defines besides :class:`ImpactLaw`'s (a law of Moreau's
family also has the attribute ``eps``, its ε ∈ [0, 1])."""

_DECLARED_PER_CLASS = ("family", "restitution_per_contact", "compliant")
"""Capabilities a subclass does not inherit: a subclass may change the law (its program,
its residuals), so it is of a fast family only when it says so itself."""


class Answer(NamedTuple):
    """A law's answer: post-impact velocity, impulses and (Moreau's family) the projection z.

    Attributes
    ----------
    u_plus : (n,) ndarray
        Post-impact velocity u⁺.
    impulses : (m,) ndarray
        Contact impulses Λ with M(u⁺ − u⁻) = WΛ.
    z : (n,) ndarray or None
        z = prox_{T_C}(u⁻) for laws of Moreau's family (docs/theory.md §3), else None.
    """

    u_plus: np.ndarray
    impulses: np.ndarray
    z: np.ndarray | None = None


class ImpactLaw(ABC):
    """Base class of impact laws.

    A subclass sets the class attributes below and either :meth:`program` with
    :meth:`recover` (a law solved through quadratic programs) or :meth:`closed_form`
    (``forms = ()``; returning u⁺ alone is enough, the impulses are recovered). Its
    :meth:`residuals` (by default momentum and Λ ≥ 0) make the law's
    :class:`~impactqp.results.Certificate`; batches run a closed form row by row unless
    :meth:`closed_form_rows` does better.

    Attributes
    ----------
    name : str
        Short name (``"moreau"``), stored in ``ImpactResult.law``.
    title : str
        Human name for messages.
    forms : tuple of str
        Program forms the law can emit, in no particular order; ``()`` for closed form.
    closed_form_backend : str
        For closed-form laws, the name their results carry as backend (``"sort"``).
    always_solvable : bool
        A solution exists for every u⁻ (Moreau's law, the sector law): the pipeline never
        reports "no solution" for such a law.
    by_name : bool
        Problem and simulation files and the command line may name the law (its
        coefficients, if any, under ``coefficient_keys``).
    coefficient_key, coefficient_symbol : str or None
        How files and the command line spell its coefficient (``"eps"``) and how reports
        print it (``"ε"``); None for a law without coefficients.
    coefficient_keys : tuple of str
        Every key of its coefficients in files and on the command line, in the order of
        :attr:`coefficients`: ``(coefficient_key,)`` unless the law sets more
        (``("mu", "e")`` for Coulomb's law, whose :meth:`from_coefficients` takes a pair).
    needs_coefficients : bool
        Naming the law requires its coefficients (they have no default).
    homogeneous : bool
        u⁻ ↦ (u⁺, Λ) is positively homogeneous of degree one (the laws of docs/theory.md
        §3, §6, §10, §13, §16): :func:`impactqp.solve` may then solve a problem whose
        velocities are far from order one in order-one units and scale the answer back
        (docs/theory.md §8).
    frictional : bool
        The law acts on frictional contacts (``problem.contact_dim`` 2 or 3, docs/theory.md
        §16), like :class:`~impactqp.Coulomb`; every other law is refused such a problem
        by the entry points (its ``normal_problem()`` is the frictionless one). Simulations
        of a frictional law run the frictional Moreau–Jean step (docs/theory.md §17), which
        reads the law's ``mu``, ``restitution`` (per contact or one number) and ``method``.
    family : str or None
        The compiled family of complementarity laws the law belongs to, whose fast paths
        take it (docs/theory.md §9): the compiled single impact, its rows in batches, the
        compiled Moreau–Jean loop and the collapse of parallel contacts.
        ``"complementarity"`` (:data:`~impactqp.laws.base.COMPLEMENTARITY_FAMILY`): the law is
        ``0 ≤ Λ ⟂ GΛ + (I + E)γ⁻ ≥ 0`` with E = ``restitution(m)`` (an (m,) diagonal or an
        (m, m) matrix), has the step form E = :meth:`step_restitution` and, with
        per-contact coefficients, :meth:`restrict`. ``"moreau"``
        (:data:`~impactqp.laws.base.MOREAU_FAMILY`): the same with E = εI from the law's
        ``eps``, and the projection
        z = ``projection(problem, u⁺)``; short chains also take the column-wise isotonic
        path. The fast paths compute and certify the family's answer with the family's
        residuals (docs/theory.md §8), not the law's :meth:`program` and :meth:`residuals`:
        a law declares a family only when it *is* that law, and it keeps its programs for
        the impacts the fast paths decline. None (the default): the law's own programs or
        closed form answer. Declared per class: a subclass of a built-in law that does not
        declare it takes the general path; a class that declares a family without its
        methods (:data:`~impactqp.laws.base.FAMILY_METHODS`) is refused when it is defined.
    residual_names : tuple of str
        The residuals of the law's certificate (:meth:`residuals`, docs/theory.md §8),
        readable as its attributes; by default the two every impact law shares,
        ``("momentum", "impulse_sign")``. A law that checks more declares them.
    restitution_per_contact : bool
        E is diagonal (one coefficient per contact, or one ε for all): contacts whose columns
        of W are parallel, with equal coefficients, act as one and an impact with more
        contacts than degrees of freedom is solved collapsed (docs/theory.md §1). Read with
        :attr:`~impactqp.laws.base.ImpactLaw.family`, whose ``restitution(m)`` gives the
        coefficients. Declared per class.
    compliant : bool
        The outcome depends on the contacts' compliance (stiffnesses, exponents), as for the
        LZB model (docs/theory.md §13), and not on the rigid geometry alone:
        :func:`~impactqp.verification.compare.compare_laws` sets such a law against the
        rigid ones. Declared per class.
    """

    name: ClassVar[str]
    title: ClassVar[str]

    def __init_subclass__(cls, **kwargs: Any) -> None:
        """A law class that names neither itself nor its title is called by its class name."""
        super().__init_subclass__(**kwargs)
        if "name" not in cls.__dict__ and not hasattr(cls, "name"):
            cls.name = cls.__name__.lower()
        if "title" not in cls.__dict__ and not hasattr(cls, "title"):
            cls.title = cls.__name__
        if "coefficient_key" in cls.__dict__ and "coefficient_keys" not in cls.__dict__:
            cls.coefficient_keys = (cls.coefficient_key,) if cls.coefficient_key else ()
        for capability in _DECLARED_PER_CLASS:
            if capability not in cls.__dict__:
                setattr(cls, capability, getattr(ImpactLaw, capability))
        if cls.family is not None:
            if cls.family not in FAMILIES:
                raise InputError(f"{cls.__name__}.family must be None or one of {FAMILIES}, "
                                 f"got {cls.family!r}")
            missing = [name for name in FAMILY_METHODS[cls.family] if not hasattr(cls, name)]
            if missing:
                raise InputError(f"{cls.__name__} declares family {cls.family!r} but has no "
                                 f"{', '.join(missing)}")
    forms: ClassVar[tuple[str, ...]] = ()
    closed_form_backend: ClassVar[str] = "closed form"
    always_solvable: ClassVar[bool] = False
    by_name: ClassVar[bool] = False
    coefficient_key: ClassVar[str | None] = None
    coefficient_symbol: ClassVar[str | None] = None
    coefficient_keys: ClassVar[tuple[str, ...]] = ()
    needs_coefficients: ClassVar[bool] = False
    homogeneous: ClassVar[bool] = False
    frictional: ClassVar[bool] = False
    family: ClassVar[str | None] = None
    restitution_per_contact: ClassVar[bool] = False
    residual_names: ClassVar[tuple[str, ...]] = ("momentum", "impulse_sign")
    compliant: ClassVar[bool] = False

    @classmethod
    def from_coefficients(cls, coefficients: Any = None) -> ImpactLaw:
        """The law named in a file or on the command line, with its coefficients (None: the
        law's defaults, or InputError when ``needs_coefficients``)."""
        if coefficients is None:
            if cls.needs_coefficients:
                raise InputError(f"law {cls.name!r} needs its coefficients "
                                 f"{cls.coefficient_key!r}")
            return cls()
        if cls.coefficient_key is None:
            raise InputError(f"law {cls.name!r} takes no coefficients")
        return cls(coefficients)

    def restrict(self, contacts: np.ndarray) -> ImpactLaw:
        """The law on a subset of the contacts (indices into its own): per-contact
        coefficients taken at ``contacts``; a law without them is itself."""
        return self

    def step_restitution(self, contacts: np.ndarray) -> float | np.ndarray | None:
        """E of the law's Moreau–Jean step form ``0 ≤ Λ ⟂ γ_{k+1} + Eγ_k`` on ``contacts``
        (docs/theory.md §14): one number when every coefficient is equal, None for a law
        without a step form (it maps the free velocity to u⁺ instead)."""
        return None

    @property
    def coefficients(self) -> Any:
        """The law's coefficients as stored in results (ε, eᵢ, E, or None)."""
        return None

    def coefficients_for(self, problem: ImpactProblem) -> Any:
        """The coefficients as they act on ``problem`` (a scalar eᵢ spread over contacts)."""
        return self.coefficients

    def check(self, problem: ImpactProblem) -> None:  # noqa: B027 (optional hook)
        """Raise an InputError (naming the argument) when the law cannot act on ``problem``;
        the default accepts every problem (the entry points refuse frictional contacts to a
        law that is not ``frictional`` before they ask)."""

    def preferred_forms(self, problem: ImpactProblem) -> tuple[str, ...]:
        """The law's forms to try, best first (:func:`!impactqp.model.programs.preferred_forms`)."""
        return tuple(f for f in preferred_forms(problem) if f in self.forms)

    def program(self, problem: ImpactProblem, form: str) -> QuadraticProgram:
        """The program of ``form`` whose solution determines the law's answer."""
        raise NotImplementedError(f"{self.title} emits no {form} program")

    def recover(self, problem: ImpactProblem, form: str, solution: QPSolution) -> Answer:
        """u⁺, Λ (and z) from a solution of :meth:`program`."""
        raise NotImplementedError(f"{self.title} emits no {form} program")

    def closed_form(self, problem: ImpactProblem) -> Answer | Any:
        """The answer of a closed-form law (``forms == ()``): an :class:`Answer`, a pair
        (u⁺, Λ), or u⁺ alone, whose impulses :meth:`~impactqp.ImpactLaw.answer_of` then recovers."""
        raise NotImplementedError(f"{self.title} is solved through programs")

    def answer_of(self, problem: ImpactProblem, output: Any) -> Any:
        """What :meth:`closed_form` returned, as an :class:`Answer` of finite real arrays
        (an answer type of the law's own, such as the LZB answer, keeps its type).

        u⁺ alone gets the impulses Λ ≥ 0 closest to M(u⁺ − u⁻) = WΛ (exact NNLS, the
        kinetic test of docs/theory.md §2); if no Λ ≥ 0 produces the jump, the momentum
        residual of the certificate says so and the answer is not returned.

        Raises
        ------
        InputError
            Output that is not one or two real arrays of the problem's sizes (complex,
            NaN, strings, wrong shapes; the message names what was wrong).
        """
        if hasattr(output, "u_plus") and hasattr(output, "impulses"):  # an Answer or kin
            u_plus = as_vector(f"{self.title}: u⁺", output.u_plus, problem.n_dof)
            impulses = as_vector(f"{self.title}: Λ", output.impulses, problem.n_impulses)
            return output._replace(u_plus=u_plus, impulses=impulses)
        if isinstance(output, tuple) and len(output) == 2:
            u_plus = as_vector(f"{self.title}: u⁺", output[0], problem.n_dof)
            impulses = as_vector(f"{self.title}: Λ", output[1], problem.n_impulses)
        else:
            u_plus = as_vector(f"{self.title}: u⁺", output, problem.n_dof)
            impulses = best_impulses(problem, u_plus - problem.u_minus)[0]
        return Answer(u_plus, impulses, None)

    def linear_terms(self, problem: ImpactProblem, U_minus: np.ndarray,
                     form: str) -> np.ndarray:
        """The linear terms c of :meth:`program` for every row of U_minus (batches): the
        rest of the program depends on the structure only."""
        raise NotImplementedError(f"{self.title} has no batched {form} program")

    def recover_rows(self, problem: ImpactProblem, form: str, U_minus: np.ndarray,
                     X: np.ndarray, Y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(U⁺, Λ) from the rows of a batched solution (X primal, Y multipliers)."""
        raise NotImplementedError(f"{self.title} has no batched {form} program")

    def closed_form_rows(self, problem: ImpactProblem,
                         U_minus: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(U⁺, Λ) of a closed-form law for every row of U_minus; by default row by row
        through :meth:`closed_form` (a law that can do better overrides it)."""
        k, n, m = U_minus.shape[0], problem.n_dof, problem.n_impulses
        U_plus, impulses = np.empty((k, n)), np.empty((k, m))
        for i, u in enumerate(U_minus):
            row = problem.with_u_minus(u)
            U_plus[i], impulses[i] = self.answer_of(row, self.closed_form(row))[:2]
        return U_plus, impulses

    def derivative(self, problem: ImpactProblem, answer: Any, *,
                   kink_tol: float) -> LocalMap | None:
        """The law's map (u⁻, M, W, parameter) ↦ (u⁺, Λ) near ``answer`` (an :class:`Answer`
        or a result on ``problem``), for ``result.derivative()`` (docs/theory.md §18–§20):
        a :class:`~impactqp.derivatives.local.LocalMap` (a user's law may return a
        :class:`~impactqp.derivatives.local.LinearPiece`). None, the default: the law has no
        derivative, and its derivative says ``"unsupported"`` by name."""
        return None

    def admissible_set(self, problem: ImpactProblem) -> AdmissibleSet:
        """The admissible set the law's answers on ``problem`` are judged against
        (docs/theory.md §2; a frictional law passes its friction coefficients,
        docs/theory.md §16)."""
        return problem.admissible_set()

    def residuals(self, structure: ImpactStructure, U_minus: np.ndarray, U_plus: np.ndarray,
                  impulses: np.ndarray) -> dict[str, np.ndarray]:
        """The law's dimensionless residuals for one impact (1-D arrays, float values) or
        for rows of impacts ((k,) arrays). By default those every impact law shares: the
        momentum ‖u⁺ − u⁻ − M⁻¹WΛ‖/V and the sign of Λ (docs/theory.md §8); whether u⁺ is
        admissible, energy included, is the separate verdict ``result.admissible``."""
        U_minus, U_plus, impulses = normalized_rows(U_minus, U_plus, impulses)
        return impact_residuals(structure, U_minus, U_plus, impulses)[1]

    def certificate(self, problem: ImpactProblem, answer: Answer, tol: float) -> Certificate:
        """The recomputed certificate of ``answer`` on ``problem``: the law's
        :meth:`residuals`, each within ``tol`` (docs/theory.md §8). A law whose checks need
        more than the structure (an independent evaluation on the problem) overrides it."""
        return Certificate(self.residuals(problem.structure, problem.u_minus, answer.u_plus,
                                          answer.impulses), tol, names=self.residual_names)

    def __repr__(self) -> str:
        coef = self.coefficients
        return f"{type(self).__name__}()" if coef is None else \
            f"{type(self).__name__}({np.array2string(np.asarray(coef), precision=6)})"
