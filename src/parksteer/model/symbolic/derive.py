"""Equations of motion by Kane's method (sympy.physics.mechanics), with per-effect generalized forces.

KanesMethod gives the mass matrix and the inertia terms of the forcing; the generalized
active forces are formed here, group by group, from each load's partial velocities:
for a force F at point P, Q_r = dv_P/du_r . F; for a torque T on frame A,
Q_r = dw_A/du_r . T. So the forcing is

    M(q) u' = f_inertia(q, u) + Q_core + sum over effects Q_effect + b(q) T_column

and each effect's generalized force on the rack, mapped to the handwheel through
d(theta_c)/d(rack), is that effect's share of the handwheel torque.
"""

from __future__ import annotations

import threading
from contextlib import contextmanager
from dataclasses import dataclass, field
from typing import Any

import sympy as sp
import sympy.physics.mechanics as me
from sympy.core.function import AppliedUndef
from sympy.matrices.matrixbase import MatrixBase

from .components import Effect
from .system import INPUT_NAMES, ModelSpace


@dataclass
class Derivation:
    """Symbolic equations of one effect set, in terms of q, u, the parameters and the handwheel input."""

    effects: tuple[str, ...]
    space: ModelSpace
    coordinate_names: list[str]
    coordinate_units: list[str]
    parameter_names: list[str]
    mass_matrix: sp.Matrix
    forcing_inertia: sp.Matrix
    generalized_forces: dict[str, sp.Matrix]  # "core" and one per effect
    column_direction: sp.Matrix  # generalized force of a unit column torque
    potential_energy: Any
    timings_s: dict[str, float] = field(default_factory=dict)

    @property
    def forcing(self) -> sp.Matrix:
        total = self.forcing_inertia + self.column_direction * self.space.kinematics.column_torque
        for q in self.generalized_forces.values():
            total += q
        return total

    def plain_symbols(self) -> dict:
        """Map q(t), u(t) to plain symbols q_i, u_i (for lambdify/codegen); the inverse is not needed."""
        mapping = {}
        for i, c in enumerate(self.space.coordinates):
            mapping[c.q] = sp.Symbol(f"q[{i}]", real=True)
            mapping[c.u] = sp.Symbol(f"u[{i}]", real=True)
        return mapping


@contextmanager
def memoised_diff():
    """Within it, Expr.diff by one symbol (as sympy.diff and every _eval_derivative call it: `x`, `(x, 1)` or
    `(x, 0)`) returns what sympy's Derivative(expr, x, evaluate=True) returns, the same expression, without its
    general front end (argument tuples, sympification, the variable-count bookkeeping, paid again at every node of
    the expression it recurses through) and once per (expression, symbol): the chain rule differentiates the same
    subexpressions (a sine of a coordinate, a parameter product) inside many others.

    The short route follows Derivative.__new__ for a symbol and count 1 step by step: zero when the symbol is not
    free in the expression (each node's free symbols found once), else the expression's _eval_derivative_n_times,
    returned at once when zero, otherwise with every Derivative in it made canonical (the same expression when it
    holds none: the zero test is then skipped). A derivative by a dynamic symbol (a coordinate or speed, q(t) or
    u(t)) takes sympy's own route, once per (expression, symbol): the partial velocities of the generalized forces
    differentiate the velocities of the same points load after load. Anything else (another kind of variable, a
    count above 1, an expression without _eval_derivative or one that leaves the derivative unevaluated) takes
    sympy's own route every time.

    The memo is a :class:`ShortDiff` the installed Expr.diff holds, shared by nested or concurrent uses; the last
    to leave restores sympy's own (a patch of sympy's class, written and restored here).
    """
    from sympy.core.expr import Expr

    with _DIFF_LOCK:
        installed = getattr(Expr.diff, "short_diff", None)
        if installed is None:
            installed = ShortDiff(Expr.diff)

            def diff(self, *symbols, **assumptions):
                return installed(self, *symbols, **assumptions)

            diff.short_diff = installed
            Expr.diff = diff
        installed.users += 1
    try:
        yield
    finally:
        with _DIFF_LOCK:
            installed.users -= 1
            if installed.users == 0:
                Expr.diff = installed.original


# Serialises installing and restoring the patch of Expr.diff between threads (it holds no state itself).
_DIFF_LOCK = threading.Lock()
_BASIC_FREE_SYMBOLS = sp.Basic.free_symbols  # the property, as a class without a free_symbols of its own has it


def free_symbols(node, memo: dict):
    """node.free_symbols (not to be changed), each node's once: Basic's free_symbols is the union of its
    arguments', walked again at every node sympy asks; a class with a free_symbols of its own answers itself."""
    found = memo.get(node)
    if found is None:
        if type(node).free_symbols is _BASIC_FREE_SYMBOLS:
            found = set().union(*(free_symbols(arg, memo) for arg in node.args))
        else:
            found = node.free_symbols
        memo[node] = found
    return found


