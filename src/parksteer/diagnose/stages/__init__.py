"""The stages of a diagnosis, in the order they run (:data:`STAGES`).

Each stage is a :class:`~parksteer.diagnose.stages.base.Stage`: a `name` (its key in the diagnosis's
``timings_s``), an optional progress line (:meth:`~parksteer.diagnose.stages.base.Stage.message`) and
:meth:`~parksteer.diagnose.stages.base.Stage.run`, which takes the frozen
:class:`~parksteer.diagnose.state.DiagnosisState` and the diagnosis's replay engine
(:class:`~parksteer.diagnose.engine.ReplayEngine`: its replays, their counts and its workers) and returns a new
state (``dataclasses.replace``) with what it found. A stage reads its settings from the state, changes nothing in
the state it is given (not the files, not the fits), replays only through the engine, and runs its independent
replays side by side through :meth:`~parksteer.diagnose.engine.ReplayEngine.in_workers`.
:func:`parksteer.diagnose.select.diagnose` makes the engine and runs the table
(:func:`~parksteer.diagnose.stages.base.run_table`: a loop that prints each stage's line and times it).

To add a stage:

1. write it in its own file here (a :class:`Stage` subclass; the reasons and derivations in its docstring);
   it keeps its result with ``state.with_output(name, value)`` (or, for a per-file result, in copies of the
   files: ``state.problem.with_files([dataclasses.replace(f, ...) ...])``);
2. put it in :data:`STAGES` below, after the stages whose results it reads;
3. give it its section in the report (:func:`parksteer.reporting.report.diagnosis_dict`, reading
   ``diagnosis.outputs[name]``) and in the JSON schema (``parksteer/data/diagnosis.schema.json``).

The torque lag search (:mod:`.torque_lag`) is such a stage; its result is per file (``files[].torque_lag_s`` in
the JSON). Settings the stage needs go in :class:`parksteer.diagnose.settings.DiagnosisSettings`.
"""

from __future__ import annotations

from .assumed import AssumedValues
from .base import Stage, restart, run_table
from .baseline import Baseline
from .calibrate import Calibrate
from .confound import Confound
from .identify import Identify
from .refit import Refit
from .replay_uncertainty import ReplayUncertainty
from .score import Score
from .select import Select
from .separate import Separate
from .signature import ResidualSignature
from .torque_lag import TorqueLag, TorqueLagWithEffect
from .verdict import Verdict

STAGES: tuple[Stage, ...] = (
    ReplayUncertainty(),  # the base model replayed at its defaults, and each sample's replay uncertainty
    Calibrate(),  # the base model's uncertain parameters
    TorqueLag(),  # each file's torque lag behind its rack (if asked), calibrating again when one moves
    Score(),  # every candidate's signature and score test at the calibrated model
    Refit(),  # the best-scored few refitted in the full model
    Select(),  # their BIC gains over the effective sample size (again with the larger replay uncertainty)
    Verdict(),  # missing, adequate or unexplained
    Baseline(),  # against an identified boost table: a gain error within the table's own uncertainty is the baseline's
    AssumedValues(),  # an assisted car: the verdict with each assumed value of its assist at its band's ends
    Separate(),  # where the indistinguishable candidates would differ
    Identify(),  # what these data fix, and the test that would fix the rest
    Confound(),  # where the confounded candidates would show
    ResidualSignature(),  # what kind of effect the calibrated model lacks, from its residual's shape
    TorqueLagWithEffect(),  # the lags searched again with the named effect; if one moved, the table again
)

__all__ = ["STAGES", "Stage", "restart", "run_table"]
