"""A vehicle's power assist: the ``[assist]`` section of a vehicle file, checked against the assist effects.

The vehicle layer reads ``[assist]`` (``type`` and entries of ``{value, unit, source}``) into the section of the
effect its type names (:data:`ASSIST_EFFECTS`). Here every entry is checked against its quantity (unit and
bounds), the assist is checked as a whole (the largest rack force it can give), and the effects spec of a run gains
the assist. :func:`assist_template` writes the section for ``parksteer vehicle new --assist``.
"""

from __future__ import annotations

from ...boost_table import off_keys, table_keys
from ...errors import UsageError
from ...boost_table import table_size
from ...parameters import ParameterError, Parameters, Quantity

# ``[assist]`` of a vehicle file (parksteer.vehicle): its ``type`` and the assist effect
# (parksteer.model.symbolic.effects) it names; the entries go into that effect's section.
ASSIST_EFFECTS = {"column": "electric_assist_column", "pinion": "electric_assist_pinion",
                  "rack": "electric_assist_rack", "hydraulic": "hydraulic_assist"}


def assist_of(params: Parameters) -> str | None:
    """The assist effect a vehicle's parameters carry (from ``[assist]``), or None."""
    found = [name for name in ASSIST_EFFECTS.values() if name in params.sections]
    return found[0] if found else None

# The window of plausible rack forces of an assist: the largest its motor (or relief valve) can give through its
# gear, and the largest its boost table asks for at its last point. Its ends are assumptions, each with why.
ASSIST_RACK_FORCE_LOW = Quantity(
    "assist_check.rack_force_low", "N", 0.0, 1.0e6, lower_inclusive=True, default=1.0e3,
    description="the least rack force an assist's limit, or its boost table's largest point, may carry",
    source="assumed: a third of the lighter of the two standstill loads the model gives its cars over the "
           "lock-to-lock cycle without assistance, 3.0 kN (Polo VI, kerb: 24.1 N m at the handwheel x 125.5 rad/m) "
           "and 3.5 kN (the paper's car, unladen: 18.6 N m x 186.5 rad/m), `parksteer simulate`; a motor's 3-6 N m "
           "peak torque written as a column torque gives 0.3-1.1 kN there (x 100-190 rad/m), 1/(eta N) of what "
           "it carries")
ASSIST_RACK_FORCE_HIGH = Quantity(
    "assist_check.rack_force_high", "N", 0.0, 1.0e7, lower_inclusive=True, default=3.0e4,
    description="the largest rack force an assist's limit, or its boost table's largest point, may carry",
    source="assumed: above the 18 kN a supplier builds its rack EPS gears for (small utility vehicles: "
           "data/published_loads.toml, gear_rating_rack_eps, read) and near ten times the model's own standstill "
           "loads (3.0-3.5 kN), while a unit slip (a pressure in Pa read as bar, a rack force written as a column "
           "torque) gives 10^2-10^5 times the intended force")


def rack_force_window_N() -> tuple[float, float]:
    """(least, largest) plausible rack force of an assist, N (:data:`ASSIST_RACK_FORCE_LOW`, ``_HIGH``)."""
    return ASSIST_RACK_FORCE_LOW.default, ASSIST_RACK_FORCE_HIGH.default


def _quantities(name: str) -> dict:
    from ..symbolic.components import discover_effects  # the effect table: not for --help

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
    low, high = rack_force_window_N()
    if not low <= force <= high:
        raise ParameterError(f"{path}: assist: the largest rack force the assist can give is {force:.0f} N, outside "
                             f"the {low:.0f}-{high:.0f} N of real cars (check the reduction, the motor torque limit "
                             "or the relief pressure and their units)")
    if name != ASSIST_EFFECTS["hydraulic"]:
        from .assisted import check_back_efficiency

        check_back_efficiency(name, float(params[f"{name}.efficiency"]), float(params[f"{name}.back_efficiency"]),
                              where=f"{path}: assist: ")
    check_table_units(params, name)
    return name


def table_rack_force_N(params: Parameters, name: str) -> tuple[float, int] | None:
    """The rack force the boost table of `name` asks for at its largest point (its last, as given, in its largest
    row) and that row (0 first), or None without a table: the assist at the column or pinion times the
    handwheel-to-rack ratio, at the rack as it is, a valve's pressure times the piston area."""
    if not has_table(params, name):
        return None
    value = lambda key: float(params[f"{name}.{key}"])  # noqa: E731
    points, rows = table_size(value)
    assists = [value(f"boost_assist_{r}_{points - 1}") for r in range(rows)]
    row = max(range(rows), key=assists.__getitem__)
    if name == ASSIST_EFFECTS["hydraulic"]:
        lever = value("piston_area")
    elif name == ASSIST_EFFECTS["rack"]:
        lever = 1.0
    else:
        lever = float(params["steering.handwheel_to_rack_ratio"])
    return assists[row] * lever, row


def check_table_units(params: Parameters, name: str) -> None:
    """Refuse (one line) a boost table whose largest point, carried to the rack, falls outside the plausible window
    (:func:`rack_force_window_N`), naming the unit its numbers most likely are in and what fixes it: a motor-torque
    curve written as the assist at the point of action is 1/(eta N) of it (14 for a 0.85 x 18 worm)."""
    found = table_rack_force_N(params, name)
    if found is None:
        return
    force, row = found
    low, high = rack_force_window_N()
    if low <= force <= high:
        return
    where = f"{params.path}: assist.boost.assist" + (f" row {row + 1}" if has_speed_rows(params, name) else "")
    kind = next(k for k, n in ASSIST_EFFECTS.items() if n == name)
    said = f"its largest point carries {force:.0f} N to the rack, outside the {low:.0f}-{high:.0f} N of real cars"
    if name == ASSIST_EFFECTS["hydraulic"]:
        likely = (f"a pressure in bar written as Pa? (unit = \"bar\")" if low <= force * 1e5 <= high else
                  f"a pressure in Pa written as bar? (unit = \"Pa\")" if low <= force / 1e5 <= high else
                  "check the pressures, their unit and the piston area")
    else:
        scale = float(params[f"{name}.efficiency"]) * float(params[f"{name}.reduction_ratio"])
        if force < low and low <= force * scale <= high:
            likely = (f"the motor's torque written as the assist at the {kind}? As motor torque through eta N = "
                      f"{scale:.4g} it is {force * scale:.0f} N: add at = \"motor\" to [assist.boost] assist "
                      "(parksteer vehicle new: --assist-boost-unit motor)")
        elif name != ASSIST_EFFECTS["rack"] and (
                low <= force / float(params["steering.handwheel_to_rack_ratio"]) <= high):
            likely = f"a rack force (N) written as a torque at the {kind}? Give the torque at the {kind} (N m)"
        else:
            unit = "N at the rack" if name == ASSIST_EFFECTS["rack"] else f"N m at the {kind}"
            likely = f"the assist is read in {unit}: check the table's unit"
    raise ParameterError(f"{where}: {said}: {likely}")


def has_speed_rows(params: Parameters, name: str) -> bool:
    """Whether the table of `name` has more than one vehicle-speed row."""
    return table_size(lambda key: float(params[f"{name}.{key}"]))[1] > 1


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
