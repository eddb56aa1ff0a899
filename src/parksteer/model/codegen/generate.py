"""C code for one derived model: mass matrix, forcing, analytic Jacobian, outputs.

The generated file holds the functions written from the sympy expressions (after common-subexpression
elimination) and the model's dimensions; the fixed runtime they are linked with (handwheel input, Cholesky solve of
the symmetric positive definite mass matrix, right-hand side, Jacobian, batched outputs, the stiff integrator:
``ps_integrate``, a whole handwheel-driven run in one call) is the same for every model and compiled once
(:mod:`.runtime`). Every parameter is read from the vector ``p`` at run time.

The Jacobian of y' = (u, M^-1 f) is assembled from generated partial derivatives:
d(M^-1 f)/dq = M^-1 (df/dq - d(M a)/dq |a fixed), d(M^-1 f)/du = M^-1 df/du, a = M^-1 f.
Those partial derivatives are taken through the common subexpressions of f and M a (forward mode, one
chain-rule line per intermediate and variable it depends on), not by differentiating the expanded
expressions: the same numbers, a fraction of the sympy time, and the shared terms shared in the C too.
"""

from __future__ import annotations

import time

import sympy as sp
from sympy.printing.c import C99CodePrinter

from ..symbolic.derive import Derivation, Replacer, free_symbols, memoised_diff
from ...errors import UsageError
from .runtime import (BOOST_TABLE_FILE, LOCAL, PORTABLE_MATH, boost_table_source, check_portable, dimension_exports,
                      model_function)
from .tangent import tangent_function

# The handwheel input is a piecewise-quadratic table in p: count, then (t0, angle0, rate0, accel) per piece.
MAX_INPUT_PIECES = 24
INPUT_FIELDS = 4


# Elementary functions come from portable_math.c (fdlibm, compiled with the model), never from the C library:
# libm's are picked for the CPU at load time and differ in the last bit between machines.
PORTABLE_FUNCTIONS = {"sin": "ps_sin", "cos": "ps_cos", "atan": "ps_atan", "atan2": "ps_atan2", "exp": "ps_exp",
                      "log": "ps_log", "tanh": "ps_tanh"}


class _Printer(C99CodePrinter):
    """C99 printer: small integer and half-integer powers as products and square roots, other powers and the
    elementary functions through portable_math.c."""

    def __init__(self):
        super().__init__({"user_functions": dict(PORTABLE_FUNCTIONS)})

    def _print_Pow(self, expr):
        base, exp = expr.as_base_exp()
        if exp.is_Integer and 2 <= abs(int(exp)) <= 4:
            b = self.parenthesize(base, 100)
            prod = "*".join([b] * abs(int(exp)))
            return f"({prod})" if exp > 0 else f"(1.0/({prod}))"
        if exp == -1:
            return f"(1.0/{self.parenthesize(base, 100)})"
        if exp == sp.Rational(1, 2):
            return f"sqrt({self._print(base)})"
        if exp == sp.Rational(-1, 2):
            return f"(1.0/sqrt({self._print(base)}))"
        if exp == sp.Rational(3, 2):
            b = self._print(base)
            return f"(({b})*sqrt({b}))"
        if exp == sp.Rational(-3, 2):
            b = self._print(base)
            return f"(1.0/(({b})*sqrt({b})))"
        return f"ps_pow({self._print(base)}, {self._print(exp)})"

    def _print_BoostTableLaw(self, expr):
        return self._table_call(TABLE_LAW, expr)

    def _print_BoostTableSlope(self, expr):
        return self._table_call(TABLE_SLOPE, expr)

    def _table_call(self, function: str, expr) -> str:
        """A boost table's law as a call of its printed function (:func:`table_functions_source`): the table's scalars
        are consecutive in p (an effect's quantities in the order of boost_table.table_keys), so the call passes
        their start."""
        torque, speed, *table = expr.args
        names = [str(t) for t in table]
        first = int(names[0][2:-1]) if names[0].startswith("p[") else -1
        if names != [f"p[{first + j}]" for j in range(len(names))]:
            raise ValueError("a boost table's scalars must be consecutive in the parameter vector")
        return f"{function}({self._print(torque)}, {self._print(speed)}, p + {first})"


