"""A vehicle's power assist: the ``[assist]`` section of a vehicle file, checked against the assist effects.

The vehicle layer reads ``[assist]`` (``type`` and entries of ``{value, unit, source}``) into the section of the
effect its type names (:data:`parksteer.vehicle.ASSIST_EFFECTS`); it cannot know the effects' quantities, which
live in the model. Here, with the effects loaded, every entry is checked against its quantity (unit and bounds),
the assist is checked as a whole (the largest rack force it can give), and the effects spec of a run gains the
assist. :func:`assist_template` writes the section for ``parksteer vehicle new --assist``.
"""

from __future__ import annotations

from ...boost_table import off_keys, table_keys
from ...errors import UsageError
from ...parameters import ParameterError, Parameters
from ...vehicle import ASSIST_EFFECTS, assist_of
from ..symbolic.components import discover_effects

# The largest rack force an assist can give (its motor limit or relief pressure through its gear), N. Rack
# forces at standstill are 3-8 kN for small and medium cars and up to 15 kN for large ones; electric racks are
# rated 6-16 kN (Harrer & Pfeffer, Steering Handbook, Springer 2017, ch. 8). An assist outside these bounds is a
# unit slip (bar for Pa, a reduction per degree) rather than a car.
MAX_ASSIST_RACK_FORCE_RANGE_N = (1.0e3, 3.0e4)


def _quantities(name: str) -> dict:
    effect = discover_effects()[name]
    return {q.name: q for q in effect.quantities}


def check_assist(params: Parameters) -> str | None:
    """The assist effect of `params` (None without one), its entries checked against the effect's quantities and
    the largest rack force it can give checked for plausibility; one-line :class:`ParameterError` otherwise."""
    name = assist_of(params)
    if name is None:
        return None
    path = params.path
    known = _quantities(name)
    for key, value in params.sections[name].items():
        q = known.get(key)
        if q is None:
            raise ParameterError(f"{path}: assist.{key}: unknown key for a {name} (keys: {', '.join(k for k in known if k not in TABLE_KEYS)}, and the table [assist.boost])")
        unit = params.sources.get(f"{name}.{key}.unit")
        if unit is not None and unit != q.unit:
            raise ParameterError(f"{path}: assist.{key}: unit {unit!r}, expected {q.unit!r}")
        q.check(value, where=f"{path}: assist.{key}")
    force = max_rack_force_N(params, name)
    low, high = MAX_ASSIST_RACK_FORCE_RANGE_N
    if not low <= force <= high:
        raise ParameterError(f"{path}: assist: the largest rack force the assist can give is {force:.0f} N, outside "
                             f"the {low:.0f}-{high:.0f} N of real cars (check the reduction, the motor torque limit "
                             "or the relief pressure and their units)")
    return name


def max_rack_force_N(params: Parameters, name: str) -> float:
    """The largest rack force of the assist: eta N T_max through the pinion (column, pinion), eta N T_max (rack),
    A p_relief (hydraulic)."""
    v = lambda key: float(params[f"{name}.{key}"])  # noqa: E731
    if name == ASSIST_EFFECTS["hydraulic"]:
        return v("piston_area") * v("relief_pressure")
    force = v("efficiency") * v("reduction_ratio") * v("motor_torque_limit")
    if name != ASSIST_EFFECTS["rack"]:
        force *= float(params["steering.handwheel_to_rack_ratio"])
    return force


def effects_with_assist(spec: str | None, params: Parameters) -> str | None:
    """The effects spec `spec` with the vehicle's assist added (unchanged without one, or if it names it)."""
    name = check_assist(params)
    if name is None or (spec and name in spec):
        return spec
    if spec and not all(s.strip()[:1] in "+-" for s in spec.split(",") if s.strip()):
        return f"{spec},{name}"  # an exact list
    return f"{spec},+{name}" if spec else f"+{name}"


# The quantities a boost table replaces (the straight line's) and those it fills (its scalars, derived by the
# vehicle reader from [assist.boost]): neither is written into a vehicle file's [assist].
LINE_KEYS = ("gain", "dead_band", "dead_band_smoothing", "speed_dependence", "gain_half_speed", "valve_slope")
TABLE_KEYS = frozenset(table_keys())


def table_off(name: str) -> dict[str, float]:
    """Overrides that switch `name`'s boost table off (the law then is the gain's straight line alone)."""
    return {f"{name}.{key}": 0.0 for key in off_keys()}


def has_table(params: Parameters, name: str) -> bool:
    """Whether the assist `name` of `params` carries a boost table (a nonzero table assist or pressure)."""
    return any(params.sections.get(name, {}).get(key, 0.0) for key in off_keys())


def gear_values(kind: str, given: dict[str, tuple[float, str]]) -> tuple[float, float]:
    """The forward efficiency and reduction of a `kind` electric assist: given, else the assumed defaults."""
    known = _quantities(ASSIST_EFFECTS[kind])
    pick = lambda key: float(given[key][0]) if key in given else float(known[key].default)  # noqa: E731
    return pick("efficiency"), pick("reduction_ratio")


def assist_template(kind: str, given: dict[str, tuple[float, str]], table: bool = False) -> str:
    """The ``[assist]`` section of a vehicle file: `given` values ({quantity: (value, source)}, declared measured)
    and every other quantity of the assist at its assumed default, declared assumed, with its range and source.
    With `table` the boost curve is a table that follows ([assist.boost]): the straight line's quantities are left
    out."""
    if kind not in ASSIST_EFFECTS:
        raise UsageError(f"--assist {kind}: one of {', '.join(ASSIST_EFFECTS)}")
    name = ASSIST_EFFECTS[kind]
    known = _quantities(name)
    lines = ["", "# Power assistance: the effect " + name + "; values marked assumed are typical of current cars.",
             "[assist]", f'type = "{kind}"']
    for key, q in known.items():
        if key in TABLE_KEYS or (table and key in LINE_KEYS):
            continue
        if key in given:
            value, source = given[key]
            q.check(value, where=f"assist.{key}")
            provenance = "measured"
        else:
            value, source = q.default, q.source
            provenance = "assumed"
        text = repr(float(value))
        source = source.replace("\\", "\\\\").replace('"', '\\"')
        lines.append(f'{key} = {{ value = {text}, unit = "{q.unit}", source = "{source}", '
                     f'provenance = "{provenance}" }}')
    return "\n".join(lines) + "\n"
