"""The static tyre rig of section 2: limiting steer torque of a sliding contact patch.

Model (Gough, as in the paper): the contact patch is a disc of radius R carrying the load W at a uniform pressure
equal to the inflation pressure p (pi R^2 p = W), every sliding element carrying the Coulomb friction mu p dA
opposite to its sliding velocity.

* Equation (1), patch turning about its own centre: T = (2/3) mu p pi R^3 = (2 mu / 3) W^1.5 / sqrt(pi p).
* Equation (2), the paper's empirical pressure correction: T = p0^(n - 0.5) (2 mu / (3 sqrt(pi))) W^1.5 / p^n,
  equal to (1) at p = p0.

Beyond the paper, the patch turning about a pin at lateral offset e (the loading-plate pin, Fig. 2): with the wheel
free to roll the tread slides in pure spin about the patch centre, so the torque is equation (1) for every e and
the wheel spins by e / rolling radius per unit steer (Table 1's "ratio for pure rolling"); with the wheel braked
the patch slides rigidly about the pin, T(e) = mu p Integral |r - e| dA over the disc, in closed form in complete
elliptic integrals, T(0) equation (1) and T tending to mu W e once e >> R.

All physics functions take and return SI units and broadcast over numpy arrays.
"""

from __future__ import annotations

import csv
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from . import portable as pm
from .errors import UsageError, cannot_read
from .parameters import Parameters

# Below this R/e the far-field series is used: the elliptic form loses about
# log10(1/k^2) digits to cancellation there, the series' first omitted term is ~k^8.
_FAR_FIELD_K = 0.02


# ---------------------------------------------------------------- equations (1), (2)


def patch_radius_m(load_N, pressure_Pa):
    """Radius of the circular contact patch that carries `load_N` at `pressure_Pa`: pi R^2 p = W."""
    return np.sqrt(np.asarray(load_N, dtype=float) / (math.pi * np.asarray(pressure_Pa, dtype=float)))


def gough_torque_Nm(load_N, pressure_Pa, mu):
    """Equation (1): torque to slide the uniform-pressure disc about its centre, (2 mu/3) W^1.5 / sqrt(pi p)."""
    load_N = np.asarray(load_N, dtype=float)
    return 2.0 * mu / 3.0 * (load_N * np.sqrt(load_N)) / np.sqrt(math.pi * np.asarray(pressure_Pa, dtype=float))


def pressure_correction(pressure_Pa, reference_pressure_Pa, pressure_index):
    """Ratio of equation (2) to equation (1) at one pressure: (p0 / p)^(n - 0.5); 1 at p = p0."""
    return pm.power(reference_pressure_Pa / np.asarray(pressure_Pa, dtype=float), pressure_index - 0.5)


def empirical_torque_Nm(load_N, pressure_Pa, mu, reference_pressure_Pa, pressure_index):
    """Equation (2): p0^(n - 0.5) (2 mu / (3 sqrt(pi))) W^1.5 / p^n."""
    load_N = np.asarray(load_N, dtype=float)
    pressure_Pa = np.asarray(pressure_Pa, dtype=float)
    return (
        pm.power(reference_pressure_Pa, pressure_index - 0.5)
        * 2.0
        * mu
        / (3.0 * math.sqrt(math.pi))
        * (load_N * np.sqrt(load_N))
        / pm.power(pressure_Pa, pressure_index)
    )


# ---------------------------------------------------------------- patch about an offset pin


def disc_distance_integral_m3(radius_m, offset_m):
    """Integral over a disc of radius R of the distance |r - e| to a point at distance e from its centre.

    Closed form (k = e/R inside the disc, k = R/e outside; E, K complete elliptic
    integrals of modulus k):
      e <= R:  (4 R^3 / 9) [(7 + k^2) E - 4 (1 - k^2) K]
      e >= R:  (4 e^3 / 9) [(1 + 7 k^2) E - (1 + 3 k^2)(1 - k^2) K]
    Both give 32 R^3 / 9 at e = R and 2 pi R^3 / 3 at e = 0. For R/e < 0.02 the series
    pi R^2 e (1 + k^2/8 + k^4/192 + k^6/1024) replaces the second form.
    """
    # Imported here: the many modules that import this one for its tables take no elliptic integral, and
    # scipy.special takes 0.15 s to import.
    from scipy.special import ellipe, ellipk

    radius_m, offset_m = np.broadcast_arrays(
        np.asarray(radius_m, dtype=float), np.abs(np.asarray(offset_m, dtype=float))
    )
    out = np.empty(radius_m.shape)
    inside = offset_m <= radius_m
    far = offset_m * _FAR_FIELD_K > radius_m
    near_outside = ~inside & ~far

    r, e = radius_m[inside], offset_m[inside]
    m = (e / r) ** 2
    # (1 - m) K(m) -> 0 as m -> 1 although K diverges: take the limit explicitly.
    with np.errstate(invalid="ignore", divide="ignore"):
        one_minus_m_k = np.where(m < 1.0, (1.0 - m) * ellipk(np.minimum(m, 1.0)), 0.0)
    out[inside] = 4.0 * (r * r * r) / 9.0 * ((7.0 + m) * ellipe(m) - 4.0 * one_minus_m_k)

    r, e = radius_m[near_outside], offset_m[near_outside]
    m = (r / e) ** 2
    with np.errstate(invalid="ignore", divide="ignore"):
        one_minus_m_k = np.where(m < 1.0, (1.0 - m) * ellipk(np.minimum(m, 1.0)), 0.0)
    out[near_outside] = 4.0 * (e * e * e) / 9.0 * ((1.0 + 7.0 * m) * ellipe(m) - (1.0 + 3.0 * m) * one_minus_m_k)

    r, e = radius_m[far], offset_m[far]
    m = (r / e) ** 2
    out[far] = math.pi * r**2 * e * (1.0 + m / 8.0 + m**2 / 192.0 + (m * m * m) / 1024.0)
    return out