def _holds_derivative(node, memo: dict) -> bool:
    """Whether an unevaluated Derivative is in node (node itself or below), each node's answer once."""
    found = memo.get(node)
    if found is None:
        found = isinstance(node, sp.Derivative) or any(_holds_derivative(arg, memo) for arg in node.args)
        memo[node] = found
    return found


class ShortDiff:
    """Expr.diff within memoised_diff: sympy's own `original`, and the memos of one installation (derivatives by
    (expression, symbol), each node's free symbols, whether a node holds an unevaluated Derivative); `users`
    counts the memoised_diff blocks that hold it."""

    def __init__(self, original):
        self.original = original
        self.memo: dict = {}
        self.free: dict = {}
        self.holds: dict = {}
        self.users = 0

    def __call__(self, expr, *symbols, **assumptions):
        original, memo = self.original, self.memo
        derivative_type = sp.Derivative

        if assumptions or len(symbols) != 1:
            return original(expr, *symbols, **assumptions)
        s = symbols[0]
        if isinstance(s, tuple):
            if len(s) != 2 or not isinstance(s[0], sp.Symbol) or s[1] not in (0, 1) or isinstance(s[1], bool):
                return original(expr, *symbols)
            s, count = s
            if count == 0:
                return expr
        elif isinstance(s, AppliedUndef):  # a coordinate or speed q(t), u(t): sympy's own route, memoised
            key = (expr, s)
            found = memo.get(key)
            if found is None:
                found = memo[key] = original(expr, s)
            return found
        elif not isinstance(s, sp.Symbol):
            return original(expr, *symbols)
        key = (expr, s)
        found = memo.get(key)
        if found is not None:
            return found
        if isinstance(expr, derivative_type) or not hasattr(expr, "_eval_derivative"):
            result = original(expr, s)
        elif s not in free_symbols(expr, self.free):
            result = sp.S.Zero
        else:
            obj = expr._eval_derivative_n_times(s, 1)
            if obj is None:
                result = original(expr, s)
            elif not _holds_derivative(obj, self.holds):
                # zero or not, the expression Derivative.__new__ returns is obj itself (replace changes nothing in an
                # expression without a Derivative): the zero test, an assumptions query over all of obj, is not made
                result = obj
            elif obj.is_zero:
                result = obj
            else:  # as Derivative.__new__ ends: every Derivative in the result made canonical
                result = obj.replace(lambda x: isinstance(x, derivative_type), lambda x: x.canonical)
        memo[key] = result
        return result


class Replacer:
    """expr.xreplace(rule) for many expressions that share subtrees, each shared subtree replaced once.

    sympy's xreplace rebuilds every node above a replaced one (node.func(*new_args)) and keeps no memo, neither
    within one expression nor across the entries of a matrix or across expressions: a model's mass matrix,
    forcing, drive and outputs hold the same kinematic terms many times over. Called on an expression (or a
    matrix, entry by entry as Matrix.xreplace does), a Replacer gives what xreplace(rule) gives, node by node the
    same rebuild (a node in the rule is replaced, a node whose arguments changed is rebuilt from them, any other
    node is kept), with each node's result kept for the next time the same node comes. One Replacer per rule.
    """

    def __init__(self, rule: dict):
        self.rule = rule
        self._memo: dict = {}

    def __call__(self, expr):
        if isinstance(expr, MatrixBase):
            return expr.applyfunc(self)
        return self._replaced(sp.sympify(expr))[0]

    def _replaced(self, node) -> tuple[Any, bool]:
        found = self._memo.get(node)
        if found is not None:
            return found
        rule = self.rule
        if node in rule:
            result = (rule[node], True)
        elif rule:
            args, changed = [], False
            for arg in node.args:
                if getattr(arg, "_xreplace", None) is not None:
                    value, arg_changed = self._replaced(arg)
                    args.append(value)
                    changed |= arg_changed
                else:
                    args.append(arg)
            result = (node.func(*args), True) if changed else (node, False)
        else:
            result = (node, False)
        self._memo[node] = result
        return result


def partial_velocity(velocity: me.Vector, speed, frame: me.ReferenceFrame) -> me.Vector:
    """velocity.diff(speed, frame), the same vector, without differentiating a direction cosine matrix that does
    not hold `speed`.

    Vector.diff differentiates, for each component expressed in another frame, that frame's direction cosine
    matrix relative to `frame` and, if the result is zero, differentiates the component's measure numbers where
    they are (what var_in_dcm=False does throughout). An orientation depends on coordinates, not speeds, so that
    matrix never holds a speed; when it holds none the result is the same, and the test (`has`) costs a walk
    over nine entries instead of nine derivatives. The measure numbers are then differentiated entry by entry, so
    that within memoised_diff an entry shared by the velocities of several loads is differentiated once.
    """
    for _, component_frame in velocity.args:
        if component_frame != frame and frame.dcm(component_frame).has(speed):
            return velocity.diff(speed, frame)
    # velocity.diff(speed, frame, var_in_dcm=False), each measure number differentiated entry by entry (the same
    # entries; a 3-vector's own diff goes through ArrayDerivative and differentiates each entry anew)
    return me.Vector([(measure.applyfunc(lambda entry: entry.diff(speed)), component_frame)
                      for measure, component_frame in velocity.args])


