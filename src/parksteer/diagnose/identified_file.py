"""The vehicle file written again by ``parksteer assist identify``: its ``[assist]`` section replaced by what was
identified (:class:`parksteer.diagnose.assist_identify.Identified`), every other line kept as the owner wrote it."""

from __future__ import annotations

import re


_HEADER = re.compile(r"^\s*\[([^\]]+)\]\s*(#.*)?$")


def _toml_string(text: str) -> str:
    return '"' + text.replace("\\", "\\\\").replace('"', '\\"') + '"'


def _number(x: float) -> str:
    return repr(float(f"{x:.6g}"))


def replace_assist_section(text: str, found) -> str:
    """`text` (a vehicle file) with its ``[assist]`` and ``[assist.*]`` tables written again from `found`."""
    import tomllib

    from ..model.numeric.assist import LINE_KEYS  # the boost line's quantities, which a table replaces

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
    own = "; the file's own " + ", ".join(found.kept) if found.kept else ""
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
    for key, entry in old.items():
        if key in ("type", "boost") or key in LINE_KEYS or key in replaced:
            continue
        lines.append(f"{key} = {{ value = {_number(entry['value'])}, unit = {_toml_string(entry['unit'])}, "
                     f"source = {_toml_string(entry['source'])} }}")
    for key, (value, u, source) in replaced.items():
        lines.append(f"{key} = {{ value = {_number(value)}, unit = {_toml_string(u)}, "
                     f"source = {_toml_string(source)} }}")
    torques = ", ".join(_number(t) for t in found.torques)
    assists = ", ".join(_number(max(a, 0.0)) for a in _strictly_rising(found.assist))
    intervals = "; ".join(f"{lo:.3g}-{hi:.3g}" for lo, hi in found.assist_ci95[2:])
    lines += ["", "[assist.boost]",
              f"torsion_bar_torque = {{ value = [{torques}], unit = \"N m\", source = "
              + _toml_string(f"{where}: the dead band {found.dead_band.text()}, then evenly spaced to the largest of "
                             "the records") + " }",
              f"assist = {{ value = [{assists}], unit = \"{unit}\", source = "
              + _toml_string(f"{where}: the current map times the product k_t eta N; 95 % beyond the dead band "
                             f"{intervals}") + " }",
              ""]
    return "\n".join(kept + lines)


def _strictly_rising(values) -> list[float]:
    """The table's assists rounded as written, kept strictly rising beyond the dead band (the reader's check)."""
    out = [0.0, 0.0]
    for a in values[2:]:
        a = float(f"{a:.6g}")
        out.append(a if a > out[-1] else float(f"{out[-1] * (1 + 1e-5) + 1e-6:.6g}"))
    return out
