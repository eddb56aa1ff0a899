"""Rivals of the paper's mechanisms: each derives, is absent at strength 0, and has its own signature against rack.

The rise of the handwheel torque towards lock is put down to lifting in the paper. Each rival
below can also raise the torque; what separates it from lifting is checked here: its shape
against the rack (does it follow the rack position, like lifting, or the rack speed, like a
friction), and how it changes with the wheel load (part laden) and with the spacer offset,
where lifting grows in proportion to the load and with the offset. Each signature is checked
against a closed form written from the physics, not from the effect's code, where one exists.
"""

from __future__ import annotations


import numpy as np
import pytest
from scipy.integrate import cumulative_trapezoid

from parksteer.diagnose.candidates import candidate_effects
from parksteer.errors import UsageError
from parksteer.geometry import steer_axis
from parksteer.model.numeric.simulate import simulate
from parksteer.model.symbolic.components import (discover_effects, known_quantities, resolve_effects,
                                                 strength_parameter, with_effect_quantities)
from parksteer.parameters import load_parameters, registry

from model_helpers import DISSIPATION_OFF, effect_documentation, with_effect, column_angle_per_rack, first_ramp, plateau_mean

# rival -> (strength quantity, a strength well inside its typical range)
RIVALS = {
    "gear_efficiency": ("inefficiency", 0.15),
    "tyre_stribeck": ("breakaway_excess", 0.2),
    "carcass_hysteresis": ("stiffness_fraction", 0.5),
    "top_mount_windup": ("stiffness", 50.0),
    "linkage_nonlinearity": ("cubic_coefficient", 0.2),
    "rolling_resistance": ("coefficient", 0.012),
}
CASES = ("unladen", "part_laden", "offset_68_5mm")


@pytest.fixture(scope="module")
def params():
    """The shipped parameter file, knowing the installed effects' quantities (the rivals' among them)."""
    return with_effect_quantities(load_parameters())


def with_rival(name: str, case: str = "unladen", strength: float | None = None, overrides=None, **kwargs):
    """The paper's model plus one rival, at its default strength (0) or at `strength`."""
    return with_effect(name, RIVALS[name][0], case, strength, overrides, **kwargs)


@pytest.fixture(scope="module")
def paper_runs(params):
    """The paper's model in the three cases that separate the rivals from lifting."""
    return {case: simulate(case, params=params) for case in CASES}


@pytest.fixture(scope="module")
def rival_runs(params):
    """Each rival at its typical strength in the three cases (cached per rival on first use)."""
    runs: dict[tuple[str, str], object] = {}

    def get(name: str, case: str = "unladen"):
        if (name, case) not in runs:
            runs[name, case] = with_rival(name, case, RIVALS[name][1], params=params)
        return runs[name, case]

    return get


def steady(result, params, margin_s: float = 0.5):
    """Samples of steady steering: away from the start, the reversals and the stop by `margin_s`."""
    t = result.columns["time_s"]
    corners = np.cumsum([0.0, params["input.time_to_right_lock"], params["input.time_right_to_left_lock"],
                         params["input.time_left_lock_to_centre"]])
    return np.min(np.abs(t[:, None] - corners[None, :]), axis=1) > margin_s


def sliding(result, params, after_start_s: float = 2.5):
    """Steady sliding of the first stroke: the carcass wound up, the tread sliding, before the lock's rounding."""
    t = result.columns["time_s"]
    return (t > after_start_s) & (t < params["input.time_to_right_lock"] - 0.3)


def lifting_share(result):
    return plateau_mean(result, "contrib_lifting_Nm")


# ---------------------------------------------------------------- registry and absence


