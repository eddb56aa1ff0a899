"""C code for one derived model: mass matrix, forcing, analytic Jacobian, outputs.

The generated file has three parts: functions written from the sympy expressions (after
common-subexpression elimination), a fixed runtime (handwheel input, Cholesky solve of
the symmetric positive definite mass matrix, right-hand side, Jacobian, batched outputs), and
the stiff integrator of ``integrator.c`` (``ps_integrate``: a whole handwheel-driven run in one call).
Every parameter is read from the vector ``p`` at run time.

The Jacobian of y' = (u, M^-1 f) is assembled from generated partial derivatives:
d(M^-1 f)/dq = M^-1 (df/dq - d(M a)/dq |a fixed), d(M^-1 f)/du = M^-1 df/du, a = M^-1 f.
Those partial derivatives are taken through the common subexpressions of f and M a (forward mode, one
chain-rule line per intermediate and variable it depends on), not by differentiating the expanded
expressions: the same numbers, a fraction of the sympy time, and the shared terms shared in the C too.
"""

from __future__ import annotations

import time
from pathlib import Path

import sympy as sp
from sympy.printing.c import C99CodePrinter

from ..symbolic.derive import Derivation, Replacer, free_symbols, memoised_diff
from .tangent import SENSITIVITY_RUNTIME, tangent_function

# The handwheel input is a piecewise-quadratic table in p: count, then (t0, angle0, rate0, accel) per piece.
MAX_INPUT_PIECES = 24
INPUT_FIELDS = 4


# Elementary functions come from portable_math.c (fdlibm, compiled with the model), never from the C library:
# libm's are picked for the CPU at load time and differ in the last bit between machines.
PORTABLE_FUNCTIONS = {"sin": "ps_sin", "cos": "ps_cos", "atan": "ps_atan", "atan2": "ps_atan2", "exp": "ps_exp",
                      "log": "ps_log", "tanh": "ps_tanh"}
PORTABLE_MATH = (Path(__file__).with_name("portable_math.c")).read_text(encoding="utf-8")


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
        """A boost table's law as a call of its printed function (:func:`_table_functions`): the table's scalars
        are consecutive in p (an effect's quantities in the order of boost_table.table_keys), so the call passes
        their start."""
        torque, speed, *table = expr.args
        names = [str(t) for t in table]
        first = int(names[0][2:-1]) if names[0].startswith("p[") else -1
        if names != [f"p[{first + j}]" for j in range(len(names))]:
            raise ValueError("a boost table's scalars must be consecutive in the parameter vector")
        return f"{function}({self._print(torque)}, {self._print(speed)}, p + {first})"


def check_portable(source: str) -> None:
    """Refuse generated C that calls a C-library function whose last bit depends on the machine."""
    import re

    calls = set(re.findall(r"(?<![A-Za-z_0-9.])([a-z][a-z0-9]*)\(", source))
    libm = {"sin", "cos", "tan", "asin", "acos", "atan", "atan2", "sinh", "cosh", "tanh", "asinh", "acosh",
            "atanh", "exp", "exp2", "expm1", "log", "log2", "log10", "log1p", "pow", "cbrt", "hypot", "erf", "erfc",
            "tgamma", "lgamma", "fma"}
    bad = sorted(calls & libm)
    if bad:
        raise RuntimeError(f"generated C calls {', '.join(bad)} from the C library; route it through portable_math.c")


# The boost table's law and its torque derivative as C functions of (torque, speed, table), printed once from
# parksteer.model.symbolic.effects.assist_common.table_law (the formula the replay evaluates on numbers).
TABLE_LAW = "ps_boost_law"
TABLE_SLOPE = "ps_boost_slope"


def _table_functions(printer: _Printer) -> str:
    """The C of the boost table's law and slope: table_law and table_slope (its derivative in the torque) on symbols
    x (torque), v (speed) and t[j] (the table's scalars in boost_table.table_keys order), each after
    common-subexpression elimination."""
    from ...boost_table import table_keys
    from ..symbolic.effects.assist_common import table_law, table_points, table_slope

    x, v = sp.Symbol("x", real=True), sp.Symbol("v", real=True)
    table = {key: sp.Symbol(f"t[{j}]", real=True) for j, key in enumerate(table_keys())}
    points = table_points(table.__getitem__, v)
    out = []
    for name, expr in ((TABLE_LAW, table_law(x, None, v, points)), (TABLE_SLOPE, table_slope(x, None, v, points))):
        body = ["    double value;", *_c_block([("value", expr)], printer), "    return value;"]
        out.append(f"static double {name}(double x, double v, const double *t)\n{{\n" + "\n".join(body) + "\n}\n")
    return "\n".join(out)


