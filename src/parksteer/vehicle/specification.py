"""A vehicle file from a car's published specification (``parksteer vehicle new``): the values it gives, those
derived from them by statics and geometry, and the paper car's values for the rest, each marked assumed
(:func:`vehicle_values`), written out as a commented file (:func:`template_text`)."""

from __future__ import annotations

import dataclasses
import math

from .. import portable as pm
from ..parameters import CASE_SCHEMA, DEFAULT_PATH, SCHEMA, Parameters, load_parameters
from . import REQUIRED


@dataclasses.dataclass(frozen=True)
class Specification:
    """A car's published specification: the few values `parksteer vehicle new` starts from (SI units)."""

    front_axle_load_N: float
    left_share: float  # share of the front axle load on the left wheel
    track_m: float
    kingpin_inclination_rad: float
    castor_rad: float
    scrub_radius_m: float  # at the ground, contact centre outboard of the axis' intercept positive
    tyre_radius_m: float
    tyre_pressure_Pa: float
    steering_ratio: float  # handwheel angle per road-wheel angle
    lock_turns: float  # handwheel turns lock to lock
    case: str = "kerb"
    spec_sources: tuple[tuple[str, str], ...] = ()  # (field, source) to name in the file instead of "specification"


@dataclasses.dataclass(frozen=True)
class Derived:
    """One value of the file: its key, value, unit, source, and how it was derived (empty: given or assumed)."""

    key: str
    value: float
    unit: str
    source: str
    how: str = ""


# Paper's-car values a specification does not give; written into the file marked as assumed.
_ASSUMED_FROM_PAPER = (
    "vehicle.chassis_roll_inertia", "vehicle.chassis_roll_stiffness", "vehicle.chassis_roll_damping",
    "steering.rack_mass", "steering.rack_roll_inertia", "steering.rack_friction_force",
    "steering.column_torsional_stiffness", "steering.column_torsional_damping", "steering.hooke_joint_angle",
    "steering.hooke_joint_phase", "steering.steering_assembly_cg_outboard", "steering.steering_assembly_mass",
    "steering.steering_assembly_inertia_x", "steering.steering_assembly_inertia_y",
    "steering.steering_assembly_inertia_z", "tyre.friction_coefficient", "tyre.reference_pressure",
    "tyre.pressure_index", "tyre.radial_stiffness", "tyre.radial_damping", "tyre.carcass_torsional_stiffness",
    "tyre.carcass_torsional_damping", "tyre.tread_ring_mass", "tyre.tread_ring_yaw_inertia",
    "steering.roadwheel_to_rack_ratio",
)


# Heights are measured from a datum of the model's choosing (z down): the ground stays where the paper's file
# puts it; the strut's length (king-pin top above the wheel centre) is the paper car's 0.4 m unless given.
GROUND_Z_M = 0.5


STRUT_HEIGHT_M = 0.4


def vehicle_values(spec: Specification, base: Parameters | None = None) -> list[Derived]:
    """Every value of a vehicle file from `spec`: given values, values derived by statics and geometry, and the
    paper car's values for what a specification does not give (each marked assumed)."""
    base = base or load_parameters(DEFAULT_PATH)
    given = dict(spec.spec_sources)

    def src(field: str) -> str:
        return given.get(field, "specification")

    def assumed(key: str) -> Derived:
        q = _quantity(key)
        return Derived(key, base[key], q.unit,
                       f"assumed: the paper's car ({base.source(key).split(';')[0].split(':')[0]}, parameters.toml); "
                       "not this car's, replace when known")

    out: dict[str, Derived] = {k: assumed(k) for k in _ASSUMED_FROM_PAPER}
    s = {k: out[k].value for k in out}
    out.update(_statics(spec, s, base["vehicle.gravity"], src))
    out.update(_geometry(spec, src))
    wheel_z = out["geometry.wheel_centre_z"].value
    out.update(_steering(spec, s, src))
    # --- the rest of [vehicle]: not in a specification
    for key, value, source in (
        ("vehicle.chassis_cg_z", base["vehicle.chassis_cg_z"],
         "assumed: the paper's choice, chassis mass centre 0.5 m above the ground"),
        ("vehicle.roll_axis_z", base["vehicle.roll_axis_z"],
         "assumed: the paper's choice, roll axis on the centreline at ground level"),
        ("steering.rack_axis_z", wheel_z, "assumed: the rack's axis at wheel-centre height, as in the paper"),
    ):
        out[key] = Derived(key, value, _quantity(key).unit, source)
    order = [k for k in REQUIRED] + [k for k in out if k.startswith("cases.")]
    return [out[k] for k in order]


