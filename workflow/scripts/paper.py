# Thin rule script: the logic is parksteer.paper.build.
import sys

from parksteer.paper import build

sys.stderr = open(snakemake.log[0], "w")
pages = build("paper/parksteer.typ", snakemake.output.pdf, root=".")
print(f"{snakemake.output.pdf}: {pages} pages", file=sys.stderr)
