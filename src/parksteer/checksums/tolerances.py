"""How far a figure's numbers may move on another platform and still count as the same figure: one tolerance per
figure family and unit, each with its reason.

``parksteer checksums verify`` calls a figure whose bytes differ from figures/SHA256SUMS "within tolerance" when
every number of its data (and of its SVG drawing) is within the tolerance below and everything else is identical;
anything more is "changed". This is the only place the tolerances are declared (docs/reproducibility.md prints them
with ``python -m parksteer.checksums.tolerances``).

A number printed with 7 significant digits (parksteer.tables) carries its rounding: two values a last bit apart can
print one unit of the 7th digit apart. Every comparison therefore also allows one unit of the last printed digit
when either side shows all 7 digits (a shorter number was printed exactly). Counts and yes/no flags are numbers too;
a change of one is beyond every tolerance here for any count below 10,000, so a flag that flips is "changed".
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field, replace

from ..model.numeric.tolerances import ATOL_Q, ATOL_U, RTOL


@dataclass(frozen=True)
class Tolerance:
    """|new - old| <= atol + rtol * max(|new|, |old|) (plus the printing unit), in the column's own unit."""

    rtol: float
    atol: float
    reason: str


@dataclass(frozen=True)
class Family:
    """Figures whose numbers come from the same kind of computation, with a tolerance per unit of a column."""

    name: str
    figures: tuple[str, ...]  # figure names (file stems) or glob patterns of them
    computed_by: str
    default: Tolerance  # a column whose unit has no entry in by_unit (or that has no unit)
    drawing: Tolerance  # the numbers of the figure's SVG, in drawing units (points)
    by_unit: dict[str, Tolerance] = field(default_factory=dict)


# Units are read from a column's name (torque_Nm, rack_mm, time_s, tyre.tyre_pressure_Pa) or, for a table with a
# `unit` column (bands, rivals), from that row's unit.
UNIT_SUFFIXES = {"Nm": "N m", "N_m": "N m", "mm": "mm", "m": "m", "N": "N", "s": "s", "Pa": "Pa", "rad": "rad",
                 "deg": "deg", "pct": "%", "%": "%"}

# A handwheel torque error per rack-speed error: the column damping c G^2, about 37,000 N m per m/s (the reason the
# model's ATOL_U is tight, parksteer.model.numeric.tolerances).
_COLUMN_DAMPING_Nm_PER_m_PER_s = 37_000.0
# "A few times" the integrator's tolerances: two runs that each meet the error control can sit on either side of
# the exact solution, and a last-bit change in the right-hand side reorders the adaptive steps.
_MODEL_FACTOR = 5.0
_MODEL_RTOL = _MODEL_FACTOR * RTOL
_MODEL_TORQUE_ATOL_Nm = _MODEL_FACTOR * _COLUMN_DAMPING_Nm_PER_m_PER_s * ATOL_U["m"]
# A torque ratio (a share, a factor, a per cent) carries the torque tolerance over a typical parking torque.
_TYPICAL_PARKING_TORQUE_Nm = 10.0

_CLOSED_FORM = Tolerance(1e-12, 1e-12, "closed form, libm last-bit: the same formula through another libm or "
                                       "another compiler's contraction differs in the last bits only")

