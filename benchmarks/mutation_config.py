"""What the mutation run mutates, with which operators, and which tests judge each module.

Each module holding formulas or verdicts is mapped to the fast test files that exercise it
(seconds per run with ``NUMBA_DISABLE_JIT=1``), so that a mutant costs one short pytest call.
Mutants shown to be equivalent (no input can tell them from the original) are listed in
:data:`EQUIVALENT` with the reason; the report counts them apart.
"""

from __future__ import annotations

MODULES: dict[str, tuple[str, ...]] = {
    # the verdict every certificate shares
    "impactqp/base/checks.py": (
        "tests/test_mutants_checks.py", "tests/test_verify.py", "tests/test_small_path.py"),
    # the compiled dense impact: pack, solve, certify
    "impactqp/kernels/impact.py": (
        "tests/test_mutants_kernels.py", "tests/test_kernels.py", "tests/test_small_path.py"),
    # the active-set LCP solver every compiled impact calls
    "impactqp/kernels/active_set.py": (
        "tests/test_mutants_kernels.py", "tests/test_mutants_active_set.py",
        "tests/test_kernels.py", "tests/test_small_path.py"),
    # the certificate's residuals, dense and chain
    "impactqp/kernels/residuals.py": (
        "tests/test_mutants_kernels.py", "tests/test_kernels.py", "tests/test_small_path.py",
        "tests/test_chain_certificate.py"),
    # the admissible set S and its membership
    "impactqp/model/admissible.py": (
        "tests/test_mutants_admissible.py", "tests/test_admissible.py"),
    # the certificate of the laws and the model's residual assembly
    "impactqp/laws/certificate.py": (
        "tests/test_mutants_certificate.py", "tests/test_verify.py", "tests/test_small_path.py",
        "tests/test_reflection_law.py"),
    "impactqp/model/residuals.py": (
        "tests/test_mutants_model_residuals.py", "tests/test_small_path.py",
        "tests/test_verify.py"),
    # the chain's compiled pass
    "impactqp/kernels/chain.py": (
        "tests/test_mutants_chain.py", "tests/test_isotonic.py",
        "tests/test_chain_certificate.py"),
    # the chain certificate over a batch's rows, block by block
    "impactqp/kernels/chain_batch.py": (
        "tests/test_chain_batch.py", "tests/test_chain_certificate.py", "tests/test_batch.py"),
    # the friction certificate's own formulas (r ∈ K_μ, ũ ∈ K*_μ, r·ũ = 0)
    "impactqp/kernels/coulomb_conditions.py": (
        "tests/test_mutants_coulomb_conditions.py", "tests/test_friction_certificate.py",
        "tests/test_friction.py"),
    # the unit of each contact every frictional problem is posed in
    "impactqp/kernels/units.py": (
        "tests/test_mutants_units.py", "tests/test_friction_scales.py", "tests/test_friction.py",
        "tests/test_friction_certificate.py"),
    # the one Moreau–Jean step every loop takes
    "impactqp/kernels/step.py": (
        "tests/test_mutants_step.py", "tests/test_compiled_moreau_jean.py"),
    # LZB's compliant impact
    "impactqp/kernels/lzb.py": ("tests/test_lzb_kernels.py",),
    "impactqp/kernels/lzb_model.py": ("tests/test_lzb_kernels.py",),
    "impactqp/kernels/lzb_groups.py": ("tests/test_lzb_kernels.py",),
    # the cone projection, De Saxcé's modified velocity, the natural map, NSGS
    "impactqp/kernels/friction.py": (
        "tests/test_mutants_friction.py", "tests/test_cones.py", "tests/test_friction.py"),
    # under refactoring when this table was written (run it once it settles)
    "impactqp/kernels/moreau_jean.py": ("tests/test_compiled_moreau_jean.py",),
}
"""Module (path from the repository root) → the test files run against each of its mutants."""

FIRST = ("impactqp/base/checks.py", "impactqp/kernels/impact.py",
         "impactqp/kernels/active_set.py", "impactqp/kernels/residuals.py",
         "impactqp/model/admissible.py")
"""The modules run when ``--modules`` is not given (the reference report's)."""

