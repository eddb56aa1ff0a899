"""The diagnosis's peers (parksteer.experiments.peers): STLSQ and FROLS on constructed residuals, the mapping of
their selections onto the diagnosis's verdicts, the tuning, and (slow) the library of a real diagnosis."""

from __future__ import annotations

import numpy as np
import pytest

from parksteer.experiments.peer_methods import (
    FROLS_SETTINGS,
    STLSQ_RIDGES,
    STLSQ_SETTINGS,
    STLSQ_THRESHOLDS,
    frols,
    frols_ranking,
    generic_terms,
    library_from,
    peer_answers,
    portable_stlsq,
    setting_label,
    stlsq,
    verdict_of,
)
from parksteer.experiments.peer_scoring import score_method, tune

SAMPLES = 4000
RATIO = 186.47  # rad/m, the parameter file's handwheel-to-rack ratio
SMOOTHING = 1000.0  # s/m, its friction smoothing


def _library(residual_of, seed=0):
    """A library over two slow strokes lock to lock (generic terms and a candidate's breakaway bump at each
    reversal, named rack_stiction), and the residual `residual_of(columns, noise)` on it."""
    rng = np.random.default_rng(seed)
    t = np.linspace(0.0, 40.0, SAMPLES)
    x = 0.07 * np.sin(2.0 * np.pi * t / 20.0)
    v = 0.07 * 2.0 * np.pi / 20.0 * np.cos(2.0 * np.pi * t / 20.0)
    terms = generic_terms(x, v, RATIO, SMOOTHING)
    reversals = np.arange(5.0, 40.0, 10.0)
    terms["rack_stiction"] = sum(np.exp(-(((t - r) / 0.3) ** 2)) * np.sign(t - r) * np.sign(np.cos(np.pi * r / 10))
                                 for r in reversals)
    owners = {k: None for k in terms} | {"rack_stiction": "rack_stiction"}
    unit = library_from(np.zeros(SAMPLES), terms, owners)  # the unit-RMS columns
    columns = {name: unit.matrix[:, i] for i, name in enumerate(unit.names)}
    return library_from(residual_of(columns, rng.normal(size=SAMPLES)), terms, owners)


def test_library_columns_have_unit_rms_and_a_zero_column_is_left_out():
    library = library_from(np.zeros(10), {"a": np.arange(10.0), "zero": np.zeros(10)}, {"a": None, "zero": None})
    assert library.names == ("a",)
    assert np.sqrt(np.mean(library.matrix[:, 0] ** 2)) == pytest.approx(1.0)


@pytest.mark.parametrize("term", ["sign(v)", "rack_stiction"])
def test_stlsq_selects_the_one_term_the_residual_holds_and_no_other(term):
    library = _library(lambda c, noise: 0.3 * c[term] + noise)
    selected = stlsq(library, 0.2)
    assert list(selected) == [term]
    assert selected[term] == pytest.approx(0.3, abs=0.05)  # the term's RMS contribution, in noise floors


@pytest.mark.parametrize("threshold, alpha", [(0.3, 0.05), (0.5, 50.0), (1.0, 500.0)])
def test_the_portable_stlsq_selects_what_pysindys_own_does_with_the_same_coefficients(threshold, alpha):
    """The same algorithm on other linear-algebra kernels: on sparse regressions with two nearly collinear terms,
    PySINDy's STLSQ (scikit-learn's ridge and LAPACK) and the portable one select the same terms, and their
    coefficients agree to rounding of the normal equations (1e-9 of coefficients of order 1)."""
    import warnings

    from pysindy.optimizers import STLSQ

    rng = np.random.default_rng(1)
    for _ in range(40):
        x = rng.normal(size=(500, 12))
        x[:, 3] = x[:, 2] + 0.1 * rng.normal(size=500)
        truth = np.zeros(12)
        truth[rng.choice(12, 3, replace=False)] = rng.normal(scale=2.0, size=3)
        y = np.sum(x * truth, axis=1) + rng.normal(scale=0.5, size=500)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            theirs = STLSQ(threshold=threshold, alpha=alpha, max_iter=20).fit(x, y).coef_.ravel()
            ours = portable_stlsq(threshold=threshold, alpha=alpha, max_iter=20,
                                  initial_guess=np.ones((1, 12))).fit(x, y).coef_.ravel()
        assert np.array_equal(theirs != 0.0, ours != 0.0)
        assert np.max(np.abs(theirs - ours)) < 1e-9


