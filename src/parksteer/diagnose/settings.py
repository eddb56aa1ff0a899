"""Every setting of compare, diagnose, the synthetic car data set and the hidden-effect benchmark.

This module is their one home: they are settings of the method (smoothing, fitting, model
selection) and of the synthetic experiments, not properties of the car, so they live beside
the method rather than in data/parameters.toml, each with its unit and its reason. Nothing
else in :mod:`parksteer.diagnose` hard-codes a threshold, a strength or a seed.
"""

from __future__ import annotations

# --- replay of a measured rack (parksteer.diagnose.replay) -------------------------------------
# The rack is smoothed by a least-squares cubic spline with evenly spaced knots (and one at each
# reversal). The spacing is the largest whose fit residual (per degree of freedom) is within this
# factor of the rack's own noise (estimated from its second differences): the discrepancy
# principle, so the spline follows the motion but not the noise or the converter's steps.
RACK_DISCREPANCY_FACTOR = 1.05  # 1
# Knot spacings tried, s: never closer than this many samples (a spline needs data in every
# interval) ...
RACK_MIN_SAMPLES_PER_KNOT = 4  # 1
# ... and within this range. Below 0.15 s the spline starts to follow the noise, and its speed
# then crosses zero where the rack does not move backwards, which flips the rack friction; above
# 0.4 s it cannot follow a reversal of the hand (the paper's cycle turns within about 0.4 s). The
# rack noise estimate from second differences of 8-bit data is itself uncertain by a few per cent,
# too little to choose reliably between neighbouring spacings, so the range does most of the work.
RACK_KNOT_SPACING_RANGE_S = (0.15, 0.4)
RACK_KNOT_SPACING_STEP = 1.15  # 1, ratio between spacings tried
# Reversals (where the spline gets a knot) are found from the speed of a local straight-line fit
# over this window, as parksteer.measure.phases finds strokes.
RACK_TURN_WINDOW_S = 0.5
# Each end of the record is held at rest unless that raises the fit's sum of squares by more than
# this many noise variances (see parksteer.diagnose.replay._lsq_fit).
RACK_REST_TEST_CHI2 = 25.0  # 1
# Replays of racks logged again through the file's logger and smoothed again (or, without a stated
# logger, drawn from the spline's least-squares distribution), whose torque spread is the replay's
# uncertainty at each sample (parksteer.diagnose.problem).
REPLAY_ENSEMBLE_DRAWS = 8
REPLAY_ENSEMBLE_SEED = 271828
# Integrator tolerances of the replay: relative, and a multiple of the model's own absolute
# tolerances (parksteer.model.numeric.simulate). Checked against the model's tight tolerances: the
# torque moves by under 1e-3 N m, a few thousandths of a converter step.
REPLAY_RTOL = 1e-5  # 1
REPLAY_ATOL_FACTOR = 100.0  # 1

# --- calibration (parksteer.diagnose.calibrate) ---------------------------------------------------
# The base model's uncertain parameters, fitted before any candidate is considered, with the
# relative step of their finite-difference sensitivities and their plausible range (a factor
# either side of the nominal value; the fit is in the logarithm so it stays positive).
CALIBRATED_PARAMETERS = (
    "tyre_friction.friction_coefficient",
    "rack_friction.friction_force",
    "carcass_compliance.torsional_stiffness",
)
CALIBRATION_RELATIVE_STEP = 0.03  # 1
CALIBRATION_RANGE_FACTOR = 3.0  # 1
CALIBRATION_MAX_ITERATIONS = 10
# A fit has converged when its Gauss-Newton step is below this fraction of every parameter's standard error.
CALIBRATION_TOLERANCE = 0.3  # 1
# The Jacobian is recomputed by finite differences at the end of a fit when a parameter has moved
# by more than this (in its fitted variable: 0.15 is 15 % of a log-fitted value) since it was taken.
JACOBIAN_REFRESH_THETA = 0.15