OPERATORS: tuple[str, ...] = (
    # arithmetic: the slips a formula is written with
    "core/ReplaceBinaryOperator_Add_Sub", "core/ReplaceBinaryOperator_Sub_Add",
    "core/ReplaceBinaryOperator_Mul_Div", "core/ReplaceBinaryOperator_Div_Mul",
    "core/ReplaceBinaryOperator_Pow_Mul", "core/ReplaceBinaryOperator_FloorDiv_Div",
    "core/ReplaceBinaryOperator_Mod_FloorDiv",
    # comparisons: a boundary moved by one, or a test turned round
    "core/ReplaceComparisonOperator_Lt_LtE", "core/ReplaceComparisonOperator_LtE_Lt",
    "core/ReplaceComparisonOperator_Gt_GtE", "core/ReplaceComparisonOperator_GtE_Gt",
    "core/ReplaceComparisonOperator_Lt_GtE", "core/ReplaceComparisonOperator_LtE_Gt",
    "core/ReplaceComparisonOperator_Gt_LtE", "core/ReplaceComparisonOperator_GtE_Lt",
    "core/ReplaceComparisonOperator_Eq_NotEq", "core/ReplaceComparisonOperator_NotEq_Eq",
    "core/ReplaceComparisonOperator_Is_IsNot", "core/ReplaceComparisonOperator_IsNot_Is",
    # signs, logic, constants and loops
    "core/ReplaceUnaryOperator_USub_UAdd", "core/ReplaceUnaryOperator_Delete_Not",
    "core/ReplaceTrueWithFalse", "core/ReplaceFalseWithTrue",
    "core/ReplaceAndWithOr", "core/ReplaceOrWithAnd",
    "core/ReplaceBreakWithContinue", "core/ReplaceContinueWithBreak",
    "core/NumberReplacer", "core/ZeroIterationForLoop",
)
"""cosmic-ray's operators applied. Left out: ``RemoveDecorator`` (removing ``@kernel`` changes
nothing with ``NUMBA_DISABLE_JIT=1``), the bitwise and shift replacements (no bit arithmetic
in these modules), the arithmetic replacements beyond one per operator pair (they repeat what
the kept ones find), ``AddNot`` (the comparison negations cover it) and the variable
replacers (random, not reproducible from a seed)."""

_ROUTE = ("to rounding: which of the two routes (the compiled dense kernel or numpy products) "
          "computes the residuals; both compute the same formulas, each tested against the "
          "same numpy reference")

_ABS = ("max(|·|) is ≥ 0 > −1: ``initial`` decides only for an empty array, which this one "
        "never is")

_INF_ENTRY = ("an infinite entry of r or u makes the contact's size ‖r‖ + ‖ũ‖ infinite and r·ũ "
              "infinite or NaN, so e is NaN and both sums are NaN")

_NAN_TERM = ("the test only asks whether the sum is NaN: " + _INF_ENTRY + "; with finite "
             "entries r_n and u_n are finite, so the sign of either changes nothing")

_NAN_SIGN = ("to the verdict: the test only asks whether the sum is NaN, and turning the sign "
             "of one non-negative term changes that only where two terms are +∞: "
             + _INF_ENTRY + "; with finite entries that needs two of a, b, e, ‖r_T‖², ‖u_T‖² "
             "overflowing (μ ≈ 1e300 or entries ≈ 1e154), and then one of the three figures is "
             "+∞ or NaN in the original too, which every verdict refuses as it refuses NaN "
             "(v ≤ tol is false for both)")