# The boost table's law and its torque derivative as C functions of (torque, speed, table), printed once from
# parksteer.model.symbolic.effects.assist_common.table_law (the formula the replay evaluates on numbers). The text is
# the same for every model with a boost table, so it is a translation unit of its own, boost_table.c, compiled once
# per cache like the runtime (runtime.SHARED_OBJECTS); a model declares the two functions and calls them.
TABLE_LAW = "ps_boost_law"
TABLE_SLOPE = "ps_boost_slope"
TABLE_ARGUMENTS = "double x, double v, const double *t"


def table_functions_source() -> str:
    """boost_table.c: the C of the boost table's law and slope, table_law and table_slope (its derivative in the
    torque) on symbols x (torque), v (speed) and t[j] (the table's scalars in boost_table.table_keys order), each
    after common-subexpression elimination. `parksteer derive --prebuilt` writes it beside the runtime's C, and a
    model derived here checks it is what the shipped file holds (:func:`generate`)."""
    from ...boost_table import table_keys
    from ..symbolic.effects.assist_common import table_law, table_points, table_slope

    printer = _Printer()
    x, v = sp.Symbol("x", real=True), sp.Symbol("v", real=True)
    table = {key: sp.Symbol(f"t[{j}]", real=True) for j, key in enumerate(table_keys())}
    points = table_points(table.__getitem__, v)
    out = ["/* The boost table's law and slope (parksteer.model.codegen.generate.table_functions_source, from the law of\n"
           "   parksteer.model.symbolic.effects.assist_common); do not edit: `parksteer derive --prebuilt` writes it. */\n"]
    for name, expr in ((TABLE_LAW, table_law(x, None, v, points)), (TABLE_SLOPE, table_slope(x, None, v, points))):
        body = ["    double value;", *_c_block([("value", expr)], printer), "    return value;"]
        out.append(f"{LOCAL}double {name}({TABLE_ARGUMENTS})\n{{\n" + "\n".join(body) + "\n}\n")
    source = "\n".join(out)
    check_portable(source)
    return source


def _table_declarations() -> str:
    """The boost table's functions as a model declares them (boost_table.c defines them), once the shipped file is
    found to be what this package prints."""
    if table_functions_source() != boost_table_source():
        raise UsageError(f"{BOOST_TABLE_FILE} is not the boost table's law as this package prints it: write it again "
                         "with `parksteer derive --prebuilt` in the checkout")
    return "".join(f"{LOCAL}double {name}({TABLE_ARGUMENTS});\n" for name in (TABLE_LAW, TABLE_SLOPE))


def _c_block(assignments: list[tuple[str, sp.Expr]], printer: _Printer) -> list[str]:
    """Lines assigning each target, sharing common subexpressions."""
    exprs = [e for _, e in assignments]
    replacements, reduced = sp.cse(exprs, symbols=sp.numbered_symbols("x"), order="none")
    lines = [f"    const double {sym} = {printer.doprint(val)};" for sym, val in replacements]
    lines += [f"    {target} = {printer.doprint(val)};" for (target, _), val in zip(assignments, reduced)]
    return lines


def _derivative_block(expressions: list[sp.Expr], variables: list[sp.Symbol], targets, printer: _Printer
                      ) -> list[str]:
    """Lines assigning d(expressions[i])/d(variables[j]) to targets[i][j], by the chain rule through the
    common subexpressions: for x_k = e_k(x_<k, v), dx_k/dv = de_k/dv + sum over x_m in e_k of de_k/dx_m dx_m/dv.

    Every intermediate and every nonzero derivative gets its own line, so no expression is ever expanded; the
    C compiler then sees the shared terms once. Subexpression symbols are real, so |x|' is sign(x).
    """
    replacements, reduced = sp.cse(expressions, symbols=sp.numbered_symbols("x", real=True), order="none")
    wanted = set(variables)
    lines = [f"    const double {sym} = {printer.doprint(val)};" for sym, val in replacements]
    derivative: dict[sp.Symbol, dict[sp.Symbol, sp.Symbol]] = {}  # x_k -> {v: symbol of dx_k/dv}
    names = sp.numbered_symbols("dx", real=True)

    def gradient(expr: sp.Expr) -> dict[sp.Symbol, sp.Expr]:
        # The terms of each derivative are summed at once: a sum is canonical (its terms sorted and collected),
        # the same expression in whatever order they come (the free symbols' order changes from run to run).
        terms: dict[sp.Symbol, list[sp.Expr]] = {}
        if isinstance(expr, sp.logic.boolalg.Boolean):  # a condition (x > 0) shared by cse: piecewise constant
            return {}
        for arg in expr.free_symbols:
            if arg in wanted:
                terms.setdefault(arg, []).append(sp.diff(expr, arg))
            elif arg in derivative:
                outer = sp.diff(expr, arg)
                for v, d in derivative[arg].items():
                    terms.setdefault(v, []).append(outer * d)
        total = {v: sp.Add(*parts) for v, parts in terms.items()}
        return {v: d for v, d in total.items() if d != 0}

    with memoised_diff():
        for sym, val in replacements:
            grads = gradient(val)
            if grads:
                derivative[sym] = {}
                for v in variables:  # in the variables' order, so the file is the same on every run
                    if v in grads:
                        name = next(names)
                        derivative[sym][v] = name
                        lines.append(f"    const double {name} = {printer.doprint(grads[v])};")
        for row, expr in zip(targets, reduced):
            grads = gradient(expr)
            lines += [f"    {target} = {printer.doprint(grads.get(v, sp.S.Zero))};"
                      for target, v in zip(row, variables)]
    return lines


