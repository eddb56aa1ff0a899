"""The fixed runtime of the generated models, as one translation unit of its own: ``runtime.c`` (handwheel input,
mass-matrix solves, right-hand side, Jacobian, outputs, the prescribed-rack drive), ``sensitivities.c`` (the forward
sensitivities) and ``integrator.c`` (the stiff integrator), after a prelude that reads the model's dimensions from the
model at run time. It is the same text for every model, so it is compiled once (``compiler.shared_object``) and
linked with each model's generated functions (as is ``boost_table.c`` with each model that has a boost table), which :mod:`.generate` writes with :func:`dimension_exports` after
them. The arithmetic is the same as in one translation unit: no operation depends on whether a dimension is known to
the compiler, and no fused multiply-add is formed at any level (``-ffp-contract=off``). No sympy here: a pre-derived
model compiles without it."""

from __future__ import annotations

import re
from pathlib import Path

HERE = Path(__file__).resolve().parent
RUNTIME_FILES = ("runtime.c", "sensitivities.c", "integrator.c")
PORTABLE_MATH = (HERE / "portable_math.c").read_text(encoding="utf-8")

# Visible to the other translation unit of the model's library, not exported from it.
LOCAL = '__attribute__((visibility("hidden"))) '

# The model's functions the runtime calls, with their C parameters.
MODEL_FUNCTIONS = {
    "eval_mf": "const double *q, const double *u, const double *p, double th, double thd, double *M, double *F",
    "eval_jac": "const double *q, const double *u, const double *a, const double *p, double th, double thd, "
                "double *dFdq, double *dFdu",
    "eval_drive": "const double *q, const double *u, const double *p, double *M, double *F, double *b",
    "eval_outputs": "const double *q, const double *u, const double *a, const double *p, double th, double thd, "
                    "double *out",
    "eval_tangent": "const double *q, const double *u, const double *a, const double *p, double T, double th, "
                    "double thd, int m, const double *dy, const double *const *dps, double *dG, double *dH",
}
# The model functions compiled without optimisation: their long straight-line bodies (eval_tangent's chain rule,
# eval_jac's derivatives) are most of the compiler's time a model, which every first use of a model waits for, and
# little of a replay's, which goes to eval_drive, eval_mf, eval_outputs, the stiff integrator and the portable math
# (optimised: eval_mf or eval_outputs unoptimised would cost a benchmark job 2-3 % each for 0.03-0.07 s of compile).
# The arithmetic is the same at any level: no fused multiply-add is formed (-ffp-contract=off), and nothing is
# reordered or carried in another precision without -ffast-math.
UNOPTIMISED = '__attribute__((optimize("O0"))) '
COMPILED_UNOPTIMISED = frozenset({"eval_jac", "eval_tangent"})
# The macro under which a model's eval_tangent is compiled. Only the optional exact Jacobians integrate sensitivities,
# so a model's library is compiled without it (a stub, PS_SENSITIVITIES 0: a third less of the compiler's time a
# model) and a second library with it on first use (compiler.tangent_library).
WITH_TANGENT = "PS_WITH_TANGENT"
# The dimensions a model's header defines and the runtime reads from it.
DIMENSIONS = ("NQ", "NY", "NOUT", "INPUT_OFFSET", "MAX_PIECES", "RACK", "OUT_COLUMN_ANGLE", "OUT_COLUMN_TORQUE",
              "PS_SENSITIVITIES")
LIBM = {"sin", "cos", "tan", "asin", "acos", "atan", "atan2", "sinh", "cosh", "tanh", "asinh", "acosh", "atanh", "exp",
        "exp2", "expm1", "log", "log2", "log10", "log1p", "pow", "cbrt", "hypot", "erf", "erfc", "tgamma", "lgamma",
        "fma"}


def check_portable(source: str) -> None:
    """Refuse C that calls a C-library function whose last bit depends on the machine (portable_math.c has them)."""
    bad = sorted(set(re.findall(r"(?<![A-Za-z_0-9.])([a-z][a-z0-9]*)\(", source)) & LIBM)
    if bad:
        raise RuntimeError(f"generated C calls {', '.join(bad)} from the C library; route it through portable_math.c")


def model_function(name: str, lines: list[str]) -> str:
    """The C definition of the model function `name` (one of MODEL_FUNCTIONS) with the body `lines`."""
    body = "\n".join(lines)
    prefix = UNOPTIMISED if name in COMPILED_UNOPTIMISED else ""
    return f"{prefix}{LOCAL}void {name}({MODEL_FUNCTIONS[name]})\n{{\n{body}\n}}\n"


def dimension_exports() -> str:
    """The C that ends a model's generated file: its dimensions as constants the runtime reads."""
    lines = [f"{LOCAL}const int ps_dim_{name.lower()} = {name};" for name in DIMENSIONS]
    return "\n/* ---- the dimensions the runtime (compiled apart, linked in) reads ---- */\n" + "\n".join(lines) + "\n"


def runtime_source() -> str:
    """The runtime's translation unit: each dimension a constant of the model it is linked with, each model function
    declared."""
    prelude = ["/* The runtime of the generated models (parksteer.model.codegen.runtime); do not edit. */",
               "#include <math.h>", "#include <string.h>", "", PORTABLE_MATH]
    for name in DIMENSIONS:
        prelude += [f"extern {LOCAL}const int ps_dim_{name.lower()};", f"#define {name} ps_dim_{name.lower()}"]
    prelude += [f"{LOCAL}void {name}({args});" for name, args in MODEL_FUNCTIONS.items()]
    source = "\n".join(prelude) + "\n" + "".join("\n" + (HERE / f).read_text(encoding="utf-8") for f in RUNTIME_FILES)
    check_portable(source)
    return source


# boost_table.c: the boost table's law and slope, the same text for every model with a boost table (an assist's), so
# compiled once like the runtime; generate.table_functions_source prints it from the law in sympy.
BOOST_TABLE_FILE = HERE / "boost_table.c"


def boost_table_source() -> str:
    return BOOST_TABLE_FILE.read_text(encoding="utf-8")


# The C compiled once per cache and compiler and linked with the models that name it: what it is, and its text.
# Every model links the runtime; a model's description lists the others it needs ("shared_objects").
SHARED_OBJECTS = {"runtime": ("the models' runtime", runtime_source),
                  "boost_table": ("the boost table's law", boost_table_source)}
