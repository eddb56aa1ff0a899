# Thin rule script: the logic is parksteer.model.codegen.cache.ensure (the one derive path).
from parksteer.model.codegen.cache import ensure
from parksteer.model.symbolic.components import resolve_effects
from parksteer.rules import rule_log
from parksteer.tables import write_json

with rule_log(snakemake):
    write_json(snakemake.output.manifest, ensure(resolve_effects(snakemake.params.effects), note_cached=True))
