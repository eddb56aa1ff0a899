# Figure checksums. `verify` rebuilds what is stale and compares every figure and its data with
# figures/SHA256SUMS, naming the largest numeric difference on a mismatch. `refresh_checksums`
# rewrites the sums and the reference data after a deliberate change (commit them with the reason).


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
    conda:
        "../envs/parksteer.yaml"
    shell:
        "parksteer checksums verify {input.figures} --report {output} > {log} 2>&1 || (cat {log}; exit 1)"


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
