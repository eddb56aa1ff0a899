# Thin rule script: the logic is parksteer.model.codegen.cache.ensure (the one derive path). The manifest keeps the
# effects spec it was derived from, which `parksteer derive --prebuilt results/model/*.json` reads.
from parksteer.model.codegen.cache import ensure
from parksteer.model.symbolic.components import resolve_effects
from parksteer.rules import rule_log
from parksteer.tables import write_json

with rule_log(snakemake):
    spec = snakemake.params.effects
    write_json(snakemake.output.manifest, {**ensure(resolve_effects(spec), note_cached=True), "spec": spec})