EQUIVALENT: dict[tuple[str, str, str, str], str] = {
    ("impactqp/base/checks.py", "core/NumberReplacer",
     "UNIT_RANGE = (1e-100, 1e100)", "UNIT_RANGE = (1e-100, 1e+100)"):
        "1e100 ± 1 rounds to the float 1e100: the constant is unchanged",
    ("impactqp/kernels/impact.py", "core/NumberReplacer",
     "return (np.empty(2 * n + 5 * m), np.empty((m, m)), np.empty(m, dtype=np.int64),",
     "return (np.empty( 3 * n + 5 * m), np.empty((m, m)), np.empty(m, dtype=np.int64),"):
        "a larger scratch array: the solve and the residuals use its first 2n + 5m floats only",
    ("impactqp/kernels/impact.py", "core/NumberReplacer",
     "w = floats[m:2 * m]", "w = floats[m: 3 * m]"):
        "the search reads and writes w[:m] only, the same cells",
    ("impactqp/kernels/impact.py", "core/NumberReplacer",
     "sv = floats[2 * m:3 * m]", "sv = floats[2 * m: 4 * m]"):
        "γ⁻ and the search's scratch use sv[:m] only, the same cells",
    ("impactqp/kernels/active_set.py", "core/NumberReplacer", "leave = -1", "leave = - 2"):
        "only leave < 0 is tested: −1 and −2 say the same",
    ("impactqp/kernels/active_set.py", "core/NumberReplacer",
     "if status == SOLVED and k > 0:", "if status == SOLVED and k > -1:"):
        "with k = 0 the final solve sets x = 0, which it already is, and recomputes w",
    ("impactqp/kernels/residuals.py", "core/NumberReplacer",
     "V = np.sqrt(V2_minus if V2_minus > 0.0 else _high(V2_plus, 0.0))",
     "V = np.sqrt(V2_minus if V2_minus > 0.0 else _high(V2_plus, 1.0))"):
        "the mutated branch (u⁻ = 0) returns max(V, 1), and max(√max(x, 1), 1) = "
        "max(√max(x, 0), 1) for every x, NaN staying NaN in both",
    ("impactqp/model/admissible.py", "core/NumberReplacer", "if st.m == 0:", "if st.m == -1:"):
        "to rounding: without contacts the NNLS over no columns returns the same ‖du‖_M "
        "(computed in order-one units and scaled back) and no impulses",
    ("impactqp/model/admissible.py", "core/ReplaceComparisonOperator_LtE_Lt",
     "if not UNIT_RANGE[0] <= scale <= UNIT_RANGE[1]:  # z scales with u⁻: order-one units",
     "if not UNIT_RANGE[0] <= scale < UNIT_RANGE[1]:  # z scales with u⁻: order-one units"):
        "to rounding: at a scale of exactly 1e100 z is computed in order-one units and "
        "scaled back instead of as given; z is positively homogeneous in u⁻",
    ("impactqp/model/admissible.py", "core/NumberReplacer",
     "kinematic = float(max(0.0, -np.min(gamma / (s * V), initial=0.0)))",
     "kinematic = float(max( -1.0, -np.min(gamma / (s * V), initial=0.0)))"):
        "min(…, initial=0) ≤ 0, so −min ≥ 0 > −1 and the outer max never picks −1",
    ("impactqp/kernels/impact.py", "core/NumberReplacer",
     "sv = floats[2 * m:3 * m]", "sv = floats[ 1 * m:3 * m]"):
        "γ⁻ and the search's scratch s then share w's cells, and no value is read after the "
        "other array overwrote it: γ⁻ is read into q before the search; every pass that "
        "writes s (the ray, the inner steps, the final solve) reads w before it or not at "
        "all, s[i] = −w[i] negates a cell in place, and w is recomputed before it is read",
    ("impactqp/model/residuals.py", "core/NumberReplacer",
     "DENSE_CONTACTS = 2000", "DENSE_CONTACTS = 2001"):
        _ROUTE,
    ("impactqp/model/residuals.py", "core/NumberReplacer",
     "DENSE_CONTACTS = 2000", "DENSE_CONTACTS = 1999"):
        _ROUTE,
    ("impactqp/model/residuals.py", "core/ReplaceUnaryOperator_Delete_Not",
     "if not st.sparse and st.chain is None and st.m <= DENSE_CONTACTS:",
     "if  st.sparse and st.chain is None and st.m <= DENSE_CONTACTS:"):
        _ROUTE,
    ("impactqp/model/residuals.py", "core/NumberReplacer",
     "bool(c.left_wall), bool(c.right_wall), E, 0.0 if eps is None else float(eps),",
     "bool(c.left_wall), bool(c.right_wall), E, -1.0 if eps is None else float(eps),"):
        "without Moreau's ε the chain kernel never reads ε (energy balance and duality gap "
        "are NaN then)",
    ("impactqp/model/residuals.py", "core/NumberReplacer",
     "bool(c.left_wall), bool(c.right_wall), E, 0.0 if eps is None else float(eps),",
     "bool(c.left_wall), bool(c.right_wall), E, 1.0 if eps is None else float(eps),"):
        "without Moreau's ε the chain kernel never reads ε (energy balance and duality gap "
        "are NaN then)",
    ("impactqp/kernels/residuals.py", "core/NumberReplacer",
     "SCALE_RANGE = (1e-60, 1e60)", "SCALE_RANGE = (1e-60, 1e+60)"):
        "1e60 ± 1 rounds to the float 1e60: the constant is unchanged",
    ("impactqp/kernels/residuals.py", "core/ReplaceComparisonOperator_Gt_GtE",
     "return a if (a > b or a != a) else b", "return a if (a >= b or a != a) else b"):
        "for a == b either argument is the same number (±0 compare equal and give the same "
        "verdicts)",
    ("impactqp/kernels/residuals.py", "core/ReplaceComparisonOperator_Lt_LtE",
     "return a if (a < b or a != a) else b", "return a if (a <= b or a != a) else b"):
        "for a == b either argument is the same number (±0 compare equal and give the same "
        "verdicts)",
    ("impactqp/kernels/active_set.py", "core/ReplaceFalseWithTrue",
     "blocked[:] = False", "blocked[:] = True"):
        "after a ray step (the only place this line survives; at the other two every test "
        "with a non-trivial LCP fails) nothing reads ``blocked`` before the restoring move, "
        "which has joined = −1 and so always reports moved and clears ``blocked``",
    ("impactqp/model/admissible.py", "core/NumberReplacer",
     'c = float(np.abs(du).max(initial=0.0))',
     'c = float(np.abs(du).max(initial= -1.0))'):
        _ABS,
    ("impactqp/model/admissible.py", "core/NumberReplacer",
     'c = float(np.abs(p.u_minus).max(initial=0.0))',
     'c = float(np.abs(p.u_minus).max(initial= -1.0))'):
        _ABS,
    ("impactqp/model/admissible.py", "core/NumberReplacer",
     'c = float(np.abs(self.problem.u_minus).max(initial=0.0))',
     'c = float(np.abs(self.problem.u_minus).max(initial= -1.0))'):
        _ABS,
    ("impactqp/model/admissible.py", "core/NumberReplacer",
     'scale = float(np.abs(self.problem.u_minus).max(initial=0.0))',
     'scale = float(np.abs(self.problem.u_minus).max(initial= -1.0))'):
        _ABS,
    ("impactqp/model/admissible.py", "core/NumberReplacer",
     'cn = float(np.abs(c).max(initial=0.0))',
     'cn = float(np.abs(c).max(initial= -1.0))'):
        _ABS,
    ("impactqp/model/admissible.py", "core/NumberReplacer",
     'lam.min() < -1e-12 * max(float(np.abs(lam).max(initial=0.0)), 1e-300):',
     'lam.min() < -1e-12 * max(float(np.abs(lam).max(initial= -1.0)), 1e-300):'):
        _ABS,
    ("impactqp/model/admissible.py", "core/NumberReplacer",
     'kinematic = float(max(0.0, -np.min(gamma / (s * V), initial=0.0)))',
     'kinematic = float(max(0.0, -np.min(gamma / (s * V), initial= 1.0)))'):
        "with every γᵢ > 0 both minima are positive and the penetration is 0 either way; with "
        "one γᵢ ≤ 0 the minimum is that one",
    ("impactqp/model/admissible.py", "core/NumberReplacer",
     'lam.min() < -1e-12 * max(float(np.abs(lam).max(initial=0.0)), 1e-300):',
     'lam.min() < -1e-12 * max(float(np.abs(lam).max(initial= 1.0)), 1e-300):'):
        "not strictly equivalent: the sparse solve's Λ is accepted down to −1e-12 instead of "
        "−1e-12·max|Λ| when max|Λ| < 1 (order-one units), and then clipped at 0; the "
        "answer moves by < 1e-12 relative, below every certificate's tolerance",
    ("impactqp/kernels/friction.py", "core/NumberReplacer",
     "gap = int(min(max(left, 1.0), CHECK_GAP))", "gap = int(min(max(left, 0.0), CHECK_GAP))"):
        "left > 0 (both logarithms are negative once tol < err < last_err), so the two differ "
        "only for left < 1, where the gap is 0 instead of 1: check_at = done or done + 1, and "
        "either way the next sweep (done + 1) is not below it and evaluates ‖F‖",
    ("impactqp/kernels/coulomb_conditions.py", "core/ReplaceBinaryOperator_Add_Sub",
     "if np.isnan(a + b + e + r[k] + u[k] + r_t2 + u_t2):",
     "if np.isnan(a - b + e + r[k] + u[k] + r_t2 + u_t2):"):
        _NAN_SIGN,
    ("impactqp/kernels/coulomb_conditions.py", "core/ReplaceBinaryOperator_Add_Sub",
     "if np.isnan(a + b + e + r[k] + u[k] + r_t2 + u_t2):",
     "if np.isnan(a + b - e + r[k] + u[k] + r_t2 + u_t2):"):
        _NAN_SIGN,
    ("impactqp/kernels/coulomb_conditions.py", "core/ReplaceBinaryOperator_Add_Sub",
     "if np.isnan(a + b + e + r[k] + u[k] + r_t2 + u_t2):",
     "if np.isnan(a + b + e - r[k] + u[k] + r_t2 + u_t2):"):
        _NAN_TERM,
    ("impactqp/kernels/coulomb_conditions.py", "core/ReplaceBinaryOperator_Add_Sub",
     "if np.isnan(a + b + e + r[k] + u[k] + r_t2 + u_t2):",
     "if np.isnan(a + b + e + r[k] - u[k] + r_t2 + u_t2):"):
        _NAN_TERM,
    ("impactqp/kernels/coulomb_conditions.py", "core/ReplaceBinaryOperator_Add_Sub",
     "if np.isnan(a + b + e + r[k] + u[k] + r_t2 + u_t2):",
     "if np.isnan(a + b + e + r[k] + u[k] - r_t2 + u_t2):"):
        _NAN_SIGN,
    ("impactqp/kernels/coulomb_conditions.py", "core/ReplaceBinaryOperator_Add_Sub",
     "if np.isnan(a + b + e + r[k] + u[k] + r_t2 + u_t2):",
     "if np.isnan(a + b + e + r[k] + u[k] + r_t2 - u_t2):"):
        _NAN_SIGN,
    ("impactqp/kernels/units.py", "core/ReplaceComparisonOperator_Gt_GtE",
     "if x > w and x < np.inf:", "if x >= w and x < np.inf:"):
        "where x == w the block's largest entry w is replaced by the same number (±0 only "
        "while w ≤ 0, which is no unit either way)",
    ("impactqp/kernels/units.py", "core/NumberReplacer", "w = 0.0", "w = -1.0"):
        "the search of the block's largest entry starting at −1 instead of 0 may pick an "
        "entry in (−1, 0], which is no unit either (w > 0 decides), and any positive finite "
        "entry beats both starts: w ends the same positive number or non-positive",
    ("impactqp/kernels/units.py", "core/NumberReplacer",
     "for k in range(1, d):", "for k in range( 0, d):"):
        "the search of the tangential entries runs only when the normal one is not positive "
        "and finite, so adding it to the search adds an entry that is never picked",
}
"""(module, operator, original line, mutated line) — lines stripped — → why no input can tell
the mutant from the original. Keyed by text rather than line number, so that edits elsewhere
in the module keep the entry."""