def _c_block(assignments: list[tuple[str, sp.Expr]], printer: _Printer) -> list[str]:
    """Lines assigning each target, sharing common subexpressions."""
    exprs = [e for _, e in assignments]
    replacements, reduced = sp.cse(exprs, symbols=sp.numbered_symbols("x"), order="none")
    lines = [f"    const double {sym} = {printer.doprint(val)};" for sym, val in replacements]
    lines += [f"    {target} = {printer.doprint(val)};" for (target, _), val in zip(assignments, reduced)]
    return lines


def _function(name: str, args: str, lines: list[str]) -> str:
    body = "\n".join(lines)
    return f"static void {name}({args})\n{{\n{body}\n}}\n"


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

    dcol = c(space.kinematics.column_angle_per_rack)
    rack = space.coordinates.index(next(cc for cc in space.coordinates if cc.name == "rack"))
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
    out_assign = [(f"out[{i}]", e) for i, (_, e) in enumerate(outputs)]

    start = time.perf_counter()
    args_mf = "const double *q, const double *u, const double *p, double th, double thd, double *M, double *F"
    parts = [
        _function("eval_mf", args_mf, _c_block(mf, printer)),
        _function("eval_jac", "const double *q, const double *u, const double *a, const double *p, double th, "
                  "double thd, double *dFdq, double *dFdu", _derivative_block(residual, q + u, jac_targets, printer)),
        _function("eval_drive", "const double *q, const double *u, const double *p, double *M, double *F, double *b",
                  _c_block(drive, printer)),
        _function(
            "eval_outputs",
            "const double *q, const double *u, const double *a, const double *p, double th, double thd, double *out",
            _c_block(out_assign, printer),
        ),
    ]
    parts.append(tangent_function(derivation, plain, F_nocol, F, M, bcol, a, printer, drive_hand))  # tangent.py
    if any(f"{TABLE_LAW}(" in part or f"{TABLE_SLOPE}(" in part for part in parts):
        parts.insert(0, _table_functions(printer))
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
    header = (
        "/* Generated by parksteer.model.codegen.generate from the sympy derivation; do not edit. */\n"
        "#include <math.h>\n#include <string.h>\n\n" + PORTABLE_MATH + "\n"
        f"#define NQ {n}\n#define NY {2 * n}\n#define NOUT {len(outputs)}\n"
        f"#define INPUT_OFFSET {n_params}\n#define MAX_PIECES {MAX_INPUT_PIECES}\n"
        f"#define RACK {rack}\n#define OUT_COLUMN_ANGLE {info['outputs'].index('column_angle_rad')}\n"
        f"#define OUT_COLUMN_TORQUE {info['outputs'].index('column_torque_Nm')}\n\n"
    )
    source = header + "\n".join(parts) + RUNTIME + SENSITIVITY_RUNTIME + INTEGRATOR
    check_portable(source)
    return source, {**info, "codegen_timings_s": timings}


# The stiff integrator of the handwheel-driven model (ps_integrate), C kept in a file of its own; it follows the
# runtime in the same translation unit, so it calls ps_rhs and ps_jac directly.
INTEGRATOR = "\n" + (Path(__file__).with_name("integrator.c")).read_text(encoding="utf-8")