_INFINITIES = (sp.S.Infinity, sp.S.NegativeInfinity, sp.S.ComplexInfinity, sp.S.NaN)


def dot(a: me.Vector, b: me.Vector):
    """a.dot(b) for two vectors, the same expression, without multiplying any expression by zero.

    Vector.dot sums, over the pairs of components (measure numbers m_a in frame A, m_b in frame B), the matrix
    product (m_b^T C_BA) m_a, C_BA the direction cosine matrix; sympy's matrix product multiplies every nonzero
    entry by 0 first to see whether it is infinite (0 * oo is nan), an assumptions query over the whole of a
    large expression. Here the same products and sums are formed in the same order (a row entry is the sum over
    k of m_b[k] C[k, j] for the nonzero pairs, the result the sum over k of row[k] m_a[k], the pairs summed one
    after another from zero) and the check skipped; vectors that hold an infinity or nan take Vector.dot.
    """
    entries = [e for measure, _ in a.args for e in measure] + [e for measure, _ in b.args for e in measure]
    if any(e.has(*_INFINITIES) for e in entries):
        return a.dot(b)
    out = sp.S.Zero
    for m1, f1 in a.args:
        for m2, f2 in b.args:
            dcm = f2.dcm(f1)
            if any(e.has(*_INFINITIES) for e in dcm):
                return a.dot(b)
            row = {}
            for j in range(3):
                terms = [m2[k] * dcm[k, j] for k in range(3) if m2[k] != 0 and dcm[k, j] != 0]
                if terms:
                    total = sp.Add(*terms)
                    if total:
                        row[j] = total
            terms = [row[k] * m1[k] for k in range(3) if k in row and m1[k] != 0]
            out += sp.Add(*terms) if terms else sp.S.Zero
    return out


def generalized_forces(loads, speeds, frame) -> sp.Matrix:
    """Q_r = sum over loads of (partial velocity or partial angular velocity wrt u_r) . (force or torque)."""
    out = sp.zeros(len(speeds), 1)
    for where, vector in loads:
        velocity = where.ang_vel_in(frame) if isinstance(where, me.ReferenceFrame) else where.vel(frame)
        for r, speed in enumerate(speeds):
            partial = partial_velocity(velocity, speed, frame)
            if partial != 0:
                out[r] += dot(partial, vector)
    return out


def build_space(effects: list[Effect], speeds_as_qdot: bool = False) -> ModelSpace:
    """Configure and build the system for `effects` (the hooks run in the order given).

    With `speeds_as_qdot` every speed is written as dq/dt instead of a speed symbol u (for
    LagrangesMethod, which takes partial velocities with respect to dq/dt).
    """
    space = ModelSpace(effects, speeds_as_qdot=speeds_as_qdot)
    for effect in effects:
        effect.configure(space)
    space.build()
    for effect in effects:
        space.bodies += effect.bodies(space)
    return space


def derive(effects: list[Effect]) -> Derivation:
    """Kane's equations and the per-effect generalized forces for the given effects."""
    with memoised_diff():  # Kane's method and the partial velocities differentiate the same terms many times
        return _derive(effects)


def _derive(effects: list[Effect]) -> Derivation:
    import time

    timings = {}
    start = time.perf_counter()
    space = build_space(effects)
    q, u = space.q, space.u
    kane = me.KanesMethod(space.N, q_ind=q, u_ind=u, kd_eqs=[qi.diff(space.t) - ui for qi, ui in zip(q, u)])
    kane.kanes_equations(space.bodies, [])
    mass_matrix = kane.mass_matrix
    forcing_inertia = kane.forcing
    timings["kane_s"] = time.perf_counter() - start

    start = time.perf_counter()
    forces = {"core": generalized_forces(space.core_loads(), u, space.N)}
    for effect in effects:
        forces[effect.name] = generalized_forces(effect.loads(space), u, space.N)
    unit_torque = sp.Symbol("unit_column_torque")
    column_torque = space.kinematics.column_torque
    column_loads = [(where, vector.subs(column_torque, unit_torque)) for where, vector in space.column_loads()]
    column = generalized_forces(column_loads, u, space.N).xreplace({unit_torque: 1})
    potential = space.core_potential_energy() + sum(e.potential_energy(space) for e in effects)
    timings["forces_s"] = time.perf_counter() - start

    return Derivation(
        effects=tuple(e.name for e in effects),
        space=space,
        coordinate_names=[c.name for c in space.coordinates],
        coordinate_units=[c.unit for c in space.coordinates],
        parameter_names=list(space.parameter_symbols),
        mass_matrix=mass_matrix,
        forcing_inertia=forcing_inertia,
        generalized_forces=forces,
        column_direction=column,
        potential_energy=potential,
        timings_s=timings,
    )


__all__ = ["Derivation", "Replacer", "derive", "free_symbols", "build_space", "generalized_forces", "INPUT_NAMES"]