@pytest.mark.parametrize("term", ["sign(v)", "rack_stiction"])
def test_frols_ranks_the_term_the_residual_holds_first_and_selects_only_it(term):
    library = _library(lambda c, noise: 0.3 * c[term] + noise)
    ranking = frols_ranking(library)
    assert ranking.names[0] == term
    assert ranking.err[0] == pytest.approx(0.09 / 1.09, abs=0.02)  # 0.3^2 of 1 + 0.3^2
    assert list(frols(ranking, "bic", 0.01)) == [term]


def test_frols_errs_add_up_to_the_share_a_least_squares_fit_on_the_taken_terms_removes():
    library = _library(lambda c, noise: 0.5 * c["x^2"] - 0.4 * c["sin(theta)"] + 0.2 * c["|v|"] + noise)
    ranking = frols_ranking(library, max_terms=4)
    taken = library.matrix[:, [library.names.index(n) for n in ranking.names]]
    y = library.residual
    left = y - taken @ np.linalg.lstsq(taken, y, rcond=None)[0]
    assert sum(ranking.err) == pytest.approx(1.0 - (left @ left) / (y @ y), rel=1e-9)
    assert set(ranking.names[:3]) == {"x^2", "sin(theta)", "|v|"}
    # the criterion falls while a real term is taken
    assert ranking.bic[2] < ranking.bic[0] and ranking.aic[2] < ranking.aic[1]


def test_a_null_residual_selects_nothing_from_moderate_thresholds_on():
    library = _library(lambda c, noise: noise, seed=3)
    assert all(not stlsq(library, t) for t in STLSQ_THRESHOLDS if t >= 0.2)
    ranking = frols_ranking(library)
    assert all(not frols(ranking, c, tol) for c, tol in FROLS_SETTINGS if tol >= 0.001)
    # the smallest settings do answer on noise, STLSQ with opposing coefficients on terms that nearly make one
    # another (the constant, |v|, x^2 and |x| x over lock-to-lock strokes): what the tuning is for
    assert len(stlsq(library, STLSQ_THRESHOLDS[0])) > 1 and frols(ranking, "aic", 0.0)


def test_selections_map_onto_the_diagnosis_verdicts():
    library = library_from(np.zeros(4), {"sign(v)": np.array([1.0, -1, 1, -1]), "x": np.arange(4.0),
                                         "rack_stiction": np.array([0.0, 1, 0, 2]),
                                         "column_friction": np.array([1.0, 2, 0, 0])},
                           {"sign(v)": None, "x": None, "rack_stiction": "rack_stiction",
                            "column_friction": "column_friction"})
    assert verdict_of({}, library) == ("adequate", None)
    assert verdict_of({"sign(v)": 2.0, "x": -1.0}, library) == ("unexplained", None)
    # a candidate's signature names it, whatever generic terms beside it; of two, the larger contribution
    assert verdict_of({"sign(v)": 5.0, "rack_stiction": 0.4}, library) == ("missing", "rack_stiction")
    assert verdict_of({"rack_stiction": 0.4, "column_friction": -0.9}, library) == ("missing", "column_friction")


def test_every_setting_of_the_grid_answers_and_the_hidden_term_is_named():
    library = _library(lambda c, noise: 0.5 * c["rack_stiction"] + noise)
    answers = peer_answers(library)
    assert set(answers["stlsq"]) == {setting_label("stlsq", s) for s in STLSQ_SETTINGS}
    assert set(answers["frols"]) == {setting_label("frols", s) for s in FROLS_SETTINGS}
    assert answers["stlsq"]["threshold=0.2 ridge=0n"]["effect"] == "rack_stiction"
    assert answers["stlsq"]["threshold=3 ridge=0n"]["verdict"] == "adequate"  # above the term's 0.5
    assert answers["frols"]["bic err>=0.01"]["effect"] == "rack_stiction"


