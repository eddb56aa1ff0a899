"""Replay a measured rack motion through the model: the parameter bookkeeping of the diagnosis.

The rack is smoothed once (:func:`parksteer.measure.smoothing.smooth_rack`, which says why) and
replayed through the model's prescribed-rack solver (:func:`parksteer.model.numeric.prescribed.solve`)
for every parameter set a fit or a candidate asks for. This module only keeps the prepared runs:
the compiled model, the parameter vector and the static balance are made once per effect set and
per override of a quantity that shapes them (a case value, the geometry), while an override of a
quantity that only enters the equations is written into a copy of the vector.

A solve asked for again with the same inputs (the model, its vector, the rack, the times) is answered from the
latest solves (:class:`SolutionMemo`), bit for bit the solve it would make, and counted as a replay all the same.

A diagnosis replays most candidates in one compiled model, the diagnosis model
(:func:`parksteer.diagnose.candidates.diagnosis_model`): the replay engine
(:class:`parksteer.diagnose.engine.ReplayEngine`) makes a replay of an effect set it maps on the compiled model of
its host set (`model_effects`), the other candidates there at their values, strength 0.
"""

from __future__ import annotations

from dataclasses import dataclass, field, fields

import numpy as np

from ..measure.rack_spline import RackSpline
from ..errors import UsageError
from ..model.numeric.assisted import solve_assisted
from ..model.numeric.compiled import CompiledModels
from ..model.numeric.prescribed import PrescribedSolution, rack_table, solve, twist_spread
from ..model.numeric.simulate import PreparedRun, prepare
from ..model.symbolic.components import Effect, power_assist_of
from ..parameters import Parameters

# Prepared runs kept per replay: the base run and the latest others.
KEPT_RUNS = 8
# Solves kept per memo (SolutionMemo), at most this many and this many bytes: a diagnosis asks for the same replay
# again some replays later (each candidate's signature replays the calibrated model at strength 0 on the diagnosis
# model: the same vector each time, a few files by a few probes apart).
KEPT_SOLUTIONS = 64
KEPT_SOLUTION_BYTES = 64 * 2**20


def _arrays(solution: PrescribedSolution) -> list[np.ndarray]:
    """The arrays `solution` holds (an assisted solve's motor channels among them)."""
    out = []
    for f in fields(solution):
        value = getattr(solution, f.name)
        out += [v for v in (value.values() if isinstance(value, dict) else [value]) if isinstance(v, np.ndarray)]
    return out


def copied(solution: PrescribedSolution) -> PrescribedSolution:
    """`solution` (an assisted solve's too) with every array its own copy, the same bits, so that a caller changing
    one changes no other."""
    def own(value):
        if isinstance(value, np.ndarray):
            return value.copy()
        if isinstance(value, dict):
            return {key: own(item) for key, item in value.items()}
        return value

    return type(solution)(**{f.name: own(getattr(solution, f.name)) for f in fields(solution)})


class SolutionMemo:
    """The latest solves of a family of replays by their exact inputs (:meth:`Replay.solve`): the compiled model, its
    effects, the parameter vector's bytes, the rack's table and ends, the output times' bytes and whether the outputs
    were asked for. A solve is a deterministic function of these, so a solve found here is the one it would compute,
    bit for bit; it is handed out as a copy (:func:`copied`). A replay engine's replays share one
    (:attr:`parksteer.diagnose.engine.ReplayEngine.solutions`); a worker process's copy is its own."""

    __slots__ = ("kept", "kept_bytes", "found")

    def __init__(self) -> None:
        self.kept: dict[tuple, tuple[PrescribedSolution, int]] = {}
        self.kept_bytes = 0
        self.found = 0  # solves answered from the memo

    def get(self, key: tuple) -> PrescribedSolution | None:
        """A copy of the solve kept under `key`, or None."""
        kept = self.kept.get(key)
        if kept is None:
            return None
        self.found += 1
        return copied(kept[0])

    def keep(self, key: tuple, solution: PrescribedSolution) -> None:
        """Keep a copy of `solution` under `key`, the oldest dropped beyond KEPT_SOLUTIONS or KEPT_SOLUTION_BYTES."""
        solution = copied(solution)
        size = sum(a.nbytes for a in _arrays(solution))
        if size > KEPT_SOLUTION_BYTES:
            return
        while self.kept and (len(self.kept) >= KEPT_SOLUTIONS or self.kept_bytes + size > KEPT_SOLUTION_BYTES):
            self.kept_bytes -= self.kept.pop(next(iter(self.kept)))[1]
        self.kept[key] = (solution, size)
        self.kept_bytes += size


