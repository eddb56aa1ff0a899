"""The shapes a suggested effect takes, as effects whose knots are parameters: one compiled model per form.

A suggested effect (:mod:`parksteer.diagnose.suggest`) is written for its user with its knots, width and speed
scale as numbers in the file: each record gets a file, and each file a model of its own. The fit that sizes it
needs only the form: the class, the number of knots (or the column orders), with the knots' places given as
values. :func:`shape_effect` is that form, its knots (``c<k>``), width and speed scale quantities held at the
values the fit is given, its strengths (``s<k>``; ``sin<m>``, ``cos<m>`` for the column) free, named as the
suggested file names them. The same sum of the same terms as the written file, so the fitted strengths are the
file's (to rounding), and the forms the signature can name are few: each is derived once, and those on the
default car ship pre-derived.

The forms, as in the written file (force on the rack between rack and housing; torque on the column):

- dissipative: ``-tanh(beta v) sum_k s_k exp(-((x - c_k) / w)^2)``; direction: the same with ``tanh(beta v)^2``;
  elastic: without the factor; uniform (no knots): ``s_0`` times the factor;
- speed: ``-tanh(beta v) sum_k s_k exp(-((z - c_k) / w)^2)``, ``z = v tanh(beta v) / v_90``;
- column: ``sum_m sin_m sin(m theta_c) + cos_m cos(m theta_c)``; dissipative x column: that times
  ``-tanh(beta v)``.
"""

from __future__ import annotations

from functools import lru_cache

from ...parameters import Quantity
from .components import Effect, register_effect
from .lazy_sympy import sp
from .system import action_reaction, torque_between

KNOT_CLASSES = ("dissipative", "direction", "elastic", "speed")
TORQUE_FORMS = ("column", "dissipative_column")  # torques on the column, by orders; the others forces, by knots
FORCE_BOUND_N = 20000.0  # a knot's rack force: far above any steering-gear force at parking speed
TORQUE_BOUND_NM = 50.0  # a column torque's amplitude: far above any handwheel torque at parking speed
_FACTOR = {"dissipative": 1, "speed": 1, "direction": 2, "elastic": 0, "dissipative_column": 1, "column": 0}


def shape_name(kind: str, knots: int = 0, orders: tuple[int, ...] = ()) -> str:
    """The form's effect name: ``shape_<class>_<knots>`` (``_uniform`` without knots) or
    ``shape_<class>_<orders joined by _>``."""
    if kind in TORQUE_FORMS:
        return f"shape_{kind}_{'_'.join(str(m) for m in orders)}"
    return f"shape_{kind}_{knots}" if knots else f"shape_{kind}_uniform"


def strength_suffixes(kind: str, knots: int = 0, orders: tuple[int, ...] = ()) -> tuple[str, ...]:
    """The strengths' names after the effect's, in the written file's order."""
    if kind in TORQUE_FORMS:
        return tuple(f"{f}{m}" for m in orders for f in ("sin", "cos"))
    return tuple(f"s{k}" for k in range(max(knots, 1)))


@lru_cache(maxsize=None)
def shape_effect(kind: str, knots: int = 0, orders: tuple[int, ...] = ()) -> Effect:
    """The form of `kind` with `knots` knots (position and speed classes; 0: uniform) or the column `orders`."""
    if kind not in KNOT_CLASSES + TORQUE_FORMS:
        raise ValueError(f"no suggested shape of class {kind!r}")
    name = shape_name(kind, knots, orders)
    column = kind in TORQUE_FORMS
    unit, bound = ("N m", TORQUE_BOUND_NM) if column else ("N", FORCE_BOUND_N)
    strengths = tuple(f"{name}.{s}" for s in strength_suffixes(kind, knots, orders))
    axis_unit = "1" if kind == "speed" else "m"
    places = tuple(f"{name}.c{k}" for k in range(knots)) if not column else ()
    quantities = [Quantity(key, unit, -bound, bound, lower_inclusive=True, default=0.0, free=True,
                           source="a suggested effect's strength; 0 = absent") for key in strengths]
    quantities += [Quantity(key, axis_unit, -10.0, 10.0, lower_inclusive=True, default=0.0,
                            source="a suggested effect's knot, given by its fit") for key in places]
    if places:
        quantities.append(Quantity(f"{name}.width", axis_unit, 0.0, 10.0, default=0.01,
                                   source="a suggested effect's knot spacing, given by its fit"))
    if kind == "speed":
        quantities.append(Quantity(f"{name}.speed_scale", "m/s", 0.0, 10.0, default=0.05,
                                   source="the rack speed's 90th percentile, given by its fit"))
    smoothing = ("steering.friction_smoothing",) if _FACTOR[kind] else ()

    def loads(self, model):
        k = model.kinematics
        v = model.rack_u
        factor = sp.tanh(model.p("steering.friction_smoothing") * v) ** _FACTOR[kind] if _FACTOR[kind] else 1
        if column:
            theta = k.column_angle
            torque = sum(model.p(f"{name}.sin{m}") * sp.sin(m * theta) + model.p(f"{name}.cos{m}") * sp.cos(m * theta)
                         for m in orders)
            # a friction opposes the motion: the column turns the way the rack moves
            return torque_between(-factor * torque if _FACTOR[kind] else torque, k.B.y, k.column_frame, k.B)
        if places:
            z = (v * sp.tanh(model.p("steering.friction_smoothing") * v) / model.p(f"{name}.speed_scale")
                 if kind == "speed" else model.rack_q)
            width = model.p(f"{name}.width")
            shape = sum(model.p(s) * sp.exp(-((z - model.p(c)) / width) ** 2) for s, c in zip(strengths, places))
        else:
            shape = model.p(strengths[0])
        force = shape * factor
        # between rack and housing: equal and opposite on the rack and on the body
        return action_reaction(k.rack_point, -force * k.B.y, k.rack_housing_point)

    cls = type(f"Shape_{name}", (Effect,), {
        "name": name, "in_default_set": False, "diagnosis_candidate": False,
        "description": f"a suggested effect's form: class {kind}, "
                       + (f"orders {', '.join(map(str, orders))}" if column else f"{knots or 'no'} knots"),
        "quantities": tuple(quantities),
        "uses": tuple(q.key for q in quantities) + smoothing,
        "loads": loads, "__module__": __name__,
    })
    return register_effect(cls(), f"suggested shape {name}")
