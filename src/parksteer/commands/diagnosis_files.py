"""What ``parksteer diagnose`` writes beside its JSON: the figure (and a user's effect's beside it), the markdown
report, the HTML page with its figures and error ladder, the suggested effect. The command line and the workflow's
vehicle study both write through :func:`write_diagnosis`, so the same diagnosis gives the same files."""

from __future__ import annotations

from pathlib import Path

from ..progress import note


def write_diagnosis(diagnosis, taken, plot: str | None = None, report: str | None = None, html: str | None = None,
                    suggest_effect: str | None = None) -> dict:
    """Write the outputs asked for of `diagnosis` (made from the intake `taken`,
    :class:`parksteer.diagnose.intake.Intake`) and give its JSON (:func:`parksteer.reporting.report.diagnosis_dict`,
    with the suggested effect where one was written)."""
    from ..reporting.report import diagnosis_dict

    result = _with_suggestion(suggest_effect, diagnosis_dict(diagnosis), diagnosis, taken.settings)
    user_plot = None
    if plot:
        from ..figures.diagnose import diagnosis_figure

        diagnosis_figure(diagnosis, plot)
        if "user_effect" in diagnosis.outputs:  # a user's effect in the model: its own figure beside
            from ..figures.user_effect import user_effect_figure, user_effect_path

            user_plot = user_effect_path(plot)
            user_effect_figure(diagnosis, user_plot)
            note(f"the figure of {', '.join(diagnosis.outputs['user_effect'].effects)}: {user_plot}")
    # both pages render the same sections: the residual by phase for both, the error ladder (a diagnosis more for
    # each effect it names) where the HTML page asks for it, and then in both
    phases = ladder = None
    if report or html:
        from ..reporting.report import phase_residuals

        phases = phase_residuals(diagnosis)
    if html:
        from ..reporting.ladder import error_ladder

        ladder = error_ladder(taken.files, taken.params, list(diagnosis.base_effects), first=diagnosis,
                              workers=taken.workers)
    if report:
        from ..reporting.pages import markdown_report, write_markdown  # a page renderer: not for the JSON alone

        figure = _linked(plot, report) if plot else None
        write_markdown(report, markdown_report(result, figure, _linked(user_plot, report) if user_plot else None,
                                               phases, ladder.as_dict() if ladder is not None else None))
    if html:
        _write_html(html, diagnosis, result, phases, ladder)
    return result


def _with_suggestion(suggest_effect: str | None, result: dict, diagnosis, settings) -> dict:
    """With --suggest-effect and an unexplained verdict, the effect the residual's signature points to, written
    and fitted (parksteer.diagnose.suggest)."""
    if not suggest_effect:
        return result
    signature = diagnosis.outputs.get("signature")
    if diagnosis.verdict != "unexplained" or signature is None or signature.effect_class is None:
        note(f"no effect suggested (verdict {diagnosis.verdict}"
             + (", no structure in the residual" if signature is not None and signature.effect_class is None
                else "") + ")")
        return result
    from ..diagnose.suggest import suggest
    from ..reporting.report import with_suggestion

    suggestion = suggest(diagnosis.problem, diagnosis.calibration, signature, suggest_effect, settings)
    note(f"suggested effect {suggestion.effect_name} written to {suggest_effect}: weighted RMS "
         f"{suggestion.before_over_floor:.2f} -> {suggestion.after_over_floor:.2f} noise floors")
    return with_suggestion(result, suggestion)


def _linked(figure, report) -> str:
    """`figure` as the markdown `report` links it: relative to the report's folder when it lies under it."""
    resolved, folder = Path(figure).resolve(), Path(report).resolve().parent
    return str(resolved.relative_to(folder)) if resolved.is_relative_to(folder) else str(figure)


def _write_html(path: str, diagnosis, result: dict, phases: list[dict], ladder) -> None:
    """The diagnosis and its error ladder as one self-contained HTML page (parksteer.reporting.pages.html_report)."""
    import tempfile

    from ..reporting.pages import html_report, write_markdown
    from ..figures.diagnose import diagnosis_figure, ladder_figure, phase_residual_figure

    captions = {
        "diagnosis": "Measured handwheel torque and the calibrated model (with the best candidate) against rack, "
                     "their residual, and the weighted RMS error with each candidate (first file).",
        "phases": "RMS residual by phase of the cycle over all files, against the noise floor.",
        "ladder": "The error ladder: the paper's model, calibrated, then with each effect the diagnoses name, down "
                  "to the noise floor.",
    }
    if "user_effect" in diagnosis.outputs:
        captions["user_effect"] = ("Your effect: the error ladder without it and with it, the record (first file) "
                                   "with both models and their residuals over the phases of the cycle, the residual "
                                   "by phase, and the error as its strengths grow from 0 to their fitted values.")
    with tempfile.TemporaryDirectory() as tmp:
        if "user_effect" in diagnosis.outputs:
            from ..figures.user_effect import user_effect_figure

            user_effect_figure(diagnosis, Path(tmp) / "user_effect.svg")
        diagnosis_figure(diagnosis, Path(tmp) / "diagnosis.svg")
        phase_residual_figure(phases, Path(tmp) / "phases.svg")
        ladder_figure(ladder.rungs, ladder.noise_floor_Nm, ladder.attainable_floor_Nm, Path(tmp) / "ladder.svg")
        figures = [(name, caption, (Path(tmp) / f"{name}.svg").read_text(encoding="utf-8"))
                   for name, caption in captions.items()]
    write_markdown(path, html_report(result, figures, phases, ladder.as_dict()))