def test_rivals_are_off_by_default_and_kept_out_of_the_diagnosis(params):
    """Bookkeeping: each rival is off by default, its strength (in the parameter file's section named after it)
    defaults to 0 inside its bounds with a unit and a source, and the diagnosis does not offer it as a candidate
    (diagnosis_candidate = False), while the eight earlier candidates stay in its list."""
    effects = discover_effects()
    table = registry(known_quantities())
    for name, (strength, typical) in RIVALS.items():
        effect = effects[name]
        assert not effect.in_default_set and not effect.diagnosis_candidate
        documentation = effect_documentation(name)
        assert "Signature" in documentation and "Provenance" in documentation
        key = f"{name}.{strength}"
        assert strength_parameter(effect, params).key == key
        assert params[key] == 0.0 and table[key].unit and params.source(key).startswith("candidate")
        assert table[key].check(typical) == typical
    testable, _ = candidate_effects(resolve_effects(None), effects)
    names = {e.name for e in testable}
    assert not names & set(RIVALS)
    assert {"column_friction", "kingpin_friction", "rack_stiction", "rack_lash", "rack_damping", "ackermann",
            "braked_wheels", "brush_patch"} <= names


@pytest.mark.parametrize("name", sorted(RIVALS))
def test_rival_derives_is_absent_at_zero_and_acts_at_its_strength(name, paper_runs, rival_runs, params):
    """Each rival's model derives and simulates; at strength 0 its cycle is the paper's (within the integrator's
    0.01 N m), at its typical strength it changes the handwheel torque measurably (above 0.1 N m, at the 68.5 mm
    spacer for rolling resistance, which the standard car's 5.8 mm scrub radius makes tiny)."""
    at_zero = with_rival(name, params=params)
    paper = paper_runs["unladen"]
    assert np.max(np.abs(at_zero.columns["handwheel_torque_Nm"] - paper.columns["handwheel_torque_Nm"])) < 0.01
    case = "offset_68_5mm" if name == "rolling_resistance" else "unladen"
    acting = rival_runs(name, case)
    change = acting.columns["handwheel_torque_Nm"] - paper_runs[case].columns["handwheel_torque_Nm"]
    assert np.max(np.abs(change)) > 0.1


def test_linkage_nonlinearity_and_ackermann_cannot_share_the_steer_function():
    """Both fill the steer_function slot (one map from rack to steer angle per model): a set with both is refused
    in one line naming the two."""
    with pytest.raises(UsageError, match="ackermann and linkage_nonlinearity both fill the slot steer_function"):
        resolve_effects("+ackermann,+linkage_nonlinearity")


# ---------------------------------------------------------------- signatures


def test_top_mount_windup_is_a_load_and_offset_free_centring_spring(params, paper_runs, rival_runs):
    """The top mount's spring k delta about each axis reaches the handwheel as sum(k delta) G_rw / (d theta_c /
    d rack) (1e-6 of its peak), odd in the rack and the same on the way out and back at the same rack (no
    hysteresis), like lifting; unlike lifting it is the same unladen, part laden and with the 68.5 mm spacer
    (0.1 %), where lifting's share grows by over 10 % with the load and doubles with the spacer."""
    k = RIVALS["top_mount_windup"][1]
    ratio = params["steering.roadwheel_to_rack_ratio"]
    shares = {}
    for case in CASES:
        result = rival_runs("top_mount_windup", case)
        c = result.columns
        expected = k * (c["steer_left_rad"] + c["steer_right_rad"]) * ratio / column_angle_per_rack(params, c["rack_m"])
        share = c["contrib_top_mount_windup_Nm"]
        assert np.max(np.abs(share - expected)) < 1e-6 * np.max(np.abs(expected))
        shares[case] = (plateau_mean(result, "contrib_top_mount_windup_Nm"), lifting_share(paper_runs[case]))
    for case in ("part_laden", "offset_68_5mm"):
        assert shares[case][0] == pytest.approx(shares["unladen"][0], rel=1e-3)
    assert shares["part_laden"][1] > 1.1 * shares["unladen"][1]
    assert shares["offset_68_5mm"][1] > 1.8 * shares["unladen"][1]