# --- candidates, score test and selection (parksteer.diagnose.candidates, .select) --------------------
# A candidate's signature is taken at a probe strength giving this RMS torque change (in noise
# floors): large enough to stand above the integrator's noise, small enough to be nearly linear.
PROBE_EFFECT_NOISE_FLOORS = 3.0  # 1
# First probe, as a fraction of the strength's upper bound, before scaling to the target above.
PROBE_START_FRACTION = 1e-3  # 1
PROBE_MAX_TRIES = 4
# A candidate whose largest strength changes the replayed torque by less than this many noise
# floors RMS is unobservable in the data as replayed.
UNOBSERVABLE_NOISE_FLOORS = 0.1  # 1
# How many of the best-scored candidates are refitted in the full nonlinear model.
REFIT_COUNT = 3
REFIT_MAX_ITERATIONS = 10
# Information criterion over the effective sample size n_eff = n (1 - rho) / (1 + rho), rho the
# lag-1 autocorrelation of the best model's residual: a candidate is "missing" when adding it
# lowers the BIC by more than this (Kass & Raftery: above 10 is very strong evidence) ...
BIC_MISSING_THRESHOLD = 10.0  # 1
# ... and with it the weighted error is within ADEQUATE_RMS_FACTOR of the noise floor, or it
# removes at least this fraction of the weighted sum of squares above the floor.
EXPLAINED_FRACTION_MISSING = 0.6  # 1
# Candidates within this BIC of the best one are indistinguishable by these data (above 6 is
# strong evidence for the better one).
BIC_INDISTINGUISHABLE = 6.0  # 1
# "adequate": the calibrated base model's weighted RMS error is within this factor of the noise
# floor (each sample weighted by the noise floor combined with the replay's uncertainty there).
# Null data sets sit at 1.0 to 1.1 (the replay's uncertainty is estimated from 8 draws).
ADEQUATE_RMS_FACTOR = 1.15  # 1
# A candidate whose signature keeps less than this fraction of its norm once the calibrated
# parameters' directions are projected out is reported as confounded with them.
CONFOUNDED_FRACTION = 0.3  # 1

# --- the error ladder and the reports -------------------------------------------------------------
LADDER_MAX_STEPS = 3  # effects added one at a time beyond the calibrated base

# --- the synthetic car data set (parksteer.synthetic.datasets) -----------------------------------
# Stand-in for the paper's car tests, with ONE hidden effect the paper's model lacks at a realistic
# strength: breakaway friction of the rack 300 N above its kinetic friction (the candidate's
# provenance gives 0-400 N as typical beside F = 730 N). Its name is kept out of the files' names
# and metadata; the case study reads it from results/diagnose/car_truth.json at its end.
CAR_HIDDEN_EFFECT = "rack_stiction"
CAR_HIDDEN_STRENGTH = 300.0  # N, rack_stiction.breakaway_excess
# The paper's car tests: Fig. 5 (unladen, part laden), Fig. 7 (three spacers on the ground), Fig. 8
# (three spacers on air bearings). The standard car on air bearings is left unmeasured, so that a
# diagnosis has conditions left to propose.
CAR_FILES = (
    ("unladen", "ground"),
    ("part_laden", "ground"),
    ("offset_12_7mm", "ground"),
    ("offset_44_5mm", "ground"),
    ("offset_68_5mm", "ground"),
    ("offset_12_7mm", "air_bearing"),
    ("offset_44_5mm", "air_bearing"),
    ("offset_68_5mm", "air_bearing"),
)
CAR_SEED = 1983  # the year of the Maestro road test the lock angle comes from
# File i's hand is seeded 100 CAR_SEED + i and its logger noise 100 CAR_SEED + 50 + i; the base
# parameters are perturbed as the benchmark's (BENCHMARK_PERTURBATION), seeded CAR_SEED.

# --- the hidden-effect benchmark (parksteer.synthetic.datasets, .benchmark) -------------------------
# Strengths: the RMS torque change of the hidden effect over the data set's files, in converter
# steps; found by bisection on the strength.
BENCHMARK_STEPS = (1.0, 2.0, 3.5, 5.0)
BENCHMARK_BISECTION_ITERATIONS = 12
BENCHMARK_BISECTION_TOLERANCE = 0.05  # 1, relative error of the RMS change accepted
# Each benchmark data set: the paper's Fig. 5 pair (the unladen and the part laden car, whose loads
# differ by 13 %) and the largest spacer (Fig. 7), all on the ground: loads and offset both vary.
BENCHMARK_FILES = (("unladen", "ground"), ("part_laden", "ground"), ("offset_68_5mm", "ground"))
# Perturbation of the base parameters of every data set: uniform within +- these fractions.
BENCHMARK_PERTURBATION = {
    "tyre_friction.friction_coefficient": 0.10,
    "rack_friction.friction_force": 0.15,
    "carcass_compliance.torsional_stiffness": 0.20,
}
BENCHMARK_NULLS = 8
BENCHMARK_SEED = 20250101  # data set k is seeded BENCHMARK_SEED + k (hands, loggers, perturbation)
# Disturbances no candidate models, each at the RMS torque change of this many converter steps.
BENCHMARK_DISTURBANCE_STEPS = (3.0, 5.0)
# Channel lag (a disturbance): the bisection on the lag of the torque channel searches up to this.
BENCHMARK_MAX_LAG_S = 0.3
