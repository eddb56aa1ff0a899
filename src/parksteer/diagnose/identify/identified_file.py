"""What ``parksteer assist identify`` found (:class:`Identified`, :func:`.assist_identify.identify_boost`)
and the vehicle file it writes again: its ``[assist]`` section replaced by what was identified, every other line
kept as the owner wrote it."""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field

from .boost_map import Estimate


_HEADER = re.compile(r"^\s*\[([^\]]+)\]\s*(#.*)?$")


def _toml_string(text: str) -> str:
    return '"' + text.replace("\\", "\\\\").replace('"', '\\"') + '"'


def _number(x: float) -> str:
    return repr(float(f"{x:.6g}"))


@dataclass(frozen=True)
class Identified:
    """What :func:`.assist_identify.identify_boost` found (that module's docstring). ``torques`` (N m) and ``assist`` (at the point of
    action, N m at the column or pinion, N at the rack) are the table with ``assist_ci95`` per point; ``current_A``
    the same map in motor current. ``beyond_map`` lists what the map cannot hold (empty: scatter and hysteresis
    within the noise)."""

    vehicle: str
    records: tuple[str, ...]
    assist_name: str
    torques: tuple[float, ...]
    assist: tuple[float, ...]
    assist_ci95: tuple[tuple[float, float], ...]
    current_A: tuple[float, ...]
    current_ci95: tuple[tuple[float, float], ...]
    dead_band: Estimate
    map_centre: Estimate
    product: Estimate  # k_t eta_f N, N m (or N) at the point of action per A
    motor_friction: Estimate
    motor_inertia: Estimate
    back_efficiency: Estimate | None  # None: too few back-driven samples, the file's kept
    offset: Estimate
    rack_friction: Estimate
    tyre_friction: float  # the file's, at which the product is identified
    product_per_tyre_friction: float  # the product's change per unit of the tyre-ground friction
    map_rms_A: float
    map_noise_A: float
    hysteresis_A: Estimate
    hysteresis_Nm: float
    balance_rms_Nm: float
    torque_noise_Nm: float
    beyond_map: tuple[str, ...]
    balance_floors: float = math.nan  # the balance's RMS in torque noise floors
    kept: tuple[str, ...] = ()  # the file's values the written file keeps: a data sheet's, or not contradicted
    balance_product: float = math.nan  # the balance's own product at the file's tyre-ground friction
    # the 95 % half-width of the table's common gain, relative: what its points' intervals leave of a scale of all
    # of them together (1 / sqrt(sum (A_k / se_k)^2), times the 95 % factor)
    gain_uncertainty: float = math.nan
    file_values: dict = field(default_factory=dict)

    def as_dict(self) -> dict:
        est = {k: getattr(self, k).as_dict() for k in ("dead_band", "map_centre", "product", "motor_friction",
                                                         "motor_inertia", "offset", "rack_friction", "hysteresis_A")}
        est["back_efficiency"] = None if self.back_efficiency is None else self.back_efficiency.as_dict()
        return {"vehicle": self.vehicle, "records": list(self.records), "assist": self.assist_name,
                "balance_floors": self.balance_floors, "kept": list(self.kept),
                "balance_product": self.balance_product if math.isfinite(self.balance_product) else None,
                "gain_uncertainty": self.gain_uncertainty if math.isfinite(self.gain_uncertainty) else None,
                "table": {"torsion_bar_torque_Nm": list(self.torques), "assist": list(self.assist),
                          "assist_ci95": [list(c) for c in self.assist_ci95], "current_A": list(self.current_A),
                          "current_ci95": [list(c) for c in self.current_ci95]},
                **est, "tyre_friction": self.tyre_friction,
                "product_per_tyre_friction": self.product_per_tyre_friction, "map_rms_A": self.map_rms_A,
                "map_noise_A": self.map_noise_A,
                "hysteresis_Nm": self.hysteresis_Nm if math.isfinite(self.hysteresis_Nm) else None,
                "balance_rms_Nm": self.balance_rms_Nm,
                "torque_noise_Nm": self.torque_noise_Nm, "beyond_map": list(self.beyond_map),
                "file_values": dict(self.file_values)}

    @property
    def assist_unit(self) -> str:
        """The unit of the assist at its point of action: N at the rack, N m at the column or pinion."""
        from ...model.symbolic.components import discover_effects

        return "N" if discover_effects()[self.assist_name].location == "rack" else "N m"

    def summary_lines(self) -> list[str]:
        unit = self.assist_unit
        lines = [f"boost table from {', '.join(self.records)} ({self.assist_name}):",
                 "  torsion-bar N m   assist " + unit + "   95 %              current A"]
        for t, a, (lo, hi), i in zip(self.torques, self.assist, self.assist_ci95, self.current_A):
            lines.append(f"  {t:15.3f}  {a:10.3f}   {lo:7.3f} to {hi:7.3f}   {i:9.2f}")
        lines += [f"dead band {self.dead_band.text()}",
                  f"map centre in the logged torque {self.map_centre.text()}",
                  f"product k_t eta N {self.product.text()} "
                  f"(file: {self.file_values.get('product', float('nan')):.4g})",
                  f"  at the file's tyre-ground friction {self.tyre_friction:g}: the product moves by "
                  f"{self.product_per_tyre_friction * 0.05:+.4g} per +0.05 of it (the balance cannot tell them apart)",
                  f"motor friction {self.motor_friction.text()} (file: "
                  f"{self.file_values.get('motor_friction_torque', float('nan')):.4g})",
                  f"motor inertia {self.motor_inertia.text()} (file: "
                  f"{self.file_values.get('motor_inertia', float('nan')):.4g})",
                  ("back-driven efficiency " + (self.back_efficiency.text() if self.back_efficiency is not None
                                                else "not fixed (too few back-driven samples)")
                   + f" (file: {self.file_values.get('back_efficiency', float('nan')):.4g})"),
                  f"the table's common gain known to +-{100 * self.gain_uncertainty:.2g} % (95 %)",
                  f"torsion-bar offset {self.offset.text()}",
                  f"rack friction {self.rack_friction.text()}",
                  f"map residual RMS {self.map_rms_A:.3f} A against {self.map_noise_A:.3f} A of noise; hysteresis "
                  f"{self.hysteresis_A.text()} ({self.hysteresis_Nm:.4f} N m of torque)",
                  f"column balance RMS {self.balance_rms_Nm:.4f} N m against a torque noise floor of "
                  f"{self.torque_noise_Nm:.4f} N m ({self.balance_floors:.2f} floors)"]
        if self.kept:
            lines.append(f"kept as the file gives them (a data sheet's, or what the records do not contradict): "
                         f"{', '.join(self.kept)}")
        file_product = self.file_values.get("product")
        if "torque_constant" in self.kept and file_product is not None and math.isfinite(self.balance_product) \
                and self.product_per_tyre_friction:
            agree = self.tyre_friction + (file_product - self.balance_product) / self.product_per_tyre_friction
            lines.append(f"the file's product {file_product:.4g} stands; the balance reads {self.balance_product:.4g} "
                         f"at the file's tyre-ground friction {self.tyre_friction:g}, and the file's at {agree:.3g}")
        lines += [f"the map cannot hold: {b}" for b in self.beyond_map] or ["the map holds the records within "
                                                                            "their noise"]
        return lines

    def to_vehicle_toml(self, text: str) -> str:
        """The vehicle file `text` with its ``[assist]`` written again: the identified table, the product as the
        torque constant, the motor friction; every other entry kept, the boost line's quantities dropped."""
        return replace_assist_section(text, self)


