# Thin rule script: the logic is parksteer.rules.write_code_stamp.
from parksteer.rules import rule_log, write_code_stamp

with rule_log(snakemake):
    write_code_stamp(snakemake.input.code, snakemake.output.stamp)