class SolveCount:
    """The solves of a family of replays, counted together: the replays a replay engine makes share one
    (:attr:`parksteer.diagnose.engine.ReplayEngine.solves`), and so do the replays made from one of them on
    another rack or at other instants (:meth:`Replay.on_rack`, :meth:`Replay.at_times`), kept or not."""

    __slots__ = ("solves",)

    def __init__(self) -> None:
        self.solves = 0


@dataclass
class Replay:
    """The model of one effect set, driven by one smoothed rack, for one case and surface.

    :meth:`torque` replays it with overrides ({key: value}, the keys of ``parksteer simulate --set``)
    and returns the handwheel torque at the requested times. A run is prepared once (compiled
    model, parameter vector, static balance). An override that only enters the equations (an
    entry of the compiled model's parameter vector and nothing else) changes that entry of a
    copy of the vector; any other (a case value, the geometry, anything the preparation derives
    from) prepares the run again. Which is which is found once per compiled model and key: by
    preparing the run with the key changed and seeing whether anything else in the vector moves.
    """

    effects: list[Effect]
    case: str
    surface: str
    params: Parameters
    rack: RackSpline  # the file's smoothed rack, or a draw of the replay's uncertainty
    time_s: np.ndarray
    base_overrides: dict[str, float] = field(default_factory=dict)
    evaluations: int = 0
    # prepared runs to start from (another replay's of the same model, case and surface: :meth:`on_rack`)
    runs: dict[tuple, PreparedRun] | None = field(default=None, repr=False, compare=False)
    # prepared runs shared with the other replays of the same compiled model, case, surface and parameters, kept
    # in this dict itself (ReplayEngine.new_replay): a run is what its overrides make it, whichever replay made it
    shared_runs: dict[tuple, PreparedRun] | None = field(default=None, repr=False, compare=False)
    # the effects of the compiled model it runs on: by default the set's own (a host's: ReplayEngine.new_replay)
    model_effects: list[Effect] | None = field(default=None, repr=False, compare=False)
    # (compiled model, quantity key) -> whether the quantity only enters the equations (_is_direct), shared by the
    # replays of one engine (ReplayEngine.direct); by default this replay's own
    direct: dict[tuple[str, str], bool] | None = field(default=None, repr=False, compare=False)
    # the compiled models it loads through, shared by the replays of one engine (ReplayEngine.models); by default
    # this replay's own
    models: CompiledModels | None = field(default=None, repr=False, compare=False)
    # the count its solves add to besides its own `evaluations`, shared with the replays made from it
    counter: SolveCount | None = field(default=None, repr=False, compare=False)
    # the latest solves by their exact inputs, shared by the replays of one engine (ReplayEngine.solutions) and those
    # made from them; by default this replay's own
    solutions: SolutionMemo | None = field(default=None, repr=False, compare=False)

    def __post_init__(self):
        self.time_s = np.asarray(self.time_s, dtype=float)
        if self.shared_runs is not None:
            self._runs = self.shared_runs
        else:
            self._runs: dict[tuple, PreparedRun] = dict(self.runs) if self.runs is not None else {}
        self.runs = self.shared_runs = None
        if self.model_effects is None:
            self.model_effects = self.effects
        if self.direct is None:
            self.direct = {}
        if self.models is None:
            self.models = CompiledModels()
        if self.solutions is None:
            self.solutions = SolutionMemo()
        self._drive_key: tuple[bytes, ...] | None = None  # made at the first solve (_solve_key)
        self._base = self._prepared(self.base_overrides)

    def on_rack(self, rack: RackSpline) -> Replay:
        """The same model, case and surface driven by another rack, at the same times: the prepared runs
        (which do not depend on the rack) are shared, not made again."""
        return self._sharing(rack, self.time_s)

    def at_times(self, time_s: np.ndarray) -> Replay:
        """The same model, case, surface and rack replayed at other instants (a lagged channel's): the prepared
        runs are shared, not made again."""
        return self._sharing(self.rack, time_s)

    def _sharing(self, rack: RackSpline, time_s: np.ndarray) -> Replay:
        return Replay(self.effects, self.case, self.surface, self.params, rack, time_s, dict(self.base_overrides),
                      runs=self._runs, model_effects=self.model_effects, direct=self.direct,
                      models=self.models, counter=self.counter, solutions=self.solutions)

    def _prepared(self, overrides: dict[str, float]) -> PreparedRun:
        key = tuple(sorted(overrides.items()))
        if key not in self._runs:
            if len(self._runs) >= KEPT_RUNS:  # a fit moving a prepared quantity makes a new run at every step
                # (the oldest run but this replay's base; a shared dict's other bases stay with their replays)
                del self._runs[next(k for k in self._runs if self._runs[k] is not getattr(self, "_base", None))]
            self._runs[key] = prepare(self.case, self.model_effects, overrides, self.surface, self.params,
                                     models=self.models)
        return self._runs[key]

    def _is_direct(self, key: str, value: float) -> bool:
        """Whether `key` only enters the compiled model's equations (so it can be set in the vector directly).

        A property of the model's structure, found once per compiled model and key.
        """
        base = self._base
        known = (base.model.directory.name, key)
        if known in self.direct:
            return self.direct[known]
        names = base.model.info["parameters"]
        if key not in names or key.startswith("derived."):
            self.direct[known] = False
            return False
        i = names.index(key)
        if value == base.p[i]:
            return True  # no change to test with, and none to make
        # Preparing with the new value also checks its bounds, once.
        moved = prepare(self.case, self.model_effects, {**self.base_overrides, key: value}, self.surface, self.params,
                        models=self.models).p
        self.direct[known] = set(np.flatnonzero(moved != base.p).tolist()) <= {i}
        return self.direct[known]

    def parameter_vector(self, overrides: dict[str, float] | None = None) -> tuple[PreparedRun, np.ndarray]:
        """The prepared run and the parameter vector of the base overrides with `overrides` on top."""
        overrides = overrides or {}
        direct = {k: v for k, v in overrides.items() if self._is_direct(k, v)}
        run = self._prepared({**self.base_overrides, **{k: v for k, v in overrides.items() if k not in direct}})
        if not direct:
            return run, run.p
        p = run.p.copy()
        known = run.values.params  # the run's parameters know the quantities of its effects
        for key, value in direct.items():
            p[run.parameter_index(key)] = known.quantity(key).check(value, f"--set {key}")
        return run, p

    def value(self, key: str) -> float:
        """The value of parameter `key` in the base run."""
        run, p = self.parameter_vector()
        return float(p[run.parameter_index(key)])

    @property
    def assisted(self) -> bool:
        """Whether the model has a power assist: then the replay is the assisted one
        (:func:`parksteer.model.numeric.assisted.solve_assisted`), its torque the torsion bar's."""
        return power_assist_of(self._base.effects) is not None

    def count_solve(self) -> None:
        """One solve of this replay spent (by :meth:`solve`, or by a caller integrating its model itself)."""
        self.evaluations += 1
        if self.counter is not None:
            self.counter.solves += 1

    def solve(self, overrides: dict[str, float] | None = None, outputs: bool = False) -> PrescribedSolution:
        """The prescribed-rack solve at `time_s` (with `outputs`, also the states and the model's outputs); of an
        assisted car, the assisted solve (torsion-bar torque, motor torque and current; no outputs)."""
        run, p = self.parameter_vector(overrides)
        self.count_solve()
        if self.assisted and outputs:
            raise UsageError("the handwheel angle of an assisted car is not replayed (its twist passes the "
                             "torsion-bar torque through the torsion bar in series); fit the torque and the motor "
                             "channel instead of --angle")
        # a repeat is counted as a solve all the same: the count is the replays asked for, at any number of workers
        key = self._solve_key(run, p, outputs)
        found = self.solutions.get(key)
        if found is not None:
            return found
        if self.assisted:
            solution = solve_assisted(run, p, self.rack, self.time_s)
        else:
            solution = solve(run, p, self.rack, self.time_s, outputs=outputs)
        self.solutions.keep(key, solution)
        return solution

    def _solve_key(self, run: PreparedRun, p: np.ndarray, outputs: bool) -> tuple:
        """A solve's inputs exactly (:class:`SolutionMemo`): the compiled model and its effects, the vector's bytes,
        whether the outputs are made, the rack's table and ends and the times' bytes (the last three made once)."""
        if self._drive_key is None:
            ends = np.array([self.rack.start_s, self.rack.end_s], dtype=float)
            self._drive_key = (rack_table(self.rack).tobytes(), ends.tobytes(), self.time_s.tobytes())
        return (run.model.directory.name, tuple(e.name for e in run.effects), outputs, p.tobytes(), *self._drive_key)

    def twist_spread(self, torque_error: np.ndarray, overrides: dict[str, float] | None = None) -> np.ndarray:
        """How far the replayed twist moves for a torque off by `torque_error` at each sample
        (:func:`parksteer.model.numeric.prescribed.twist_spread`)."""
        run, p = self.parameter_vector(overrides)
        return twist_spread(run, p, self.solve(overrides, outputs=True), torque_error)

    def torque(self, overrides: dict[str, float] | None = None) -> np.ndarray:
        """Handwheel torque (N m) at `time_s`."""
        return self.solve(overrides).torque_Nm