def _outputs(derivation: Derivation, c: Replacer, M, a: list, rack: int) -> tuple[list, list]:
    """The outputs eval_outputs writes, (name, expression in C symbols), and those of them the effects declare."""
    space = derivation.space
    n = len(space.coordinates)
    dcol = c(space.kinematics.column_angle_per_rack)
    outputs: list[tuple[str, sp.Expr]] = [
        ("column_angle_rad", c(space.kinematics.column_angle)),
        ("column_angle_per_rack_rad_per_m", dcol),
        ("column_torque_Nm", c(space.kinematics.column_torque)),
        ("load_left_N", c(space.kinematics.wheel_load["left"])),
        ("load_right_N", c(space.kinematics.wheel_load["right"])),
        ("steer_left_rad", c(space.kinematics.steer_angle["left"])),
        ("steer_right_rad", c(space.kinematics.steer_angle["right"])),
        ("ring_yaw_rate_left_rad_s", c(space.kinematics.ring_frame["left"].ang_vel_in(space.N).dot(space.N.z))),
        ("ring_yaw_rate_right_rad_s", c(space.kinematics.ring_frame["right"].ang_vel_in(space.N).dot(space.N.z))),
    ]
    for name in derivation.effects:
        outputs.append((f"contrib_{name}_Nm", -c(derivation.generalized_forces[name][rack]) / dcol))
    inertia_row = sum(M[rack, j] * a[j] for j in range(n))
    outputs.append((
        "contrib_inertia_Nm",
        (inertia_row - c(derivation.forcing_inertia[rack]) - c(derivation.generalized_forces["core"][rack])) / dcol,
    ))
    outputs += [
        ("kinetic_energy_J", c(space.kinetic_energy())),
        ("potential_energy_J", c(derivation.potential_energy)),
        ("column_energy_J", c(space.column_potential_energy())),
    ]
    effect_outputs = [(name, c(expr)) for effect in space.effects for name, expr in effect.outputs(space)]
    taken = {name for name, _ in outputs}
    for name, _ in effect_outputs:
        if name in taken:
            raise ValueError(f"output {name} is given twice (an effect's outputs must have names of their own)")
        taken.add(name)
    outputs += effect_outputs
    return outputs, effect_outputs


def _header(info: dict, n: int) -> str:
    """The generated file's head: the portable math and the model's dimensions, from its description `info`."""
    return (
        "/* Generated by parksteer.model.codegen.generate from the sympy derivation; do not edit. */\n"
        "#include <math.h>\n#include <string.h>\n\n" + PORTABLE_MATH + "\n"
        f"#define NQ {n}\n#define NY {2 * n}\n#define NOUT {len(info['outputs'])}\n"
        f"#define INPUT_OFFSET {info['input_offset']}\n#define MAX_PIECES {MAX_INPUT_PIECES}\n"
        f"#define RACK {info['rack_index']}\n#define OUT_COLUMN_ANGLE {info['outputs'].index('column_angle_rad')}\n"
        f"#define OUT_COLUMN_TORQUE {info['outputs'].index('column_torque_Nm')}\n\n"
    )