RUNTIME = r"""
/* ---- fixed runtime ---------------------------------------------------------------- */

int ps_nq(void) { return NQ; }
int ps_nout(void) { return NOUT; }

/* Handwheel angle and rate from the piecewise-quadratic table in p (constant outside it). */
void ps_handwheel(double t, const double *p, double *th, double *thd)
{
    const double *tab = p + INPUT_OFFSET;
    int n = (int)tab[0], k = 0;
    if (n < 1) { *th = 0.0; *thd = 0.0; return; }
    while (k + 1 < n && t >= tab[1 + 4 * (k + 1)]) k++;
    const double *piece = tab + 1 + 4 * k;
    double dt = t - piece[0];
    if (dt < 0.0) { *th = piece[1]; *thd = 0.0; return; }
    *th = piece[1] + piece[2] * dt + 0.5 * piece[3] * dt * dt;
    *thd = piece[2] + piece[3] * dt;
}

static void fill_lower(double *M)
{
    for (int i = 0; i < NQ; i++)
        for (int j = 0; j < i; j++) M[i * NQ + j] = M[j * NQ + i];
}

/* In-place Cholesky factor (lower) of the symmetric positive definite M; 0 on success. */
static int cholesky(double *M)
{
    for (int j = 0; j < NQ; j++) {
        double d = M[j * NQ + j];
        for (int k = 0; k < j; k++) d -= M[j * NQ + k] * M[j * NQ + k];
        if (!(d > 0.0)) return -1;
        d = sqrt(d);
        M[j * NQ + j] = d;
        for (int i = j + 1; i < NQ; i++) {
            double s = M[i * NQ + j];
            for (int k = 0; k < j; k++) s -= M[i * NQ + k] * M[j * NQ + k];
            M[i * NQ + j] = s / d;
        }
    }
    return 0;
}

/* Solve L L^T x = b for `nrhs` right-hand sides stored as columns of b (row-major, stride ld). */
static void chol_solve(const double *L, double *b, int nrhs, int ld)
{
    for (int c = 0; c < nrhs; c++) {
        for (int i = 0; i < NQ; i++) {
            double s = b[i * ld + c];
            for (int k = 0; k < i; k++) s -= L[i * NQ + k] * b[k * ld + c];
            b[i * ld + c] = s / L[i * NQ + i];
        }
        for (int i = NQ - 1; i >= 0; i--) {
            double s = b[i * ld + c];
            for (int k = i + 1; k < NQ; k++) s -= L[k * NQ + i] * b[k * ld + c];
            b[i * ld + c] = s / L[i * NQ + i];
        }
    }
}

/* Accelerations a = M^-1 F at state y and handwheel (th, thd); leaves the factor in L. */
static int accelerations(const double *y, const double *p, double th, double thd, double *L, double *a)
{
    eval_mf(y, y + NQ, p, th, thd, L, a);
    fill_lower(L);
    if (cholesky(L)) return -1;
    chol_solve(L, a, 1, 1);
    return 0;
}

int ps_rhs(double t, const double *y, const double *p, double *ydot)
{
    double th, thd, L[NQ * NQ];
    ps_handwheel(t, p, &th, &thd);
    memcpy(ydot, y + NQ, NQ * sizeof(double));
    return accelerations(y, p, th, thd, L, ydot + NQ);
}

/* Jacobian d(ydot)/dy, row-major NY x NY. */
int ps_jac(double t, const double *y, const double *p, double *J)
{
    double th, thd, L[NQ * NQ], a[NQ], dFdq[NQ * NQ], dFdu[NQ * NQ], rhs[NQ * 2 * NQ];
    ps_handwheel(t, p, &th, &thd);
    if (accelerations(y, p, th, thd, L, a)) return -1;
    eval_jac(y, y + NQ, a, p, th, thd, dFdq, dFdu);
    for (int i = 0; i < NQ; i++)
        for (int j = 0; j < NQ; j++) {
            rhs[i * 2 * NQ + j] = dFdq[i * NQ + j];
            rhs[i * 2 * NQ + NQ + j] = dFdu[i * NQ + j];
        }
    chol_solve(L, rhs, 2 * NQ, 2 * NQ);
    memset(J, 0, NY * NY * sizeof(double));
    for (int i = 0; i < NQ; i++) {
        J[i * NY + NQ + i] = 1.0;
        for (int j = 0; j < NY; j++) J[(NQ + i) * NY + j] = rhs[i * 2 * NQ + j];
    }
    return 0;
}

/* Forcing F (full, at the handwheel input of time t) for static solves. */
void ps_forcing(double t, const double *y, const double *p, double *F)
{
    double th, thd, M[NQ * NQ];
    ps_handwheel(t, p, &th, &thd);
    eval_mf(y, y + NQ, p, th, thd, M, F);
}

/* Partial derivatives of F (a = 0) for static solves: dF/dq, row-major. */
void ps_forcing_dq(double t, const double *y, const double *p, double *dFdq)
{
    double th, thd, a[NQ], dFdu[NQ * NQ];
    memset(a, 0, sizeof a);
    ps_handwheel(t, p, &th, &thd);
    eval_jac(y, y + NQ, a, p, th, thd, dFdq, dFdu);
}

/* For a prescribed rack: mass matrix (full), forcing without the column, column direction b. */
void ps_drive(const double *y, const double *p, double *M, double *F, double *b)
{
    eval_drive(y, y + NQ, p, M, F, b);
    fill_lower(M);
}

/* Outputs at n samples: handwheel-driven (a computed here) when acc is NULL, else given a and (th, thd). */
int ps_outputs(int n, const double *t, const double *y, const double *acc, const double *hw, const double *p,
               double *out)
{
    for (int k = 0; k < n; k++) {
        const double *yk = y + k * NY;
        double th, thd, L[NQ * NQ], a[NQ];
        if (acc) {
            th = hw[2 * k]; thd = hw[2 * k + 1];
            memcpy(a, acc + k * NQ, sizeof a);
        } else {
            ps_handwheel(t[k], p, &th, &thd);
            if (accelerations(yk, p, th, thd, L, a)) return -1;
        }
        eval_outputs(yk, yk + NQ, a, p, th, thd, out + k * NOUT);
    }
    return 0;
}

/* ---- prescribed rack (parksteer.model.numeric.prescribed) ----------------------------
   The rack follows a piecewise polynomial held in one table: [pieces, order, breaks (pieces + 1),
   coefficients (order x pieces, highest power first, coefficient i of piece k at i * pieces + k)], held at its
   end values outside the breaks. The reduced state z holds the other coordinates, then their speeds. */
#define NO (NQ - 1)

/* Rack position, speed and acceleration at t (Horner with the derivatives alongside). */
void ps_rack(double t, const double *tab, double *r)
{
    int n = (int)tab[0], order = (int)tab[1];
    const double *x = tab + 2, *c = tab + 3 + n;
    if (t < x[0]) t = x[0];
    if (t > x[n]) t = x[n];
    int lo = 0, hi = n + 1;  /* the first break above t */
    while (lo < hi) {
        int mid = (lo + hi) / 2;
        if (t < x[mid]) hi = mid; else lo = mid + 1;
    }
    int k = lo - 1;
    if (k > n - 1) k = n - 1;
    if (k < 0) k = 0;
    double h = t - x[k], position = 0.0, speed = 0.0, accel = 0.0;
    for (int i = 0; i < order; i++) {
        accel = accel * h + 2.0 * speed;
        speed = speed * h + position;
        position = position * h + c[i * n + k];
    }
    r[0] = position; r[1] = speed; r[2] = accel;
}

/* Solve A x = c in place (A n x n row-major, destroyed) by Gaussian elimination with partial pivoting. */
static int lu_solve(double *A, double *c, int n)
{
    for (int j = 0; j < n; j++) {
        int pivot = j;
        for (int i = j + 1; i < n; i++)
            if (fabs(A[i * n + j]) > fabs(A[pivot * n + j])) pivot = i;
        if (!(A[pivot * n + j] != 0.0)) return -1;
        if (pivot != j) {
            for (int k = 0; k < n; k++) { double s = A[j * n + k]; A[j * n + k] = A[pivot * n + k]; A[pivot * n + k] = s; }
            double s = c[j]; c[j] = c[pivot]; c[pivot] = s;
        }
        for (int i = j + 1; i < n; i++) {
            double f = A[i * n + j] / A[j * n + j];
            if (f == 0.0) continue;
            for (int k = j + 1; k < n; k++) A[i * n + k] -= f * A[j * n + k];
            c[i] -= f * c[j];
        }
    }
    for (int i = n - 1; i >= 0; i--) {
        double s = c[i];
        for (int k = i + 1; k < n; k++) s -= A[i * n + k] * c[k];
        c[i] = s / A[i * n + i];
    }
    return 0;
}

/* The full state y from z and the rack at t; the other accelerations and the column torque x (x[NO] the torque)
   from M a = F + b T with the rack's acceleration given; M, b as ps_drive leaves them; r the rack's motion. */
static int prescribed_solve(double t, const double *z, const double *p, const double *rack, double *y, double *x,
                            double *M, double *b, double *r)
{
    double F[NQ], A[NQ * NQ];
    ps_rack(t, rack, r);
    for (int i = 0, j = 0; i < NQ; i++) {
        if (i == RACK) continue;
        y[i] = z[j]; y[NQ + i] = z[NO + j]; j++;
    }
    y[RACK] = r[0]; y[NQ + RACK] = r[1];
    ps_drive(y, p, M, F, b);
    for (int i = 0; i < NQ; i++) {
        for (int j = 0, k = 0; j < NQ; j++) {
            if (j == RACK) continue;
            A[i * NQ + k++] = M[i * NQ + j];
        }
        A[i * NQ + NO] = -b[i];
        x[i] = F[i] - M[i * NQ + RACK] * r[2];
    }
    return lu_solve(A, x, NQ);
}

/* dz/dt of the reduced system. */
int ps_prescribed_rhs(double t, const double *z, const double *p, const double *rack, double *zdot)
{
    double y[NY], x[NQ], M[NQ * NQ], b[NQ], r[3];
    if (prescribed_solve(t, z, p, rack, y, x, M, b, r)) return -1;
    memcpy(zdot, z + NO, NO * sizeof(double));
    memcpy(zdot + NO, x, NO * sizeof(double));
    return 0;
}

/* Jacobian of the reduced system, row-major 2 NO x 2 NO: the full model's, evaluated at a constant handwheel
   input that makes its column torque the prescribed-rack torque (p_jac: the parameters with a unit column spring,
   no damper and one input piece, whose angle is set here), with the rack's row eliminated:
   d a_o / dy = J_o - (h_o / h_rack) J_rack, h = M^-1 b. */
int ps_prescribed_jac(double t, const double *z, const double *p, double *p_jac, const double *rack, double *J)
{
    double y[NY], x[NQ], M[NQ * NQ], b[NQ], r[3], acc[NQ], hw[2] = {0.0, 0.0}, out[NOUT], Jf[NY * NY];
    int reduced[2 * NO];
    if (prescribed_solve(t, z, p, rack, y, x, M, b, r)) return -1;
    for (int i = 0, j = 0; i < NQ; i++) {
        if (i == RACK) { acc[i] = r[2]; continue; }
        acc[i] = x[j]; reduced[j] = i; reduced[NO + j] = NQ + i; j++;
    }
    /* angle = column angle + torque / (unit stiffness); a column law with a dead band (rack lash) passes less
       torque for that twist: widen it by the shortfall, so that the Jacobian is exact whatever the law. */
    ps_outputs(1, &t, y, acc, hw, p_jac, out);
    hw[0] = out[OUT_COLUMN_ANGLE] + x[NO];
    ps_outputs(1, &t, y, acc, hw, p_jac, out);
    p_jac[INPUT_OFFSET + 2] = hw[0] + x[NO] - out[OUT_COLUMN_TORQUE];
    if (ps_jac(t, y, p_jac, Jf)) return -1;
    if (cholesky(M)) return -1;
    chol_solve(M, b, 1, 1);
    memset(J, 0, 4 * NO * NO * sizeof(double));
    for (int i = 0; i < NO; i++) {
        J[i * 2 * NO + NO + i] = 1.0;
        const double *row = Jf + (NQ + reduced[i]) * NY, *rack_row = Jf + (NQ + RACK) * NY;
        double ratio = b[reduced[i]] / b[RACK];
        for (int j = 0; j < 2 * NO; j++)
            J[(NO + i) * 2 * NO + j] = row[reduced[j]] - ratio * rack_row[reduced[j]];
    }
    return 0;
}

/* At m samples (t, z): the full states y (m x NY), accelerations (m x NQ) and column torques. */
int ps_prescribed_samples(int m, const double *t, const double *z, const double *p, const double *rack, double *y,
                          double *acc, double *torque)
{
    for (int k = 0; k < m; k++) {
        double x[NQ], M[NQ * NQ], b[NQ], r[3];
        if (prescribed_solve(t[k], z + k * 2 * NO, p, rack, y + k * NY, x, M, b, r)) return -1;
        for (int i = 0, j = 0; i < NQ; i++) acc[k * NQ + i] = (i == RACK) ? r[2] : x[j++];
        torque[k] = x[NO];
    }
    return 0;
}
"""
