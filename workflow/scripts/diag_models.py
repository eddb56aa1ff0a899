# Thin rule script: the logic is parksteer.diagnose.candidates.write_candidate_models.
from parksteer.diagnose.candidates import write_candidate_models
from parksteer.rules import rule_log

with rule_log(snakemake):
    write_candidate_models(snakemake.output.manifest, extra=(snakemake.input.sources[-1],))