def replace_assist_section(text: str, found) -> str:
    """`text` (a vehicle file) with its ``[assist]`` and ``[assist.*]`` tables written again from `found`."""
    import tomllib

    from ...model.numeric.assist import LINE_KEYS  # the boost line's quantities, which a table replaces

    doc = tomllib.loads(text)
    old = doc.get("assist", {})
    kept, inside = [], False
    for line in text.splitlines():
        header = _HEADER.match(line)
        if header:
            inside = header.group(1).strip() == "assist" or header.group(1).strip().startswith("assist.")
        if not inside:
            kept.append(line)
    while kept and not kept[-1].strip():
        kept.pop()
    records = ", ".join(found.records)
    where = f"identified by parksteer assist identify from {records}"
    unit = found.assist_unit
    written = [label for key, label in (("torque_constant", "the product k_t eta N (as the torque constant)"),
                                        ("motor_friction_torque", "the motor's friction"),
                                        ("motor_inertia", "the rotor's inertia"),
                                        ("back_efficiency", "the back-driven efficiency"))
               if key not in found.kept
               and (key != "back_efficiency" or found.back_efficiency is not None)]
    confirmed = _confirmed(found, old, where)
    own = [k for k in found.kept if k not in confirmed]
    own = ("; the file's own " + ", ".join(own) if own else "") + (
        "; measured, holding the file's " + ", ".join(confirmed) if confirmed else "")
    lines = ["", "# Power assistance: the gear's data as the file gave them; the boost table"
             + "".join(f", {w}" for w in written), f"# {where}{own}.",
             "# Also identified, with no entry in a vehicle file: the torsion-bar sensor's offset "
             f"{found.offset.text()};",
             f"# the map's centre in the logged torque {found.map_centre.text()}; the rack friction",
             f"# {found.rack_friction.text()} (a diagnosis calibrates it again).",
             *(f"# The map cannot hold: {b}" for b in found.beyond_map),
             "[assist]", f"type = {_toml_string(old.get('type', 'column'))}"]
    k_t = found.product.value / (found.file_values["efficiency"] * found.file_values["reduction_ratio"])
    replaced = {
        "torque_constant": (k_t, "N m/A", f"{where}: the product k_t eta N = {found.product.text()} through the "
                                          f"file's efficiency and reduction (only the product is fixed); the file "
                                          f"gave {found.file_values['torque_constant']:g}"),
        "motor_friction_torque": (max(found.motor_friction.value, 0.0), "N m",
                                  f"{where}: {found.motor_friction.text()} (the column balance; the file gave "
                                  f"{found.file_values['motor_friction_torque']:g})"),
        "motor_inertia": (max(found.motor_inertia.value, 0.0), "kg m^2",
                          f"{where}: {found.motor_inertia.text()} (the column balance; the file gave "
                          f"{found.file_values['motor_inertia']:g})"),
    }
    if found.back_efficiency is not None:
        replaced["back_efficiency"] = (min(max(found.back_efficiency.value, 0.5), 0.99), "1",
                                       f"{where}: {found.back_efficiency.text()} (the column balance on the "
                                       f"back-driven samples; the file gave {found.file_values['back_efficiency']:g})")
    replaced = {k: e for k, e in replaced.items() if k not in found.kept}
    # A value the records measured and whose interval holds the file's assumed value: the file's value stays, as a
    # measured one, so its source says so (a diagnosis replays only what is still assumed: stages/assumed.py)
    replaced.update(confirmed)
    for key, entry in old.items():
        if key in ("type", "boost") or key in LINE_KEYS or key in replaced:
            continue
        declared = f", provenance = {_toml_string(entry['provenance'])}" if "provenance" in entry else ""
        lines.append(f"{key} = {{ value = {_number(entry['value'])}, unit = {_toml_string(entry['unit'])}, "
                     f"source = {_toml_string(entry['source'])}{declared} }}")
    for key, (value, u, source) in replaced.items():
        lines.append(f"{key} = {{ value = {_number(value)}, unit = {_toml_string(u)}, "
                     f"source = {_toml_string(source)}, provenance = \"identified\" }}")
    torques = ", ".join(_number(t) for t in found.torques)
    assists = ", ".join(_number(max(a, 0.0)) for a in _strictly_rising(found.assist))
    intervals = "; ".join(f"{lo:.3g}-{hi:.3g}" for lo, hi in found.assist_ci95[2:])
    lines += ["", "[assist.boost]",
              f"torsion_bar_torque = {{ value = [{torques}], unit = \"N m\", source = "
              + _toml_string(f"{where}: the dead band {found.dead_band.text()}, then evenly spaced to the largest of "
                             "the records") + " }",
              f"assist = {{ value = [{assists}], unit = \"{unit}\", source = "
              + _toml_string(f"{where}: the current map times the product k_t eta N; 95 % beyond the dead band "
                             f"{intervals}") + " }"]
    if math.isfinite(found.gain_uncertainty):
        lines.append(f"gain_uncertainty = {{ value = {_number(min(found.gain_uncertainty, 0.5))}, unit = \"1\", "
                     "source = " + _toml_string(f"{where}: the 95 % half-width of the table's common gain, "
                                                "relative (a later record's gain error within it is this baseline's)")
                     + " }")
    lines.append("")
    return "\n".join(kept + lines)


