# The one derive rule: the compiled model of every named effect set the other rules registered with
# model_manifest (the figures' models, the sweep's, the diagnosis's base model and candidates), each built or
# found in the cache by parksteer.model.codegen.cache.ensure. Its inputs are the modules that derivation and
# code generation run (model/symbolic, model/codegen and what they import): an edit of model/numeric derives
# nothing. The set of a job is looked up when the job is planned (model_set), so this file can be included
# before or after the rule files that register sets.


rule derive:
    input:
        effects=lambda w: effect_files(model_set(w.model)),
    output:
        manifest="results/model/{model}.json",
    params:
        code=code("derive"),
        effects=lambda w: model_set(w.model),
    wildcard_constraints:
        model="[^/]+",
    priority: PRIORITY["derive"]
    log:
        "logs/derive/{model}.log",
    benchmark:
        benchmark_file("derive", "model")
    conda:
        "../envs/parksteer.yaml"
    script:
        "../scripts/derive.py"
