# The diagnosis against its peers (parksteer.experiments.peers): PySINDy's STLSQ and FROLS on the calibrated residual
# and the candidates' signatures. The variation and out-of-class benchmarks' batches run the peers on each diagnosis
# they make (evaluation__<case>.peers.json beside it: the same replays, not diagnosed again); diag_peers_batch makes
# and diagnoses the tuning split (the variation grid with records of config["peers"]["tuning_seed"]), keeping for
# each the diagnosis's answer and every peer setting's; diag_peers tunes each peer on the tuning split and scores
# all three on the benchmarks' records.
PEER_JOBS = [f"tuning:{name}" for name in DIAG_VARIATION_CASES]
PEER_BATCHES = case_batches("peers_", PEER_JOBS, DIAG_PER_JOB)


rule diag_peers_batch:
    input:
        parameters=PARAMETERS,
        models=DIAG_MODELS,
    output:
        directory("results/diagnose/peers/{batch}"),
    params:
        code=code("diag_peers_batch"),
        design=config["variations"],
        tuning_seed=config["peers"]["tuning_seed"],
        jobs=lambda wildcards: PEER_BATCHES[wildcards.batch],
    wildcard_constraints:
        batch="|".join(PEER_BATCHES) if PEER_BATCHES else "none",
    priority: PRIORITY["diag_peers_batch"]
    log:
        "logs/diag_peers_batch/{batch}.log",
    benchmark:
        benchmark_file("diag_peers_batch", "batch")
    conda:
        "../envs/parksteer.yaml"
    script:
        "../scripts/diag_peers_batch.py"


rule diag_peers:
    input:
        batches=expand("results/diagnose/peers/{batch}", batch=list(PEER_BATCHES))
        + expand("results/diagnose/variations/{batch}", batch=DIAG_VARIATION_BATCHES)
        + expand("results/diagnose/outclass/{batch}", batch=DIAG_OUTCLASS_BATCHES),
    output:
        svg=figure_report("figures/diag_peers.svg", "diagnose"),
        csv=figure_report("figures/diag_peers.csv", "diagnose"),
        json="results/diag_peers.json",
    params:
        code=code("diag_peers"),
    log:
        "logs/diag_peers.log",
    benchmark:
        benchmark_file("diag_peers")
    conda:
        "../envs/parksteer.yaml"
    script:
        "../scripts/diag_peers.py"