FAMILIES: tuple[Family, ...] = (
    Family(
        "closed form", ("fig3", "fig4", "figA3", "table1"),
        "closed-form tyre rig and lifting formulas (equations (1), (2), (A1), Table 1's geometry)",
        default=_CLOSED_FORM,
        drawing=Tolerance(0.0, 0.01, "matplotlib writes coordinates in points with 6 decimals; 0.01 pt (3.5 "
                                     "micrometres) is invisible and far above a last-bit difference"),
    ),
    Family(
        "model", ("fig12", "fig13", "fig14", "fig15", "fig16", "figContrib", "bands", "rivals", "sweep_*"),
        f"the multibody model integrated at rtol {RTOL:g} (parksteer.model.numeric.tolerances)",
        default=Tolerance(_MODEL_RTOL, _MODEL_TORQUE_ATOL_Nm / _TYPICAL_PARKING_TORQUE_Nm,
                          f"a ratio of torques (share, factor): the torque tolerance over a "
                          f"{_TYPICAL_PARKING_TORQUE_Nm:g} N m parking torque"),
        drawing=Tolerance(0.0, 0.05, "the torque tolerance moves a curve by about 0.02 pt at the figures' 10 pt "
                                     "per N m (a 3e-4 N m wobble of fig12's runs moved it 0.003 pt); 0.05 pt (18 "
                                     "micrometres) is invisible"),
        by_unit={
            "N m": Tolerance(_MODEL_RTOL, _MODEL_TORQUE_ATOL_Nm,
                             f"{_MODEL_FACTOR:g} x the integrator's rtol, and {_MODEL_FACTOR:g} x its rack-speed "
                             f"atol ({ATOL_U['m']:g} m/s) through the column damping "
                             f"({_COLUMN_DAMPING_Nm_PER_m_PER_s:g} N m per m/s)"),
            "%": Tolerance(_MODEL_RTOL, 100.0 * _MODEL_TORQUE_ATOL_Nm / _TYPICAL_PARKING_TORQUE_Nm,
                           f"a torque change in per cent: the torque tolerance over a "
                           f"{_TYPICAL_PARKING_TORQUE_Nm:g} N m parking torque"),
            "mm": Tolerance(_MODEL_RTOL, _MODEL_FACTOR * ATOL_Q["m"] * 1e3,
                            f"{_MODEL_FACTOR:g} x the integrator's rtol and rack-position atol ({ATOL_Q['m']:g} m)"),
            "m": Tolerance(_MODEL_RTOL, _MODEL_FACTOR * ATOL_Q["m"],
                           f"{_MODEL_FACTOR:g} x the integrator's rtol and rack-position atol"),
            "rad": Tolerance(_MODEL_RTOL, _MODEL_FACTOR * ATOL_Q["rad"],
                             f"{_MODEL_FACTOR:g} x the integrator's rtol and angle atol ({ATOL_Q['rad']:g} rad)"),
            "N": Tolerance(_MODEL_RTOL, 1e-3,
                           f"{_MODEL_FACTOR:g} x the integrator's rtol; a wheel load of a few kN follows the rack "
                           "position, so 1e-3 N covers the relative part at the loads shown"),
            "s": Tolerance(1e-12, 1e-12, "times are the output grid asked of the integrator, not integrated"),
            "Pa": _CLOSED_FORM,  # design inputs (tyre pressure), not results
        },
    ),
    Family(
        "diagnosis", ("diag_*",),
        "fits of the model to seeded noisy synthetic records (parksteer.diagnose)",
        default=Tolerance(1e-3, 1e-3,
                          "a fit stops when its Gauss-Newton step is below 0.3 standard errors "
                          "(parksteer.diagnose.settings.calibration_tolerance): a last bit can end it one step "
                          "earlier or later, which moves a fitted parameter by a fraction of its standard error and "
                          "an RMS or ratio by far less than 1e-3 of itself"),
        drawing=Tolerance(0.0, 0.5, "1e-3 of a plotted value is up to about 0.2 pt on axes of 200 pt that span the "
                                    "values shown; 0.5 pt (0.18 mm) is at the edge of visible, a moved tick label "
                                    "or marker is far beyond it"),
        by_unit={
            "BIC": Tolerance(1e-3, 0.1,
                             "a BIC is a chi-square: a fit stopped 0.3 standard errors from its optimum moves it by "
                             "up to 0.3^2 = 0.09"),
        },
    ),
)

# The assist study's rack forces are handwheel torques through the gear, d(column angle)/d(rack) about 125-190
# rad/m on the paper's car and the shipped vehicles: the model's torque tolerance through 250 rad/m. Otherwise the
# model's.
_GEAR_RAD_PER_m = 250.0
FAMILIES = (*FAMILIES, replace(
    FAMILIES[1], name="model, rack force", figures=("assist_study", "assist_creep"),
    by_unit={**FAMILIES[1].by_unit,
             "N": Tolerance(_MODEL_RTOL, _MODEL_TORQUE_ATOL_Nm * _GEAR_RAD_PER_m,
                            f"a rack force is a handwheel torque through the gear: the torque tolerance through "
                            f"{_GEAR_RAD_PER_m:g} rad/m")}))

# Text (verdicts, names, mechanisms, units) has no tolerance: a verdict that changes is "changed".
TEXT = "exact: text (verdicts, names) must match"

def family_of(figure: str) -> Family | None:
    """The family of a figure (file stem), or None if none declares it."""
    from fnmatch import fnmatchcase

    for family in FAMILIES:
        if any(fnmatchcase(figure, pattern) for pattern in family.figures):
            return family
    return None


def unit_of(column: str, row_unit: str | None = None) -> str | None:
    """The unit of a column from its name's suffix (torque_Nm -> N m), else the row's `unit` cell, else None."""
    if re.search(r"(^|_)bic(_|$)", column):
        return "BIC"
    for suffix, unit in UNIT_SUFFIXES.items():
        if column.endswith("_" + suffix):
            return unit
    if row_unit:
        return UNIT_SUFFIXES.get(row_unit, row_unit)
    return None


def tolerance_for(family: Family, unit: str | None) -> Tolerance:
    return family.by_unit.get(unit, family.default) if unit is not None else family.default


def table_markdown() -> str:
    """The tolerance table as Markdown (docs/reproducibility.md shows it)."""
    lines = ["| family | figures | unit | rtol | atol | reason |", "|---|---|---|---|---|---|"]
    for family in FAMILIES:
        figures = ", ".join(family.figures)
        rows = [("other / none", family.default)] + [(u, t) for u, t in family.by_unit.items()]
        for unit, tol in rows:
            lines.append(f"| {family.name} | {figures} | {unit} | {tol.rtol:.3g} | {tol.atol:.3g} | {tol.reason} |")
        tol = family.drawing
        lines.append(f"| {family.name} | {figures} | SVG drawing, pt | - | {tol.atol:.3g} | {tol.reason} |")
    lines.append(f"| every family | all | text | - | - | {TEXT} |")
    return "\n".join(lines)


if __name__ == "__main__":
    print(table_markdown())
