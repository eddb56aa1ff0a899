# The diagnosis against its peers (parksteer.diagnose.peers): PySINDy's STLSQ and FROLS on the calibrated residual
# and the candidates' signatures. diag_peers_batch diagnoses again the records the variation and out-of-class
# benchmarks wrote (the same files, read back) and makes and diagnoses the tuning split (the variation grid with
# records of config["peers"]["tuning_seed"]), keeping for each the diagnosis's answer and every peer setting's;
# diag_peers tunes each peer on the tuning split and scores all three on the benchmarks' records.
PEER_JOBS = (
    [f"tuning:{name}" for name in DIAG_VARIATION_CASES]
    + [f"variations:{path}" for path in
       case_outputs("results/diagnose/variations", DIAG_VARIATION_CASES, DIAG_VARIATION_BATCHES, "truth")]
    + [f"outclass:{path}" for path in
       case_outputs("results/diagnose/outclass", DIAG_OUTCLASS_CASES, DIAG_OUTCLASS_BATCHES, "truth")]
)
PEER_BATCHES = case_batches("peers_", PEER_JOBS, DIAG_PER_JOB)


rule diag_peers_batch:
    input:
        parameters=PARAMETERS,
        models=DIAG_MODELS,
        variations=expand("results/diagnose/variations/{batch}", batch=DIAG_VARIATION_BATCHES),
        outclass=expand("results/diagnose/outclass/{batch}", batch=DIAG_OUTCLASS_BATCHES),
        code=script_sources("diag_peers_batch"),
    output:
        directory("results/diagnose/peers/{batch}"),
    params:
        design=config["variations"],
        benchmark=config["benchmark"],
        tuning_seed=config["peers"]["tuning_seed"],
        jobs=lambda wildcards: PEER_BATCHES[wildcards.batch],
    wildcard_constraints:
        batch="|".join(PEER_BATCHES) if PEER_BATCHES else "none",
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
        batches=expand("results/diagnose/peers/{batch}", batch=list(PEER_BATCHES)),
        code=script_sources("diag_peers"),
    output:
        svg=figure_report("figures/diag_peers.svg", "diagnose"),
        csv=figure_report("figures/diag_peers.csv", "diagnose"),
        json="results/diag_peers.json",
    log:
        "logs/diag_peers.log",
    benchmark:
        benchmark_file("diag_peers")
    conda:
        "../envs/parksteer.yaml"
    script:
        "../scripts/diag_peers.py"