def generate(derivation: Derivation) -> tuple[str, dict]:
    """C source of the model and its description (state names, parameter order, output names)."""
    timings = {}
    start = time.perf_counter()
    space = derivation.space
    n = len(space.coordinates)
    printer = _Printer()
    plain = derivation.plain_symbols()
    for i, name in enumerate(derivation.parameter_names):
        plain[space.parameter_symbols[name]] = sp.Symbol(f"p[{i}]", real=True)
    plain[space.handwheel_angle] = sp.Symbol("th", real=True)
    plain[space.handwheel_rate] = sp.Symbol("thd", real=True)
    # every expression in C symbols through one Replacer: the matrices and outputs share their kinematic terms
    c = Replacer(plain)

    q = [plain[x] for x in space.q]
    u = [plain[x] for x in space.u]
    a = [sp.Symbol(f"a[{i}]", real=True) for i in range(n)]
    M = c(derivation.mass_matrix)
    F = c(derivation.forcing)
    F_nocol = c(derivation.forcing_inertia + sum(derivation.generalized_forces.values(), sp.zeros(n, 1)))
    bcol = c(derivation.column_direction)

    mf = [(f"M[{i * n + j}]", M[i, j]) for i in range(n) for j in range(i, n)]
    mf += [(f"F[{i}]", F[i]) for i in range(n)]
    # F - M a with a held fixed: its q-derivative is df/dq - d(M a)/dq, its u-derivative df/du.
    residual = [F[i] - sum(M[i, j] * a[j] for j in range(n)) for i in range(n)]
    jac_targets = [[f"dFdq[{i * n + j}]" for j in range(n)] + [f"dFdu[{i * n + j}]" for j in range(n)]
                   for i in range(n)]
    drive = [(f"M[{i * n + j}]", M[i, j]) for i in range(n) for j in range(i, n)]
    # The prescribed-rack drive takes the column torque as its unknown, so the forcing without the column must not
    # hold it; an effect that feeds the column torque back (a power assist's torsion bar) is driven by the
    # handwheel only, and its drive is written at zero handwheel input (prescribed.solve refuses it).
    hand = {plain[space.handwheel_angle], plain[space.handwheel_rate]}
    seen: dict = {}  # free symbols of each node, found once across the rows (they share their terms)
    drive_hand = any(free_symbols(F_nocol[i], seen) & hand for i in range(n))
    if drive_hand:
        F_nocol = Replacer({h: 0 for h in hand})(F_nocol)
    drive += [(f"F[{i}]", F_nocol[i]) for i in range(n)] + [(f"b[{i}]", bcol[i]) for i in range(n)]
    timings["expressions_s"] = time.perf_counter() - start

    rack = space.coordinates.index(next(cc for cc in space.coordinates if cc.name == "rack"))
    outputs, effect_outputs = _outputs(derivation, c, M, a, rack)
    out_assign = [(f"out[{i}]", e) for i, (_, e) in enumerate(outputs)]

    start = time.perf_counter()
    parts = [
        model_function("eval_mf", _c_block(mf, printer)),
        model_function("eval_jac", _derivative_block(residual, q + u, jac_targets, printer)),
        model_function("eval_drive", _c_block(drive, printer)),
        model_function("eval_outputs", _c_block(out_assign, printer)),
    ]
    parts.append(tangent_function(derivation, plain, F_nocol, F, M, bcol, a, printer, drive_hand))  # tangent.py
    boost_table = any(f"{TABLE_LAW}(" in part or f"{TABLE_SLOPE}(" in part for part in parts)
    if boost_table:
        parts.insert(0, _table_declarations())
    timings["cse_derivatives_print_s"] = time.perf_counter() - start
    n_params = len(derivation.parameter_names)
    info = {
        "effects": list(derivation.effects),
        "coordinates": derivation.coordinate_names,
        "coordinate_units": derivation.coordinate_units,
        "coordinate_owners": [cc.owner for cc in space.coordinates],
        "parameters": derivation.parameter_names,
        "input_offset": n_params,
        "max_input_pieces": MAX_INPUT_PIECES,
        "n_parameter_vector": n_params + 1 + INPUT_FIELDS * MAX_INPUT_PIECES,
        "outputs": [name for name, _ in outputs],
        "effect_outputs": [name for name, _ in effect_outputs],
        "rack_drive": not drive_hand,
        "rack_index": rack,
    }
    if boost_table:
        info["shared_objects"] = ["boost_table"]
    source = _header(info, n) + "\n".join(parts) + dimension_exports()
    check_portable(source)
    return source, {**info, "codegen_timings_s": timings}
