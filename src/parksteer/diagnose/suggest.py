"""A starting effect: from the residual's signature, a user-effect file with the form it points to, fitted.

The signature (:mod:`parksteer.diagnose.signature`) names a class and a shape along one axis. The suggested
effect is that shape as a mechanism of the model, in the format of ``examples/user_effect/``: one module that
defines ``EFFECT`` (a :class:`parksteer.model.symbolic.components.Effect`) with its own quantities, which a user
reads, edits, and passes back with ``--effects=+FILE.py``. Its magnitude is a sum of knot strengths ``a_k``
times smooth bumps ``exp(-((z - c_k) / h)^2)`` along the axis the signature found (the knots its best basis
used), written as sympy expressions code generation takes (exp, tanh, sin, cos; no Piecewise),
one form per class of the signature.

:func:`suggest` returns the error before and after in noise floors and the BIC gain over the calibrated model. The
derivation, its reasoning and its sources: docs/signature.md, "The suggested effect's forms and fit
(`parksteer.diagnose.suggest`)".
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from ..errors import UsageError
from ..model.symbolic.shapes import FORCE_BOUND_N, TORQUE_BOUND_NM, shape_effect
from ..tables import atomic_path
from .calibrate import calibration_parameters
from .fitting import Fit, least_squares
from .engine import ReplayEngine
from .problem import Problem
from .statistics import bic_gain, effective_samples, fit_statistics, lag1_autocorrelation
from .settings import DEFAULT_SETTINGS, DiagnosisSettings
from .signature import COLUMN_CLASSES, Signature



@dataclass(frozen=True)
class Suggestion:
    """A written effect and how far it takes the error: weighted RMS over the noise floor, before (the calibrated
    base model) and after (with the effect, its strengths and the calibrated parameters fitted together)."""

    effect_name: str
    effect_class: str
    path: str | None
    source: str
    strengths: dict[str, float]
    before_over_floor: float
    after_over_floor: float
    delta_bic: float
    fit: Fit | None = None

    def as_dict(self) -> dict:
        return {"effect": self.effect_name, "class": self.effect_class, "path": self.path,
                "strengths": self.strengths, "before_over_floor": self.before_over_floor,
                "after_over_floor": self.after_over_floor, "delta_bic": self.delta_bic}


def _tuple(values) -> str:
    return "(" + ", ".join(repr(float(v)) for v in values) + ("," if len(values) == 1 else "") + ")"


def effect_source(signature: Signature, fitted: dict[str, float] | None = None, speed_90_m_s: float | None = None
                  ) -> str:
    """The text of the effect file for `signature`'s class and shape (docs/signature.md)."""
    if signature.effect_class is None or signature.best is None:
        raise UsageError("suggest: the residual shows no structure beyond the noise; there is no effect to suggest")
    kind, best = signature.effect_class, signature.best
    name = f"suggested_{kind}"
    if kind in COLUMN_CLASSES:
        keys = [f"{name}.{f}{m}" for m in best.orders for f in ("sin", "cos")]
        unit, bound = "N m", TORQUE_BOUND_NM
    else:
        count = max(len(best.knots), 1)
        keys = [f"{name}.s{k}" for k in range(count)]
        unit, bound = "N", FORCE_BOUND_N
    fitted_line = ""
    if fitted:
        fitted_line = ("\nFitted with the calibrated parameters on the records it was suggested for, the strengths "
                       "take\nthe weighted RMS error from {before:.2f} to {after:.2f} noise floors; those values "
                       "(START) are the\nfile's defaults and the start of the fit.\n")
    header = f'''"""Suggested by parksteer diagnose --suggest-effect from the residual's signature: {signature.sentence}.

A {kind} effect (class {kind!r} of parksteer.diagnose.signature), its magnitude shaped by {len(keys)} strength(s)
along the axis the signature found. The strengths are free (``free=True``, within +-{bound:g} {unit}): passed back as
it stands, ``parksteer diagnose RUN.csv --effects=+THIS_FILE.py`` fits them together with the calibrated parameters
and gives its verdict on the model with this effect (``parksteer compare`` fits them too). Edit the form as the
physics you know suggests.
{{fitted}}"""

from __future__ import annotations

import sympy as sp

from parksteer.model.symbolic.components import Effect
from parksteer.model.symbolic.system import action_reaction, torque_between
from parksteer.parameters import Quantity

NAME = {name!r}
STRENGTHS = {tuple(keys)!r}
# The strengths fitted with the calibrated parameters on the records the file was suggested for: the defaults, and
# the start of the fit when the file is passed back.
START = {{fitted_values}}
'''
    if kind == "dissipative_column":
        body = dissipative_column_body(best.orders, bound)
    elif kind == "column":
        body = f'''ORDERS = {tuple(best.orders)!r}  # per column turn


class Suggested(Effect):
    name = NAME
    description = "Suggested: a torque on the column, sum of sin and cos of the column angle times " + ", ".join(
        str(m) for m in ORDERS) + " (per turn); 0 = absent"
    in_default_set = False
    diagnosis_candidate = False
    quantities = tuple(Quantity(key, "N m", -{bound!r}, {bound!r}, lower_inclusive=True,
                                default=START.get(key, 0.0), free=True,
                                source="suggested from the residual's signature; 0 = absent") for key in STRENGTHS)
    uses = STRENGTHS

    def loads(self, model):
        k = model.kinematics
        theta = k.column_angle
        torque = sum(model.p(f"{{NAME}}.sin{{m}}") * sp.sin(m * theta) + model.p(f"{{NAME}}.cos{{m}}") * sp.cos(m * theta)
                     for m in ORDERS)
        return torque_between(torque, k.B.y, k.column_frame, k.B)
'''
    else:
        if kind == "speed":
            knots, width = best.knots, best.width
            coordinate = "v * sp.tanh(beta * v) / SPEED_SCALE_M_S"
            scale = round(float(speed_90_m_s or 0.05), 3)
            extra = f"SPEED_SCALE_M_S = {scale!r}  # 90th percentile of the rack speed, to 1 mm/s\n"
            what = "sign(v) times a shape in the rack speed magnitude"
        else:
            knots, width = best.knots, best.width
            coordinate = "model.rack_q"
            extra = ""
            what = {"dissipative": "sign(v) times a shape along the rack position",
                    "direction": "sign(v)^2 (moving, either way) times a shape along the rack position",
                    "elastic": "a shape along the rack position"}[kind]
        if knots:
            shape = (f"sum(model.p(key) * sp.exp(-((z - c) / WIDTH) ** 2) for key, c in zip(STRENGTHS, KNOTS))")
            extra += f"KNOTS = {_tuple(knots)}  # along the axis\nWIDTH = {float(width)!r}\n"
        else:
            shape = "model.p(STRENGTHS[0])"
        factor = {"dissipative": " * sp.tanh(beta * v)", "speed": " * sp.tanh(beta * v)",
                  "direction": " * sp.tanh(beta * v) ** 2", "elastic": ""}[kind]
        body = f'''{extra}

class Suggested(Effect):
    name = NAME
    description = "Suggested: a force on the rack, {what}; 0 = absent"
    in_default_set = False
    diagnosis_candidate = False
    quantities = tuple(Quantity(key, "N", -{bound!r}, {bound!r}, lower_inclusive=True,
                                default=START.get(key, 0.0), free=True,
                                source="suggested from the residual's signature; 0 = absent") for key in STRENGTHS)
    uses = STRENGTHS + ("steering.friction_smoothing",)

    def loads(self, model):
        k = model.kinematics
        v = model.rack_u
        beta = model.p("steering.friction_smoothing")
        z = {coordinate}
        force = ({shape}){factor}
        # Between rack and housing: equal and opposite on the rack and on the body.
        return action_reaction(k.rack_point, -force * k.B.y, k.rack_housing_point)
'''
    text = header + body + "\n\nEFFECT = Suggested()\n"
    values = "{" + ", ".join(f"{k!r}: {fitted[k]!r}" for k in keys) + "}" if fitted else "{}"
    text = text.replace("{fitted_values}", values)
    return text.replace("{fitted}", fitted_line.format(before=fitted.get("_before", math.nan),
                                                         after=fitted.get("_after", math.nan)) if fitted else "")