def braked_pin_torque_Nm(load_N, pressure_Pa, mu, offset_m):
    """Torque about a pin at lateral offset e to slide the patch of a braked (non-rolling) wheel.

    The patch turns rigidly about the pin, so each element slides perpendicular to its
    radius from the pin: T = mu p Integral |r - e| dA over the uniform-pressure disc.
    Equals equation (1) at e = 0, tends to mu W e for e >> R.
    """
    pressure_Pa = np.asarray(pressure_Pa, dtype=float)
    radius_m = patch_radius_m(load_N, pressure_Pa)
    return mu * pressure_Pa * disc_distance_integral_m3(radius_m, offset_m)


def free_rolling_pin_torque_Nm(load_N, pressure_Pa, mu, offset_m):
    """Torque about a pin at lateral offset e to slide the patch of a wheel free to roll.

    Rolling at omega e takes up the patch centre's translation, the tread slides in pure
    spin about the patch centre (zero net force), so the torque about the pin is the
    spin torque, equation (1), whatever e: the result is equation (1) broadcast over e.
    """
    spin_torque_Nm = gough_torque_Nm(load_N, pressure_Pa, mu)
    return np.broadcast_arrays(spin_torque_Nm, np.asarray(offset_m, dtype=float))[0].copy()


def pure_rolling_spin_ratio(offset_m, rolling_radius_m):
    """Wheel spin angle per unit steer angle when the patch centre's travel is pure rolling: e / r_roll."""
    return np.asarray(offset_m, dtype=float) / rolling_radius_m


# ---------------------------------------------------------------- conveniences taking params


def limiting_torque_Nm(params: Parameters, load_N, pressure_Pa=None):
    """Equation (2) with the rig's mu, p0 and n; `pressure_Pa` defaults to the car model's tyre pressure."""
    if pressure_Pa is None:
        pressure_Pa = params["tyre.tyre_pressure"]
    return empirical_torque_Nm(
        load_N,
        pressure_Pa,
        params["tyre.friction_coefficient"],
        params["tyre.reference_pressure"],
        params["tyre.pressure_index"],
    )


@dataclass(frozen=True)
class PinTorques:
    """Limiting torques about an offset pin (N m), with the rig's pressure correction on the spin part."""

    free_rolling_Nm: np.ndarray
    braked_Nm: np.ndarray


def pin_torques_Nm(params: Parameters, load_N, pressure_Pa, offset_m) -> PinTorques:
    """Free-rolling and braked torques about a pin at `offset_m`, with the rig's pressure correction.

    The braked integral splits into the spin part, equation (1) (the patch turning about its
    own centre), and the drag part, the braked integral minus equation (1) (the patch dragged
    about the pin). Only the spin part carries (p0/p)^(n - 0.5), the ratio of equation (2) to
    equation (1), which the rig measured for a patch spinning about its centre: a pressure
    distribution changes the moment arm of the spin friction, never the net sliding force
    mu W, so the drag part stays the uniform-pressure integral and tends to mu W e. Since
    |r - e| <= |r| + e, the drag part never exceeds mu W e, and the braked torque never
    exceeds mu W e plus the free-rolling torque. At e = 0 both equal equation (2).
    """
    mu = params["tyre.friction_coefficient"]
    scale = pressure_correction(pressure_Pa, params["tyre.reference_pressure"], params["tyre.pressure_index"])
    spin_Nm = free_rolling_pin_torque_Nm(load_N, pressure_Pa, mu, offset_m)
    drag_Nm = braked_pin_torque_Nm(load_N, pressure_Pa, mu, offset_m) - spin_Nm
    return PinTorques(free_rolling_Nm=scale * spin_Nm, braked_Nm=scale * spin_Nm + drag_Nm)


# ---------------------------------------------------------------- Table 1

TABLE1_COLUMNS = (
    "offset_mm",
    "steer_deg",
    "spin_deg",
    "spin_steer_ratio",
    "pure_rolling_ratio",
    "percentage_difference",
)


