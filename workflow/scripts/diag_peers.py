# Thin rule script: the logic is parksteer.figures.peers.make_peers_figure.
from pathlib import Path

from parksteer.figures.peers import make_peers_figure
from parksteer.rules import rule_log

with rule_log(snakemake):
    make_peers_figure(sorted(p for folder in snakemake.input.batches for p in Path(folder).glob("*.peers.json")),
                      snakemake.output.svg, snakemake.output.csv, snakemake.output.json)