def _case(hidden, stlsq_answers, benchmark="variations", kind=None):
    truth = {"hidden": hidden, "steps_requested": 3.5 if hidden else None, "kind": kind}
    return {"name": f"case_{hidden}", "split": "tuning", "benchmark": benchmark, "truth": truth,
            "diagnosis": {"verdict": "adequate", "effect": None, "outcome": {"named": False, "confident_wrong": False}},
            "stlsq": {setting_label("stlsq", (t, r)): {"verdict": v, "effect": e}
                      for t, (v, e) in zip(STLSQ_THRESHOLDS, stlsq_answers) for r in STLSQ_RIDGES},
            "time_s": {"diagnose": 10.0, "upstream": 5.0, "stlsq": 0.01, "frols": 0.01},
            "replays": {"diagnose": 200, "upstream": 120}}


def test_tuning_takes_the_setting_that_names_the_hidden_effects_and_keeps_the_nulls_adequate():
    k = len(STLSQ_THRESHOLDS)
    named = [("missing", "rack_lash")] * 4 + [("adequate", None)] * (k - 4)  # named up to the 4th threshold
    null = [("unexplained", None)] * 2 + [("adequate", None)] * (k - 2)  # quiet from the 3rd on
    cases = [_case("rack_lash", named), _case(None, null)]
    best, table = tune(cases, "stlsq")
    # the largest threshold and ridge of the equal best (the 3rd and 4th thresholds, any ridge)
    assert best == setting_label("stlsq", (STLSQ_THRESHOLDS[3], STLSQ_RIDGES[-1]))
    scores = {row["setting"]: row["score"] for row in table}
    assert [scores[setting_label("stlsq", (t, 0.0))] for t in STLSQ_THRESHOLDS[:5]] == [0.5, 0.5, 1.0, 1.0, 0.5]
    numbers = score_method(cases, "stlsq", best)
    assert numbers["named"] == [1, 1] and numbers["null_adequate"] == [1, 1]


def test_an_out_of_class_rival_answered_with_an_unrelated_candidate_is_a_peers_confident_wrong_answer():
    rival = _case("gear_efficiency", [("missing", "tyre_relaxation")] * len(STLSQ_THRESHOLDS), "outclass", "rival")
    rival["truth"].update(closest="column_friction", related=["kingpin_friction"])
    related = _case("gear_efficiency", [("missing", "kingpin_friction")] * len(STLSQ_THRESHOLDS), "outclass", "rival")
    related["truth"].update(closest="column_friction", related=["kingpin_friction"])
    numbers = score_method([rival, related], "stlsq", "threshold=1 ridge=0n")
    assert numbers["confident_wrong"] == 1
    assert numbers["outclass"] == {"closest or related": 1, "unrelated": 1, "unexplained": 0, "adequate": 0}


@pytest.mark.slow
def test_the_library_of_a_real_diagnosis_holds_its_residual_and_its_candidates_signatures(written, params):
    from parksteer.experiments.peer_methods import record_library
    from parksteer.diagnose.problem import load_files
    from parksteer.diagnose.select import diagnose

    paths, _truth = written("peers_null", "null", None, None)
    diagnosis = diagnose(load_files(paths, params), params)
    library = record_library(diagnosis)
    assert np.array_equal(library.residual, diagnosis.calibration.weighted)
    observable = [c for c in diagnosis.candidates if c.signature.observable]
    for candidate in observable:
        column = library.column(candidate.name)
        w = candidate.signature.weighted
        assert np.allclose(column, w / np.sqrt(np.mean(w**2)))
    assert {"sign(v)", "x^3", "cos(2theta)"} <= set(library.names)
    assert library.matrix.shape == (diagnosis.problem.n, len(library.names))
    # the replays are counted as they run: never fewer after a stage than before it, all of them by the end, and
    # the peers' share (up to the signatures) short of the whole, since the refits replay the candidates again
    counts = list(diagnosis.replays_by_stage.values())
    assert counts == sorted(counts) and counts[-1] == diagnosis.replays
    assert 0 < diagnosis.replays_by_stage["signatures_and_scores"] < diagnosis.replays