def test_gear_efficiency_friction_is_a_share_of_the_load_and_flips_with_the_motion(params, paper_runs, rival_runs):
    """Mesh friction (1 - eta) |F_road|: in steady steering its handwheel share is (1 - eta) times the rest of the
    handwheel torque (within 2 %, where that is above 2 N m), of the sign of the rack speed (it takes work on every stroke: dissipative), and it
    grows with the wheel load like the torque it is a share of (part laden over unladen as the paper's plateau, 2 %);
    lifting's share keeps its sign at the same rack position on the way back."""
    loss = RIVALS["gear_efficiency"][1]
    plateaus = {}
    for case in ("unladen", "part_laden"):
        result = rival_runs("gear_efficiency", case)
        c = result.columns
        share = c["contrib_gear_efficiency_Nm"]
        rest = c["handwheel_torque_Nm"] - share
        moving = steady(result, params) & (np.abs(rest) > 2.0)  # away from where the torque crosses zero
        assert np.max(np.abs(np.abs(share[moving] / rest[moving]) - loss)) < 0.02 * loss
        rack_speed = np.gradient(c["rack_m"], c["time_s"])
        assert np.all(share[moving] * rack_speed[moving] > 0.0)
        plateaus[case] = plateau_mean(result, "contrib_gear_efficiency_Nm") / plateau_mean(paper_runs[case])
    assert plateaus["part_laden"] == pytest.approx(plateaus["unladen"], rel=0.02)
    back = rival_runs("gear_efficiency").columns
    t = back["time_s"]
    returning = (t > 5.5) & (t < 8.0) & (back["rack_m"] > 0.01)
    assert np.all(back["contrib_gear_efficiency_Nm"][returning] < 0.0) and np.all(
        back["contrib_lifting_Nm"][returning] > 0.0)


def test_tyre_stribeck_is_a_breakaway_hump_scaled_by_the_tyre_moment(params, paper_runs, rival_runs):
    """The breakaway excess a M(W) exp(-(omega / omega_s)^2) tanh(beta omega) on each tread ring reaches the
    handwheel through the axis's vertical component, G_rw and d theta_c / d rack (closed form from the ring yaw
    rates and loads, within 1 % of its peak): humps where the tread is slow, as it slows into each reversal and
    where it breaks away after the carcass wind-up, gone in steady sliding (below 2 % of the peak); its peak on
    each stroke does not change with the spacer offset (2 %), where lifting's share doubles."""
    a = RIVALS["tyre_stribeck"][1]
    rate = params["tyre_stribeck.stribeck_rate"]
    beta = params["steering.friction_smoothing"]
    mu, p, p0, n = (params[k] for k in ("tyre.friction_coefficient", "tyre.tyre_pressure", "tyre.reference_pressure",
                                        "tyre.pressure_index"))
    ratio = params["steering.roadwheel_to_rack_ratio"]
    peaks = {}
    for case in ("unladen", "offset_68_5mm"):
        result = rival_runs("tyre_stribeck", case)
        c = result.columns
        out = result.model.evaluate_outputs(c["time_s"], result.states, result.parameter_vector)
        expected = 0.0
        for side in ("left", "right"):
            load = np.maximum(c[f"load_{side}_N"], 0.0)
            moment = p0 ** (n - 0.5) * 2.0 * mu / (3.0 * np.sqrt(np.pi)) * load**1.5 / p**n
            omega = out[f"ring_yaw_rate_{side}_rad_s"]
            excess = a * moment * np.exp(-(omega / rate) ** 2) * np.tanh(beta * omega)
            expected = expected + excess * steer_axis(params, case, side).direction[2]
        expected = expected * ratio / column_angle_per_rack(params, c["rack_m"])
        share = c["contrib_tyre_stribeck_Nm"]
        peak = np.max(np.abs(share))
        assert peak > 0.2
        assert np.max(np.abs(share - expected)) < 0.01 * peak
        assert np.max(np.abs(share[sliding(result, params)])) < 0.02 * peak
        t = c["time_s"]
        peaks[case] = np.array([np.max(np.abs(share[(t >= a) & (t < b)])) for a, b in ((0.0, 4.5), (4.5, 13.5))])
    np.testing.assert_allclose(peaks["offset_68_5mm"], peaks["unladen"], rtol=0.02)
    assert lifting_share(paper_runs["offset_68_5mm"]) > 1.8 * lifting_share(paper_runs["unladen"])


