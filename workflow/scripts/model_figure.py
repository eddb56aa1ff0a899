# Thin rule script for fig12-fig16 and figContrib: the logic is parksteer.figures.model.make_model_figure.
from parksteer.figures.model import make_model_figure
from parksteer.progress import note
from parksteer.rules import rule_log

with rule_log(snakemake):
    note(f"{snakemake.wildcards.figure} from {len(snakemake.params.runs)} runs (case, variant): "
         f"{', '.join(f'{c}/{v}' for c, v in snakemake.params.runs)}")
    make_model_figure(
        snakemake.wildcards.figure,
        snakemake.params.runs,
        snakemake.params.labels,
        snakemake.input.parameters,
        list(snakemake.input.sims),
        snakemake.output.svg,
        snakemake.output.csv,
        snakemake.output.json,
    )
