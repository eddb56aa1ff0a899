# Figure checksums. `verify` rebuilds what is stale and says for every figure and its data whether it is identical
# to figures/SHA256SUMS, within its family's tolerance (named with the platform facts that differ) or changed, and
# fails on changed; `verify_strict` (CI) fails on anything not identical (docs/reproducibility.md). Each writes its
# own report, so a lenient pass never stands in for a strict one. `refresh_checksums` rewrites the sums, the
# reference copies and figures/PLATFORM.json after a deliberate change (commit them with the reason).


rule verify:
    input:
        figures=all_figure_files(),
        sums="figures/SHA256SUMS",
    output:
        "results/checksums_verified.txt",
    log:
        "logs/verify.log",
    benchmark:
        benchmark_file("verify")
    params:
        strictness="",
    conda:
        "../envs/parksteer.yaml"
    shell:
        "parksteer checksums verify {input.figures} --complete {params.strictness} --report {output} > {log} 2>&1 "
        "|| (cat {log}; exit 1)"


use rule verify as verify_strict with:
    output:
        "results/checksums_verified_strict.txt",
    log:
        "logs/verify_strict.log",
    benchmark:
        benchmark_file("verify_strict")
    params:
        strictness="--strict",


rule refresh_checksums:
    input:
        figures=all_figure_files(),
    output:
        "results/checksums_refreshed.txt",
    log:
        "logs/refresh_checksums.log",
    benchmark:
        benchmark_file("refresh_checksums")
    conda:
        "../envs/parksteer.yaml"
    shell:
        "parksteer checksums refresh {input.figures} > {log} 2>&1 && cp {log} {output}"