def _confirmed(found, old: dict, where: str) -> dict[str, tuple[float, str, str]]:
    """(value, unit, source) of each value of the gear the file assumed and the records measured with an interval
    holding it (kept as the file gives it: :attr:`Identified.kept`): the file's value, its source the estimate."""
    estimates = {"torque_constant": found.product, "motor_friction_torque": found.motor_friction,
                 "motor_inertia": found.motor_inertia, "back_efficiency": found.back_efficiency}
    out = {}
    for key in found.kept:
        estimate, entry = estimates.get(key), old.get(key)
        if estimate is None or entry is None or entry.get("provenance", "assumed") != "assumed":
            continue
        measured = "the product k_t eta N = " if key == "torque_constant" else ""
        file_value = found.file_values.get("product" if key == "torque_constant" else key, entry["value"])
        low, high = estimate.ci95
        if estimate.value < 0.0 or not low <= file_value <= high:
            continue  # not a physical reading of the part: the file's value stays as assumed as it was
        out[key] = (entry["value"], entry["unit"],
                    f"{where}: {measured}{estimate.text()} holds the file's {file_value:.4g}, which stays")
    return out


def _strictly_rising(values) -> list[float]:
    """The table's assists rounded as written, kept strictly rising beyond the dead band (the reader's check)."""
    out = [0.0, 0.0]
    for a in values[2:]:
        a = float(f"{a:.6g}")
        out.append(a if a > out[-1] else float(f"{out[-1] * (1 + 1e-5) + 1e-6:.6g}"))
    return out
