"""``parksteer baseline`` and ``parksteer diagnose --baseline``: a car's healthy records, and later records judged
against them (parksteer.diagnose.baseline). The record options are ``diagnose``'s (:mod:`.measure`)."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, replace
from pathlib import Path

from ..errors import UsageError
from ..progress import note
from . import add_quiet_option


@dataclass(frozen=True)
class RecordOptions:
    """What ``diagnose`` (:mod:`.measure`) lends these commands, so that they read records exactly as it does (it
    passes them in: this module does not import it back): `add(parser, outputs=False)`, the record options;
    `effects(args, params)`, the model's effects; `check_writable(option, value, folder)`; `channel_map(args)`;
    `request(args, params)`, the intake's request (:class:`parksteer.diagnose.intake.Request`) of the options."""

    add: Callable
    effects: Callable
    check_writable: Callable
    channel_map: Callable
    request: Callable

    def load(self, args, paths, params, effects):
        """(files, params, effects): the records `paths` read with the command's record options, at their speed,
        through the intake (:func:`parksteer.diagnose.intake.intake`; a rack that never reverses is refused)."""
        from ..diagnose.intake import intake

        taken = intake(replace(self.request(args, params), files=paths, effects=effects, vehicle=None,
                               with_assist=False, command="baseline"))
        return taken.files, taken.params, taken.effects


def add_baseline_options(p) -> None:
    """``diagnose --baseline``."""
    p.add_argument("--baseline", action="append", default=None, metavar="BASE",
                   help="judge the records against the car's baseline: a file `parksteer baseline` wrote (.toml), or "
                        "the healthy records themselves (repeat --baseline for each; learnt in memory first, with "
                        "the same record options)")


def register_baseline(sub, records: RecordOptions, diagnose) -> None:
    """``parksteer baseline``, and ``--baseline`` on the `diagnose` parser."""
    add_baseline_options(diagnose)
    p = sub.add_parser("baseline", help="learn what a car's healthy records fix (calibrated values, what the model "
                                        "lacks, the spread of healthy data) and write it for diagnose --baseline")
    records.add(p, outputs=False)
    p.add_argument("--out", required=True, metavar="CAR_baseline.toml", help="the baseline file to write (TOML)")
    p.add_argument("--force", action="store_true", help="overwrite an existing --out")
    p.add_argument("--jobs", type=int, default=None, metavar="N",
                   help="replays run side by side on N processes (default: the CPUs available; same result)")
    add_quiet_option(p)
    p.set_defaults(func=_baseline, records=records)


def _learnt(args, paths, params, effects, settings, workers: int, records: RecordOptions):
    """The baseline learnt from the records `paths` (loaded with the command's record options)."""
    from ..diagnose.baseline import learn_baseline

    files, params, effects = records.load(args, paths, params, effects)
    return learn_baseline(files, params, effects, settings, vehicle=args.vehicle,
                          progress=None if args.quiet else note, workers=workers)


def baseline_of(args, params, effects, settings, workers: int, records: RecordOptions):
    """The baseline of --baseline: read from its file, or learnt from the healthy records given (None without)."""
    if not getattr(args, "baseline", None):
        return None
    from ..diagnose.baseline import Baseline

    given = args.baseline
    if len(given) == 1 and given[0].endswith(".toml"):
        baseline = Baseline.read(given[0])
        baseline.check(params, effects)
        return baseline
    if any(b.endswith(".toml") for b in given):
        raise UsageError(f"--baseline {' '.join(given)}: give one baseline file (.toml) or the healthy records, "
                         "not both")
    return _learnt(args, given, params, effects, settings, workers, records)


def _baseline(args) -> int:
    from ..diagnose.parallel import available_workers
    from ..diagnose.settings import DEFAULT_SETTINGS
    from .vehicle import parameters_of

    records = args.records
    out = Path(args.out)
    if out.is_dir():
        raise UsageError(f"--out {args.out}: is a directory; name a file to write")
    if out.exists() and not args.force:
        raise UsageError(f"--out {args.out}: exists (--force to overwrite)")
    if not out.resolve().parent.is_dir():
        raise UsageError(f"--out {args.out}: folder {out.resolve().parent} does not exist")
    records.check_writable("out", args.out, out.resolve().parent)
    if args.jobs is not None and args.jobs < 1:
        raise UsageError(f"--jobs {args.jobs}: give at least 1")
    workers = args.jobs if args.jobs is not None else available_workers()
    params = parameters_of(args)
    effects = records.effects(args, params)
    baseline = _learnt(args, args.files, params, effects, DEFAULT_SETTINGS, workers, records).write(out)
    print("\n".join(baseline_lines(baseline)))
    return 0


def baseline_lines(baseline) -> list[str]:
    """What a baseline says, in a few lines."""
    lines = [f"baseline of {', '.join(baseline.records)}: absolute verdict {baseline.verdict} "
             f"({baseline.over_floor:.2f} noise floors)"]
    if baseline.form is not None:
        form = baseline.form
        lines.append(f"held in later records: {form.effect} ({form.source}, {len(form.strengths)} strength(s))"
                     + (f": {form.signature}" if form.signature else ""))
    t = baseline.threshold
    lines.append(f"as the baseline: up to {t.over_floor:.2f} noise floors, a BIC gain up to {t.bic_per_sample:.4f} "
                 f"per sample, a confident name leading the second best by more than {t.lead_per_sample:.4f} per "
                 f"sample and the settings' band ({t.method})")
    lines.append(f"wrote {baseline.path} (content hash {baseline.content_hash})")
    return lines