def dissipative_column_body(orders: tuple[int, ...], bound: float) -> str:
    """The effect class of a friction on the column shaft periodic in the column angle: a torque between column
    and body, ``-tanh(beta v) sum_m a_m sin(m theta_c) + b_m cos(m theta_c)``, reversing with the motion (the
    column turns with the rack, so the rack speed's smoothed sign is the column's)."""
    return f'''ORDERS = {tuple(orders)!r}  # per column turn


class Suggested(Effect):
    name = NAME
    description = ("Suggested: a friction torque on the column, sign(v) times a sum of sin and cos of the column "
                   "angle times " + ", ".join(str(m) for m in ORDERS) + " (per turn); 0 = absent")
    in_default_set = False
    diagnosis_candidate = False
    quantities = tuple(Quantity(key, "N m", -{bound!r}, {bound!r}, lower_inclusive=True,
                                default=START.get(key, 0.0), free=True,
                                source="suggested from the residual's signature; 0 = absent") for key in STRENGTHS)
    uses = STRENGTHS + ("steering.friction_smoothing",)

    def loads(self, model):
        k = model.kinematics
        theta = k.column_angle
        beta = model.p("steering.friction_smoothing")
        shape = sum(model.p(f"{{NAME}}.sin{{m}}") * sp.sin(m * theta) + model.p(f"{{NAME}}.cos{{m}}") * sp.cos(m * theta)
                    for m in ORDERS)
        # Opposes the motion: the column turns the way the rack moves.
        torque = -sp.tanh(beta * model.rack_u) * shape
        return torque_between(torque, k.B.y, k.column_frame, k.B)
'''