def read_printed_table1(path: str | Path) -> tuple[list[dict[str, str]], dict[str, str]]:
    """Read data/table1_printed.csv keeping each cell's printed text (its decimals carry the rounding).

    Returns the rows (column name -> text) and the ``# key: value`` header lines.
    """
    path = Path(path)
    try:
        lines = path.read_text(encoding="utf-8").splitlines()
    except OSError as exc:
        raise UsageError(cannot_read(path, exc)) from None
    header: dict[str, str] = {}
    body = []
    for line in lines:
        if line.startswith("#"):
            key, _, value = line[1:].partition(":")
            header[key.strip()] = value.strip()
        elif line.strip():
            body.append(line)
    rows = list(csv.DictReader(body))
    if not rows or tuple(rows[0].keys()) != TABLE1_COLUMNS:
        found = ", ".join(rows[0].keys()) if rows else "no rows"
        raise UsageError(f"{path}: expected columns {', '.join(TABLE1_COLUMNS)}; found {found}")
    for i, row in enumerate(rows, start=1):
        for name, text in row.items():
            try:
                float(text)
            except (TypeError, ValueError):
                raise UsageError(f"{path}: row {i}, {name}: {text!r} is not a number") from None
    return rows, header


def printed_half_unit(text: str) -> float:
    """Half a unit in the last printed digit: the rounding interval of a printed number ("0.097" -> 0.0005)."""
    _, _, decimals = text.strip().partition(".")
    return 0.5 / 10 ** len(decimals)


def table1(params: Parameters, printed_rows: Sequence[Mapping[str, str]]) -> dict[str, np.ndarray]:
    """Recompute Table 1 from its printed angles and offsets; flag disagreements beyond printed rounding.

    * quotient of the printed angles, spin / steer, against the printed spin/steer ratio;
      also whether the two are consistent once every printed number may be anywhere in its
      rounding interval (the printed ratio's interval overlaps the range of quotients the
      rounded angles allow), i.e. whether the ratio may have come from unrounded angles;
    * ratio for pure rolling = offset / rolling radius (``rig.rolling_radius``);
    * percentage difference = (measured ratio - pure rolling) / pure rolling * 100, with the
      printed spin/steer ratio as the measured ratio (this reproduces the printed
      percentages; the same formula with the quotient is given beside it).

    A ``*_disagrees`` column is 1 where the printed value and its recomputation differ by
    more than half a unit in the printed value's last digit.
    """

    def column(name: str) -> np.ndarray:
        return np.array([float(row[name]) for row in printed_rows])

    def half_units(name: str) -> np.ndarray:
        return np.array([printed_half_unit(row[name]) for row in printed_rows])

    def disagrees(printed: np.ndarray, recomputed: np.ndarray, half_unit: np.ndarray) -> np.ndarray:
        # a hair of slack so that an exact tie (e.g. 0.22075 against 0.2208) is not a disagreement
        return (np.abs(printed - recomputed) > half_unit * (1.0 + 1e-9)).astype(int)

    offset_mm = column("offset_mm")
    steer_deg, spin_deg = column("steer_deg"), column("spin_deg")
    printed_ratio = column("spin_steer_ratio")
    printed_rolling = column("pure_rolling_ratio")
    printed_percent = column("percentage_difference")

    quotient = spin_deg / steer_deg
    ratio_half = half_units("spin_steer_ratio")
    steer_half, spin_half = half_units("steer_deg"), half_units("spin_deg")
    quotient_low = (spin_deg - spin_half) / (steer_deg + steer_half)
    quotient_high = (spin_deg + spin_half) / (steer_deg - steer_half)

    rolling = pure_rolling_spin_ratio(offset_mm / 1000.0, params["rig.rolling_radius"])
    percent = (printed_ratio - rolling) / rolling * 100.0
    percent_from_quotient = (quotient - rolling) / rolling * 100.0

    return {
        "offset_mm": offset_mm,
        "steer_deg": steer_deg,
        "spin_deg": spin_deg,
        "printed_spin_steer_ratio": printed_ratio,
        "spin_steer_quotient": quotient,
        "spin_steer_quotient_low": quotient_low,
        "spin_steer_quotient_high": quotient_high,
        "spin_steer_ratio_disagrees": disagrees(printed_ratio, quotient, ratio_half),
        "spin_steer_ratio_consistent_with_rounding": (
            (printed_ratio + ratio_half >= quotient_low) & (printed_ratio - ratio_half <= quotient_high)
        ).astype(int),
        "printed_pure_rolling_ratio": printed_rolling,
        "pure_rolling_ratio": rolling,
        "pure_rolling_ratio_disagrees": disagrees(printed_rolling, rolling, half_units("pure_rolling_ratio")),
        "printed_percentage_difference": printed_percent,
        "percentage_difference": percent,
        "percentage_difference_disagrees": disagrees(printed_percent, percent, half_units("percentage_difference")),
        "percentage_difference_from_quotient": percent_from_quotient,
    }
