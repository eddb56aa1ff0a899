# Thin rule script: the logic is parksteer.figures.model.write_simulation.
from parksteer.figures.model import write_simulation
from parksteer.progress import note
from parksteer.rules import rule_log

with rule_log(snakemake):
    effects = snakemake.params.effects or "the paper's five"
    note(f"simulating {snakemake.wildcards.case} with the model {snakemake.wildcards.variant}: effects {effects}, "
         f"surface {snakemake.params.surface}")
    write_simulation(snakemake.input.parameters, snakemake.wildcards.case, snakemake.wildcards.variant,
                     snakemake.params.effects, snakemake.params.surface, snakemake.output.csv)