def _statics(spec: Specification, s: dict[str, float], g: float, src) -> dict[str, Derived]:
    """The unsprung mass and the load case's masses, loads and mass centre, by statics; `s` the assumed values,
    `g` gravity (m/s^2), `src` a field's source."""
    out: dict[str, Derived] = {}
    unsprung = 2.0 * s["steering.steering_assembly_mass"] + 2.0 * s["tyre.tread_ring_mass"] + s["steering.rack_mass"]
    out["vehicle.unsprung_mass"] = Derived(
        "vehicle.unsprung_mass", unsprung, "kg", "derived: 2 steering assemblies + 2 tread rings + rack",
        f"2 x {s['steering.steering_assembly_mass']:g} + 2 x {s['tyre.tread_ring_mass']:g} + "
        f"{s['steering.rack_mass']:g} kg")
    load_left = spec.front_axle_load_N * spec.left_share
    load_right = spec.front_axle_load_N - load_left
    chassis = spec.front_axle_load_N / g - unsprung
    half_track = spec.track_m / 2.0
    cg_y = (load_right - load_left) * half_track / (chassis * g)
    case = f"cases.{spec.case}"
    out[f"{case}.load_left"] = Derived(f"{case}.load_left", load_left, "N",
                                       f"derived from {src('front_axle_load_N')} and {src('left_share')}",
                                       f"front axle load x left share = {spec.front_axle_load_N:g} x {spec.left_share:g}")
    out[f"{case}.load_right"] = Derived(f"{case}.load_right", load_right, "N",
                                        f"derived from {src('front_axle_load_N')} and {src('left_share')}",
                                        f"front axle load - left load = {spec.front_axle_load_N:g} - {load_left:g}")
    out[f"{case}.chassis_mass"] = Derived(
        f"{case}.chassis_mass", chassis, "kg", "derived by statics: the front axle load less the unsprung mass",
        f"(W_l + W_r) / g - unsprung = {spec.front_axle_load_N:g} / {g:g} - {unsprung:g}")
    out[f"{case}.wheel_centre_y"] = Derived(f"{case}.wheel_centre_y", half_track, "m",
                                            f"derived: half the front track ({src('track_m')})",
                                            f"track / 2 = {spec.track_m:g} / 2")
    out[f"{case}.chassis_cg_y"] = Derived(
        f"{case}.chassis_cg_y", cg_y, "m", "derived by statics: moments of the wheel loads about the centreline",
        f"(W_r - W_l) y2 / (m g) = ({load_right:g} - {load_left:g}) x {half_track:g} / ({chassis:g} x {g:g})")
    out[f"{case}.extra_offset"] = Derived(f"{case}.extra_offset", 0.0, "m", "the car's own wheels, no spacer")
    return out


