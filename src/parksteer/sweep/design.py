"""From a sweep point's values to the overrides `simulate` takes, and the base car's value of each key.

Direct keys (``tyre.tyre_pressure``, ``case.chassis_mass``, ``steering.rack_friction_force``)
pass through unchanged. Design variables set several parameters together so that the
model stays consistent with how the base car was built:

* front axle load W and spacer offset e: the chassis mass is W/g minus the unsprung mass,
  the wheel centres sit at y2 = y2_standard + e, and the wheel loads follow from statics,
  W_r - W_l = m_chassis g y_cm / y2 with the chassis's lateral mass centre y_cm kept (the
  relation Table B1 satisfies to 0.1 N);
* steering ratio G: handwheel-to-rack ratio G times the road-wheel-to-rack ratio, and the
  handwheel lock angle scaled by G / G_base so the rack travel and road-wheel lock stay;
* castor: the mechanical trail (z2 - z1) tan(castor), so that the axis still passes
  through the wheel centre in side view.

Every value reads the point's own direct overrides first, so that, for instance, a swept
gravity or unsprung mass enters the statics.
"""

from __future__ import annotations


from .. import portable as pm
from ..errors import UsageError
from ..parameters import Parameters


class SweepError(UsageError):
    """A sweep declaration that cannot be run; the message is one line naming the file and the key."""


def _effective(params: Parameters, case: str, values: dict[str, float]):
    base_case = params.case(case)

    def get(key: str) -> float:
        if key in values:
            return values[key]
        owner, _, name = key.partition(".")
        if owner == "case":
            return base_case[name]
        return params[key]

    return get


def point_overrides(params: Parameters, case: str, values: dict[str, float]) -> dict[str, float]:
    """The ``{"owner.name": value}`` overrides that simulate the point `values` of base case `case`."""
    get = _effective(params, case, values)
    out = {k: v for k, v in values.items() if not k.startswith("design.")}

    load = values.get("design.front_axle_load")
    offset = values.get("design.extra_offset")
    if load is not None or offset is not None:
        g = get("vehicle.gravity")
        unsprung_kg = get("vehicle.unsprung_mass")
        chassis_kg = get("case.chassis_mass") if load is None else load / g - unsprung_kg
        if chassis_kg <= 0:
            raise SweepError(f"design.front_axle_load = {load:g} N is not above the unsprung weight "
                             f"{unsprung_kg * g:g} N")
        total_N = (chassis_kg + unsprung_kg) * g
        standard_y2 = get("case.wheel_centre_y") - get("case.extra_offset")
        y2 = standard_y2 if offset is None else standard_y2 + offset
        difference_N = chassis_kg * g * get("case.chassis_cg_y") / y2
        out.update({
            "case.chassis_mass": chassis_kg,
            "case.wheel_centre_y": y2,
            "case.load_left": (total_N - difference_N) / 2.0,
            "case.load_right": (total_N + difference_N) / 2.0,
        })
        if offset is not None:
            out["case.extra_offset"] = offset

    ratio = values.get("design.steering_ratio")
    if ratio is not None:
        base_ratio = get("steering.handwheel_to_rack_ratio") / get("steering.roadwheel_to_rack_ratio")
        out["steering.handwheel_to_rack_ratio"] = ratio * get("steering.roadwheel_to_rack_ratio")
        out["input.handwheel_lock_angle"] = get("input.handwheel_lock_angle") * ratio / base_ratio

    castor = values.get("design.castor_angle")
    if castor is not None:
        out["geometry.castor_angle"] = castor
        out["geometry.mechanical_trail"] = (get("geometry.wheel_centre_z") - get("geometry.kingpin_top_z")) * \
            pm.tan(castor)
    return out


def base_value(params: Parameters, case: str, key: str) -> float:
    """The base car's value of a sweep key (its design point)."""
    owner, _, name = key.partition(".")
    c = params.case(case)
    if owner == "design":
        if name == "front_axle_load":
            return c["load_left"] + c["load_right"]
        if name == "extra_offset":
            return c["extra_offset"]
        if name == "steering_ratio":
            return params["steering.handwheel_to_rack_ratio"] / params["steering.roadwheel_to_rack_ratio"]
        if name == "castor_angle":
            return params["geometry.castor_angle"]
        raise KeyError(key)
    if owner == "case":
        return c[name]
    return float(params[key])
