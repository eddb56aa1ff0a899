"""The forward sensitivities' part of the generated C: eval_tangent, the directional derivative of the prescribed-rack
residual and of the full forcing along run-time directions of the coordinates, speeds and parameters (forward mode
through the common subexpressions), and the runtime that makes the reduced system's tangent of it
(``sensitivities.c``: ps_prescribed_tangent, ps_forcing_tangent). A directional derivative, not a dF/dp block of a
listed subset: any parameter a fit names has its sensitivity without a re-derivation, and the code's size does not
grow with the number of parameters. Used by :mod:`.generate`; the integration of the sensitivities is
``integrator.c``'s."""

from __future__ import annotations

import sympy as sp

from ..symbolic.derive import Derivation, memoised_diff
from .runtime import WITH_TANGENT, model_function

# A model without the tangent: the runtime's sensitivities return -1 (PS_SENSITIVITIES 0) and never call the stub.
NO_TANGENT = "#define PS_SENSITIVITIES 0\n" + model_function(
    "eval_tangent", ["    (void)q; (void)u; (void)a; (void)p; (void)T; (void)th; (void)thd; (void)m; (void)dy; "
                     "(void)dps; (void)dG; (void)dH;"])

def _directional_block(expressions: list[sp.Expr], directions: dict[sp.Symbol, sp.Symbol], targets: list[str],
                       printer, loop: str) -> list[str]:
    """Lines assigning the directional derivative of expressions[i] along `directions` (each variable's direction
    symbol) to targets[i], forward mode through the common subexpressions: for x_k = e_k(x_<k, v),
    dx_k = sum over v in e_k of de_k/dv dv + sum over x_m in e_k of de_k/dx_m dx_m, one line per intermediate
    that depends on a variable. The values are computed once; the derivative lines sit in the C `loop` header's
    body (`loop` opens it), once per direction. Subexpression symbols are real, so |x|' is sign(x)."""
    replacements, reduced = sp.cse(expressions, symbols=sp.numbered_symbols("x", real=True), order="none")
    lines = [f"    const double {sym} = {printer.doprint(val)};" for sym, val in replacements]
    lines.append(f"    {loop}")
    tangent: dict[sp.Symbol, sp.Symbol] = {}
    names = sp.numbered_symbols("dx", real=True)

    def along(expr: sp.Expr) -> sp.Expr:
        # a condition shared by cse is piecewise constant (a Symbol is a Boolean too in sympy: not that test)
        if isinstance(expr, (sp.logic.boolalg.BooleanFunction, sp.logic.boolalg.BooleanAtom, sp.core.relational.Relational)
                      ):
            return sp.S.Zero
        # summed at once: a sum is canonical, the same expression in whatever order the free symbols come
        terms = [sp.diff(expr, arg) * (directions.get(arg) or tangent[arg])
                 for arg in expr.free_symbols if arg in directions or arg in tangent]
        return sp.Add(*terms)

    with memoised_diff():
        for sym, val in replacements:
            derivative = along(val)
            if derivative != 0:
                tangent[sym] = next(names)
                lines.append(f"        const double {tangent[sym]} = {printer.doprint(derivative)};")
        lines += [f"        {target} = {printer.doprint(along(expr))};" for target, expr in zip(targets, reduced)]
    lines.append("    }")
    return lines


def tangent_function(derivation: Derivation, plain: dict, F_drive, F_full, M, bcol, a, printer, drive_hand: bool
                     ) -> str:
    """eval_tangent: along m directions (dq, du, dp: the coordinates', speeds' and parameters'), the derivatives of
    the prescribed-rack residual G = F_drive + b T - M a (the column torque T and the accelerations a held) and of
    the full forcing F (the statics' residual, at the handwheel input th, thd), the directions' values computed
    once. The forward sensitivities of the prescribed-rack solve are made of them (sensitivities.c's
    ps_prescribed_tangent, ps_forcing_tangent). It is compiled only where the macro WITH_TANGENT is defined
    (:func:`.compiler.tangent_library`): the model's own library, which every replay loads, has the stub instead."""
    if drive_hand:  # an assist's drive, written at zero handwheel input, has no sensitivities
        return NO_TANGENT
    space = derivation.space
    n = len(space.coordinates)
    torque = sp.Symbol("T", real=True)
    directions = {plain[x]: sp.Symbol(f"dq[{i}]", real=True) for i, x in enumerate(space.q)}
    directions.update({plain[x]: sp.Symbol(f"du[{i}]", real=True) for i, x in enumerate(space.u)})
    directions.update({sp.Symbol(f"p[{i}]", real=True): sp.Symbol(f"dp[{i}]", real=True)
                       for i in range(len(derivation.parameter_names))})
    residual = [F_drive[i] + bcol[i] * torque - sum(M[i, j] * a[j] for j in range(n)) for i in range(n)]
    targets = [f"dG[k * NQ + {i}]" for i in range(n)] + [f"dH[k * NQ + {i}]" for i in range(n)]
    loop = ("for (int k = 0; k < m; k++) {\n        const double *dq = dy + k * NY, *du = dq + NQ, *dp = dps[k];"
            "\n        (void)dq; (void)du; (void)dp;")  # the loop's head and the direction's arrays
    lines = _directional_block(residual + list(F_full), directions, targets, printer, loop)
    return (f"#ifdef {WITH_TANGENT}\n#define PS_SENSITIVITIES 1\n" + model_function("eval_tangent", lines)
            + f"#else\n{NO_TANGENT}#endif\n")