def test_the_comparison_tunes_on_the_tuning_split_and_scores_on_the_evaluation_records():
    from parksteer.experiments.peer_scoring import compare

    k = len(STLSQ_THRESHOLDS)
    frols_quiet = {setting_label("frols", s): {"verdict": "adequate", "effect": None} for s in FROLS_SETTINGS}

    def case(split, hidden, answers):
        c = _case(hidden, answers)
        c["split"], c["frols"] = split, frols_quiet
        c["diagnosis"]["outcome"]["named"] = hidden is not None
        return c

    # tuning: the hidden effect named up to the 5th threshold, the null quiet from the 3rd; evaluation: the
    # hidden effect named only up to the 2nd, so the tuned 5th threshold misses it
    cases = [case("tuning", "rack_lash", [("missing", "rack_lash")] * 5 + [("adequate", None)] * (k - 5)),
             case("tuning", None, [("unexplained", None)] * 2 + [("adequate", None)] * (k - 2)),
             case("evaluation", "rack_lash", [("missing", "rack_lash")] * 2 + [("adequate", None)] * (k - 2))]
    comparison = compare(cases)
    assert comparison["records"] == {"tuning": 2, "evaluation": 1}
    ours, stlsq_row, frols_row = comparison["methods"]
    assert stlsq_row["setting"] == setting_label("stlsq", (STLSQ_THRESHOLDS[4], STLSQ_RIDGES[-1]))
    assert stlsq_row["named"] == [0, 1] and ours["named"] == [1, 1]
    assert comparison["grids"]["stlsq"]["tied_best"] == [setting_label("stlsq", (t, r))
                                                         for t in STLSQ_THRESHOLDS[2:5] for r in STLSQ_RIDGES]
    assert comparison["grids"]["stlsq"]["tied_best_evaluation"]["named"] == [0, 0]
    assert frols_row["named"] == [0, 1]
    # a peer replays nothing of its own: what it needs is the diagnosis's replays up to the signatures
    assert (ours["replays_median"], stlsq_row["replays_median"], stlsq_row["replays_with_upstream_median"]) == \
        (200, 0, 120)


@pytest.mark.slow
def test_the_peers_run_beside_a_benchmark_batch_are_those_of_diagnosing_its_files_again(tmp_path):
    """The variation and out-of-class batches run the peers on the diagnosis they have just made
    (peers_beside), instead of a peers job reading the written records back and diagnosing them again: the same
    records and settings give the same diagnosis, so both records agree in everything but the machine's times."""
    import json

    from parksteer.experiments.benchmark import run_batch
    from parksteer.synthetic.datasets import BASE_PERTURBATION
    from parksteer.experiments.peers import peers_beside, peers_file_name, run_peer_batch
    from parksteer.experiments.variations import VariationDesign, run_case, variation_cases
    from parksteer.parameters import DEFAULT_PATH

    files = (("unladen", "ground"), ("part_laden", "ground"), ("offset_68_5mm", "ground"))
    design = VariationDesign(("pauses",), 1, ("rack_stiction",), (3.5,), files, 11, BASE_PERTURBATION)
    name = next(c.name for c in variation_cases(design) if c.hidden is None)
    batch = tmp_path / "variations_00"
    run_batch(run_case, DEFAULT_PATH, design, [name], batch, on_diagnosis=peers_beside("variations"))
    beside = json.loads((batch / peers_file_name("evaluation", name)).read_text(encoding="utf-8"))
    run_peer_batch(DEFAULT_PATH, [f"variations:{batch / (name + '.truth.json')}"], tmp_path / "peers")
    again = json.loads((tmp_path / "peers" / peers_file_name("evaluation", name)).read_text(encoding="utf-8"))
    for record in (beside, again):
        record.pop("time_s")
    assert beside == again
    said = beside["diagnosis"]
    assert beside["replays"]["diagnose"] > 0
    assert said["benchmark_said"] == (said["effect"] if said["verdict"] == "missing" else said["verdict"])