def strength_keys(source: str) -> tuple[str, ...]:
    namespace: dict = {}
    line = next(l for l in source.splitlines() if l.startswith("STRENGTHS = "))
    exec(line, namespace)  # a literal tuple written by effect_source
    return namespace["STRENGTHS"]


def shape_forms(settings: DiagnosisSettings = DEFAULT_SETTINGS) -> list:
    """Every form a suggestion can take under `settings` (the signature's bases,
    :mod:`parksteer.diagnose.signature_axes`): the uniform frictions, the position classes at each knot count, the
    speed class, the column orders and the dissipative x column orders."""
    sig = settings.signature
    forms = [shape_effect("dissipative"), shape_effect("direction")]
    forms += [shape_effect(kind, count) for count in sig.position_knots for kind in ("dissipative", "elastic", "direction")]
    forms.append(shape_effect("speed", sig.speed_knots))
    forms += [shape_effect("column", orders=tuple(o)) for o in (*sig.column_orders, (sig.mesh_order,))]
    forms += [shape_effect("dissipative_column", orders=tuple(o)) for o in sig.combined_orders]
    return forms


def shape_of(signature: Signature, speed_90_m_s: float | None = None):
    """The suggested effect's form (:func:`parksteer.model.symbolic.shapes.shape_effect`) and the values of its
    knots, width and speed scale, those the written file (:func:`effect_source`) has as numbers."""
    kind, best = signature.effect_class, signature.best
    if kind in COLUMN_CLASSES:
        return shape_effect(kind, orders=tuple(best.orders)), {}
    shape = shape_effect(kind, len(best.knots))
    values = {f"{shape.name}.c{k}": float(c) for k, c in enumerate(best.knots)}
    if best.knots:
        values[f"{shape.name}.width"] = float(best.width)
    if kind == "speed":
        values[f"{shape.name}.speed_scale"] = round(float(speed_90_m_s or 0.05), 3)  # as the file writes it
    return shape, values


def suggest(problem: Problem, calibration: Fit, signature: Signature, path: str | Path | None = None,
            settings: DiagnosisSettings = DEFAULT_SETTINGS) -> Suggestion:
    """Write the effect `signature` points to, fit its strengths with the calibrated parameters on `problem`, and
    write it again with the fitted values as its defaults (to `path`, if given). The fit runs on the effect's form
    (:func:`shape_of`: the same terms, its knots given as values), on a replay engine of its own, in line."""
    speed_90 = signature.numbers.get("speed_90_m_s")
    if signature.effect_class == "speed" and speed_90 is None:
        speed_90 = float(np.quantile(np.abs(np.concatenate([f.rack.evaluate(f.replay_time_s)[1]
                                                            for f in problem.files])), 0.9))
    source = effect_source(signature, speed_90_m_s=speed_90)
    keys = strength_keys(source)
    shape, places = shape_of(signature, speed_90)
    shape_keys = [f"{shape.name}.{key.partition('.')[2]}" for key in keys]
    model = sorted([*calibration.effects, shape], key=lambda e: e.name)
    before = fit_statistics(problem, calibration.predictions)
    floor = before["noise_floor_Nm"]
    ratio = problem.params.sections["steering"]["handwheel_to_rack_ratio"]
    column = signature.effect_class in COLUMN_CLASSES
    step = floor if column else floor * ratio  # a strength moving the torque by about a noise floor
    engine = ReplayEngine()
    # the form's strengths are free (calibration_parameters adds them, last), each stepped by about a floor
    parameters = [replace(p, step=step) if p.key in shape_keys else p
                  for p in calibration_parameters(engine, problem, model, settings=settings)]
    # from the calibration as it stands (its own theta, not a value's round trip) and zero strengths
    start = {q.key: t for q, t in zip(calibration.parameters, calibration.theta)}
    theta0 = np.array([start.get(p.key, 0.0) for p in parameters])
    fit = least_squares(engine, problem, model, parameters, theta0, {**calibration.fixed, **places},
                        settings=settings)
    after = fit_statistics(problem, fit.predictions)
    rho = lag1_autocorrelation(problem, fit.weighted)
    n_eff = effective_samples(problem.n, rho)
    gain = bic_gain(calibration.rss, fit.rss, n_eff, len(keys))
    values = fit.values if isinstance(fit.values, dict) else {}
    strengths = {k: float(values.get(s, fit.theta[len(calibration.theta) + i]))
                 for i, (k, s) in enumerate(zip(keys, shape_keys))}
    before_ratio = before["weighted_rms_Nm"] / floor
    after_ratio = after["weighted_rms_Nm"] / floor
    final = effect_source(signature, {**strengths, "_before": before_ratio, "_after": after_ratio}, speed_90)
    if path is not None:
        with atomic_path(path) as tmp:  # complete or absent, whenever the run is stopped
            tmp.write_text(final, encoding="utf-8")
    return Suggestion(f"suggested_{signature.effect_class}", signature.effect_class,
                      str(path) if path is not None else None, final, strengths, float(before_ratio),
                      float(after_ratio), float(gain), fit)