def _geometry(spec: Specification, src) -> dict[str, Derived]:
    """The suspension geometry: z down, the ground at GROUND_Z_M, the axis through the wheel centre in side view as
    in the paper; `src` a field's source."""
    chi, eps = spec.kingpin_inclination_rad, spec.castor_rad
    half_track = spec.track_m / 2.0
    wheel_z = GROUND_Z_M - spec.tyre_radius_m
    top_z = wheel_z - STRUT_HEIGHT_M
    front_view_slope = pm.tan(chi) / pm.cos(eps)  # lateral run of the axis per unit height (see geometry.steer_axis)
    intercept_y = half_track - spec.scrub_radius_m
    top_y = intercept_y - (GROUND_Z_M - top_z) * front_view_slope
    trail = (wheel_z - top_z) * pm.tan(eps)
    geo = {
        "geometry.castor_angle": (eps, "rad", src("castor_rad"), ""),
        "geometry.kingpin_inclination": (chi, "rad", src("kingpin_inclination_rad"), ""),
        "geometry.ground_z": (GROUND_Z_M, "m", "choice: height datum (z down) as in the paper's file", ""),
        "geometry.wheel_centre_z": (wheel_z, "m", f"derived: ground less the tyre radius ({src('tyre_radius_m')})",
                                    f"ground_z - r = {GROUND_Z_M:g} - {spec.tyre_radius_m:g}"),
        "geometry.kingpin_top_z": (top_z, "m", "assumed: king-pin top 0.4 m above the wheel centre, the paper's car",
                                   f"wheel_centre_z - {STRUT_HEIGHT_M:g}"),
        "geometry.kingpin_top_y": (
            top_y, "m", f"derived: the axis through the ground at half track less the scrub radius "
                        f"({src('scrub_radius_m')}), inclined by the king-pin inclination",
            f"(t/2 - r_s) - (ground_z - z1) tan(kpi)/cos(castor) = {intercept_y:g} - {GROUND_Z_M - top_z:g} x "
            f"{front_view_slope:.5g}"),
        "geometry.mechanical_trail": (trail, "m", "derived: the axis through the wheel centre in side view, as the "
                                                  "paper's reconstruction",
                                      f"(z2 - z1) tan(castor) = {wheel_z - top_z:g} x {pm.tan(eps):.5g}"),
    }
    return {key: Derived(key, value, unit, source, how) for key, (value, unit, source, how) in geo.items()}


def _steering(spec: Specification, s: dict[str, float], src) -> dict[str, Derived]:
    """The steering ratio, the handwheel lock and the tyre pressure; `s` the assumed values, `src` a field's
    source."""
    out: dict[str, Derived] = {}
    road = s["steering.roadwheel_to_rack_ratio"]
    out["steering.handwheel_to_rack_ratio"] = Derived(
        "steering.handwheel_to_rack_ratio", spec.steering_ratio * road, "rad/m",
        f"derived: overall steering ratio ({src('steering_ratio')}) x roadwheel_to_rack_ratio",
        f"{spec.steering_ratio:g} x {road:g}")
    lock = spec.lock_turns * math.pi  # half the lock-to-lock turns, 2 pi each
    out["input.handwheel_lock_angle"] = Derived(
        "input.handwheel_lock_angle", lock, "rad", f"derived: half the turns lock to lock ({src('lock_turns')})",
        f"{spec.lock_turns:g} turns / 2 x 2 pi; road-wheel lock {math.degrees(lock / spec.steering_ratio):.1f} deg")
    out["tyre.tyre_pressure"] = Derived("tyre.tyre_pressure", spec.tyre_pressure_Pa, "Pa", src("tyre_pressure_Pa"))
    return out


def _quantity(key: str):
    section, _, name = key.partition(".")
    return CASE_SCHEMA[name] if section == "cases" else SCHEMA[section][name]


def _toml_value(value: float) -> str:
    text = repr(float(value))
    return text if any(c in text for c in ".en") else text + ".0"


def _toml_string(text: str) -> str:
    return '"' + text.replace("\\", "\\\\").replace('"', '\\"') + '"'


def template_text(name: str, spec: Specification, values: list[Derived]) -> str:
    """The commented vehicle file of `values` (from :func:`vehicle_values`)."""
    lines = [
        f"# parksteer vehicle file: {name}",
        "# Written by `parksteer vehicle new` from a specification; check every value marked `assumed` against",
        "# your car. Each entry is {value, unit, source} in SI units under the keys of the parameter registry",
        "# (src/parksteer/parameters.py); `parksteer vehicle check FILE` validates it. Axes: x forward, y right, z down.",
        "# The rig, spacers, synthetic logger and the test cycle's timing come from the shipped parameter file.",
    ]
    section = None
    for d in values:
        head, _, rest = d.key.rpartition(".")
        if head != section:
            section = head
            lines += ["", f"[{head}]"]
        if d.how:
            lines.append(f"# {rest} = {d.how}")
        lines.append(f"{rest} = {{ value = {_toml_value(d.value)}, unit = {_toml_string(d.unit)}, "
                     f"source = {_toml_string(d.source)} }}")
    return "\n".join(lines) + "\n"
