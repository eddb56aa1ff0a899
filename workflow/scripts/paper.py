# Thin rule script: the logic is parksteer.paper.build.
import sys

from parksteer.paper import build
from parksteer.rules import rule_log

with rule_log(snakemake):
    pages = build("paper/parksteer.typ", snakemake.output.pdf, root=".")
    print(f"{snakemake.output.pdf}: {pages} pages", file=sys.stderr)