def test_carcass_hysteresis_stiffens_the_wind_up_and_relaxes_in_sliding(params, paper_runs, rival_runs):
    """A Maxwell branch beside the carcass spring makes the carcass stiffer while it winds up: the torque rises
    faster at the start (above the paper's by over 0.3 N m on average in 0.2-1.2 s) and falls faster after the
    reversal (below it by over 0.3 N m in 4.7-5.5 s); in steady sliding the twist is constant, the branch relaxes
    and the plateau is the paper's (0.05 N m). Its mean in both windows is the same with the 68.5 mm spacer
    (0.03 N m): nothing in it is geometric, whereas lifting grows with the offset."""
    changes = {}
    for case in ("unladen", "offset_68_5mm"):
        result = rival_runs("carcass_hysteresis", case)
        t = result.columns["time_s"]
        change = result.columns["handwheel_torque_Nm"] - paper_runs[case].columns["handwheel_torque_Nm"]
        winding, unwinding = np.mean(change[(t > 0.2) & (t < 1.2)]), np.mean(change[(t > 4.7) & (t < 5.5)])
        assert winding > 0.3 and unwinding < -0.3
        assert np.max(np.abs(change[sliding(result, params)])) < 0.05
        changes[case] = np.array([winding, unwinding])
    np.testing.assert_allclose(changes["offset_68_5mm"], changes["unladen"], atol=0.03)


def test_carcass_hysteresis_dissipates_what_its_damper_takes(params):
    """Energy: with every other friction and damper off, on air bearings, the work done at the handwheel equals the
    change of kinetic and potential energy (the branch's spring included) plus the work the Maxwell damper has
    dissipated, integral of c_m (node rate - ring rate)^2 (1e-4 of the work); that work is positive."""
    name, strength = "carcass_hysteresis", RIVALS["carcass_hysteresis"][1]
    result = with_rival(name, strength=strength, overrides=DISSIPATION_OFF, surface="air_bearing", params=params,
                        t_end_s=3.0, output_dt_s=0.0005, rtol=1e-10)
    model, c = result.model, result.columns
    out = model.evaluate_outputs(c["time_s"], result.states, result.parameter_vector)
    energy_J = out["kinetic_energy_J"] + out["potential_energy_J"] + out["column_energy_J"]
    work_J = cumulative_trapezoid(c["handwheel_torque_Nm"] * c["handwheel_rate_rad_s"], c["time_s"], initial=0.0)
    n = model.n_q
    damping = strength * params["tyre.carcass_torsional_stiffness"] * params["carcass_hysteresis.relaxation_time"]
    rack_rate = result.states[:, n + model.index("rack")]
    power_W = 0.0
    for side in ("left", "right"):
        ring_rate = params["steering.roadwheel_to_rack_ratio"] * rack_rate + result.states[:, n + model.index(
            f"twist_{side}")]
        power_W = power_W + damping * (result.states[:, n + model.index(f"maxwell_{side}")] - ring_rate) ** 2
    dissipated_J = cumulative_trapezoid(power_W, c["time_s"], initial=0.0)
    assert work_J[-1] > 1.0 and dissipated_J[-1] > 0.0
    assert np.max(np.abs(work_J - (energy_J - energy_J[0]) - dissipated_J)) < 1e-4 * work_J[-1]


def test_linkage_nonlinearity_multiplies_every_road_wheel_share(params, paper_runs, rival_runs):
    """steer = G x (1 + c (G x)^2) at both wheels (1e-12), so the rack force a road-wheel moment needs grows by
    d steer / d x / G = 1 + 3 c (G x)^2: near lock the tyre share is the paper's times that factor at the same
    rack (2 %), in every case; the relative rise is the same unladen, part laden and with the spacer (1 %),
    whereas lifting's own share grows with the load and the offset. It also changes the steer angle at lock,
    which a measurement of the wheel angle against the rack shows."""
    c_cubic = RIVALS["linkage_nonlinearity"][1]
    ratio = params["steering.roadwheel_to_rack_ratio"]
    rises = {}
    for case in CASES:
        result, paper = rival_runs("linkage_nonlinearity", case), paper_runs[case]
        c = result.columns
        g_x = ratio * c["rack_m"]
        for side in ("left", "right"):
            np.testing.assert_allclose(c[f"steer_{side}_rad"], g_x * (1.0 + c_cubic * g_x**2), rtol=1e-12, atol=1e-15)
        near_lock = first_ramp(result, 0.058, 0.064)
        tyre = np.interp(c["rack_m"][near_lock], paper.columns["rack_m"][first_ramp(paper, 0.05, 0.07)],
                         paper.columns["contrib_tyre_friction_Nm"][first_ramp(paper, 0.05, 0.07)])
        factor = 1.0 + 3.0 * c_cubic * g_x[near_lock] ** 2
        measured = c["contrib_tyre_friction_Nm"][near_lock] / tyre
        assert np.max(np.abs(measured / factor - 1.0)) < 0.02
        rises[case] = float(np.mean(measured))
    for case in ("part_laden", "offset_68_5mm"):
        assert rises[case] == pytest.approx(rises["unladen"], rel=0.01)