_TIE = ("reached only when a variable of P has x = s = 0 exactly (a tie at a vertex: at a "
        "warm start's first move, where every x is 0, or where two variables reach zero in "
        "one step), which changes which inner step drops the variable, and with it the "
        "number of outer steps, not the end: the same status, and a solution of the same "
        "LCP (another of them where G is singular and the solutions many; 3,000 random "
        "integer LCPs with redundant columns, cold and warm, compared)")

_BUDGET = ("the search's step budget 20m + 50 moved by m or 1: searches take m to 3m steps, "
           "so only an LCP near the budget could tell")

NOTES: dict[tuple[str, str, str, str], str] = {
    ("impactqp/model/admissible.py", "core/ReplaceUnaryOperator_Delete_Not",
     "if lam is None or not np.all(np.isfinite(lam)) or \\",
     "if lam is None or  np.all(np.isfinite(lam)) or \\"):
        "sends every finite sparse Λ to the certified LCP instead (slower, the same answer); "
        "differs only when the sparse LU of the Delassus matrix returns a non-finite Λ, "
        "which no test's problem does",
    ("impactqp/kernels/active_set.py", "core/NumberReplacer",
     "if i != stop and (s[i] > 0.0 or x[i] > 0.0):",
     "if i != stop and (s[i] > 1.0 or x[i] > 0.0):"):
        _TIE,
    ("impactqp/kernels/active_set.py", "core/NumberReplacer",
     "if i != stop and (s[i] > 0.0 or x[i] > 0.0):",
     "if i != stop and (s[i] > -1.0 or x[i] > 0.0):"):
        _TIE,
    ("impactqp/kernels/active_set.py", "core/NumberReplacer",
     "if i != stop and (s[i] > 0.0 or x[i] > 0.0):",
     "if i != stop and (s[i] > 0.0 or x[i] > -1.0):"):
        _TIE,
    ("impactqp/kernels/active_set.py", "core/NumberReplacer",
     "if i != stop and (s[i] > 0.0 or x[i] > 0.0):",
     "if i != stop and (s[i] > 0.0 or x[i] > 1.0):"):
        "drops variables still moving with 0 < x ≤ 1; they join again in later outer steps "
        "and the answer is the minimizer on the final support: the path changes, not the end",
    ("impactqp/kernels/active_set.py", "core/ReplaceBinaryOperator_Mul_Div",
     "x[idx[a]] += t * s[idx[a]]", "x[idx[a]] += t / s[idx[a]]"):
        "the point reached along a ray only starts the restoring inner steps, which end at the "
        "minimizer on the new support: the path changes, not the end",
    ("impactqp/kernels/active_set.py", "core/ReplaceAndWithOr",
     "if status == SOLVED and k > 0:", "if status == SOLVED or k > 0:"):
        "refines x after a failed search too; every caller refuses a failed search's answer "
        "(no test reads x after NO_SOLUTION or ITERATION_LIMIT)",
    ("impactqp/kernels/impact.py", "core/NumberReplacer",
     "if lcp_psd_work(G, q, passive, lam, w, 20 * m + 50, L, idx, sv, blocked) != SOLVED:",
     "if lcp_psd_work(G, q, passive, lam, w, 21 * m + 50, L, idx, sv, blocked) != SOLVED:"):
        _BUDGET,
    ("impactqp/kernels/impact.py", "core/NumberReplacer",
     "if lcp_psd_work(G, q, passive, lam, w, 20 * m + 50, L, idx, sv, blocked) != SOLVED:",
     "if lcp_psd_work(G, q, passive, lam, w, 19 * m + 50, L, idx, sv, blocked) != SOLVED:"):
        _BUDGET,
    ("impactqp/kernels/impact.py", "core/NumberReplacer",
     "if lcp_psd_work(G, q, passive, lam, w, 20 * m + 50, L, idx, sv, blocked) != SOLVED:",
     "if lcp_psd_work(G, q, passive, lam, w, 20 * m + 51, L, idx, sv, blocked) != SOLVED:"):
        _BUDGET,
    ("impactqp/kernels/impact.py", "core/NumberReplacer",
     "if lcp_psd_work(G, q, passive, lam, w, 20 * m + 50, L, idx, sv, blocked) != SOLVED:",
     "if lcp_psd_work(G, q, passive, lam, w, 20 * m + 49, L, idx, sv, blocked) != SOLVED:"):
        _BUDGET,
    ("impactqp/kernels/active_set.py", "core/NumberReplacer",
     "step = x[i] / (x[i] - s[i]) if x[i] > s[i] else 0.0",
     "step = x[i] / (x[i] - s[i]) if x[i] > s[i] else 1.0"): _TIE,
    ("impactqp/kernels/active_set.py", "core/NumberReplacer",
     "step = x[i] / (x[i] - s[i]) if x[i] > s[i] else 0.0",
     "step = x[i] / (x[i] - s[i]) if x[i] > s[i] else -1.0"): _TIE,
    ("impactqp/kernels/active_set.py", "core/ReplaceAndWithOr",
     "if i != stop and (s[i] > 0.0 or x[i] > 0.0):",
     "if i != stop or (s[i] > 0.0 or x[i] > 0.0):"):
        "a variable of P other than the blocking one that reaches zero in the same step "
        "stays in P at x = 0 and leaves at the next inner step (step 0): a tie again, one "
        "more inner step, the same end",
    ("impactqp/kernels/active_set.py", "core/ReplaceFalseWithTrue",
     "first = False", "first = True"):
        "a joining variable whose minimizer turns non-positive after the first inner step "
        "leaves at once and is blocked instead of being stepped past; this could end a "
        "search with that variable still descending, which no test (150 random LCPs, "
        "redundant contacts, warm starts) has produced",
    ("impactqp/kernels/friction.py", "core/ReplaceComparisonOperator_Gt_GtE",
     "active = xn > 0.0", "active = xn >= 0.0"):
        "Φ is the same ((x_n)₊ = 0 at x_n = 0 either way); only the Jacobian on the kink "
        "x_n = r_n − ρu_n = 0 exactly changes branch, and both branches are elements of the "
        "Clarke Jacobian there: a semismooth Newton step may take another path, not to "
        "another end",
}
"""Survivors that are not equivalent but not yet killed, keyed as :data:`EQUIVALENT`: what
they change and why no test sees it. They count as survived."""