@pytest.mark.parametrize("name", ["top_mount_windup", "linkage_nonlinearity"])
def test_conservative_rivals_keep_the_energy_balance(name, params):
    """The top mount's spring and the nonlinear linkage store and return energy: with every friction and damper off,
    on air bearings, the work done at the handwheel equals the change of kinetic plus potential energy (the top
    mount's spring included) over the first 3 s (1e-4 of the work)."""
    result = with_rival(name, strength=RIVALS[name][1], overrides=DISSIPATION_OFF, surface="air_bearing",
                        params=params, t_end_s=3.0, output_dt_s=0.0005, rtol=1e-10)
    c = result.columns
    out = result.model.evaluate_outputs(c["time_s"], result.states, result.parameter_vector)
    energy_J = out["kinetic_energy_J"] + out["potential_energy_J"] + out["column_energy_J"]
    work_J = cumulative_trapezoid(c["handwheel_torque_Nm"] * c["handwheel_rate_rad_s"], c["time_s"], initial=0.0)
    assert work_J[-1] > 1.0
    assert np.max(np.abs(work_J - (energy_J - energy_J[0]))) < 1e-4 * work_J[-1]


def test_rolling_resistance_grows_with_the_scrub_radius_and_flips_with_the_motion(params, paper_runs, rival_runs):
    """Rolling resistance C_rr W |e| tanh(beta omega) about each axis (omega the tread's rate about it) reaches the
    handwheel as its sum times G_rw / (d theta_c / d rack) (0.5 % of its peak, e the scrub radius from the
    geometry); in steady steering, wherever both treads turn, it has the sign of the rack speed
    (dissipative); with the 68.5 mm spacer (e = 62.7 against 5.8 mm) it is over 8 times larger, proportional
    to the offset like lifting is not (lifting doubles), and on the way back it changes sign where lifting's
    share keeps it."""
    coefficient = RIVALS["rolling_resistance"][1]
    ratio = params["steering.roadwheel_to_rack_ratio"]
    plateaus = {}
    for case in ("unladen", "offset_68_5mm"):
        result = rival_runs("rolling_resistance", case)
        c = result.columns
        out = result.model.evaluate_outputs(c["time_s"], result.states, result.parameter_vector)
        rolling = np.ones(len(c["time_s"]), dtype=bool)  # both treads turning (not held while a carcass unwinds)
        expected = 0.0
        for side in ("left", "right"):
            axis = steer_axis(params, case, side)
            rate = out[f"ring_yaw_rate_{side}_rad_s"] / axis.direction[2]  # the tread's rate about its axis
            turning = np.tanh(params["steering.friction_smoothing"] * rate)
            rolling &= np.abs(turning) > 0.99
            expected = expected + coefficient * c[f"load_{side}_N"] * abs(axis.scrub_radius_m()) * turning
        expected = expected * ratio / column_angle_per_rack(params, c["rack_m"])
        share = c["contrib_rolling_resistance_Nm"]
        assert np.max(np.abs(share - expected)) < 0.005 * np.max(np.abs(expected))
        rack_speed = np.gradient(c["rack_m"], c["time_s"])
        rolling &= steady(result, params)
        assert np.mean(rolling) > 0.4 and np.all(share[rolling] * rack_speed[rolling] > 0.0)
        plateaus[case] = plateau_mean(result, "contrib_rolling_resistance_Nm")
    assert plateaus["offset_68_5mm"] > 8.0 * plateaus["unladen"]
    assert lifting_share(paper_runs["offset_68_5mm"]) < 3.0 * lifting_share(paper_runs["unladen"])
