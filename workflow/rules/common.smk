import glob
from pathlib import Path

# Shared names. FIGURES maps each figure or table target to the files it writes;
# these are the files checksummed in figures/SHA256SUMS.
PARAMETERS = config["parameters"]

# The model's source: a change here re-derives the compiled models (and only a change here).
MODEL_SOURCES = sorted(glob.glob("src/parksteer/model/symbolic/**/*.py", recursive=True) + glob.glob("src/parksteer/model/codegen/**/*.py", recursive=True))

FIGURES = {
    "table1": ["figures/table1.csv"],
    "fig3": ["figures/fig3.svg", "figures/fig3.csv"],
    "fig4": ["figures/fig4.svg", "figures/fig4.csv"],
    "figA3": ["figures/figA3.svg", "figures/figA3.csv"],
    "fig12": ["figures/fig12.svg", "figures/fig12.csv"],
    "fig13": ["figures/fig13.svg", "figures/fig13.csv"],
    "fig14": ["figures/fig14.svg", "figures/fig14.csv"],
    "fig15": ["figures/fig15.svg", "figures/fig15.csv"],
    "fig16": ["figures/fig16.svg", "figures/fig16.csv"],
    "figContrib": ["figures/figContrib.svg", "figures/figContrib.csv"],
    "sweep_design": ["figures/sweep_design.svg", "figures/sweep_design.csv"],
    "diag_compare": ["figures/diag_compare.svg", "figures/diag_compare.csv"],
    "diag_ladder": ["figures/diag_ladder.svg", "figures/diag_ladder.csv"],
    "diag_benchmark": ["figures/diag_benchmark.svg", "figures/diag_benchmark.csv"],
}


def all_figure_files():
    return [f for files in FIGURES.values() for f in files]


def all_number_files():
    """The key numbers of each figure or table (results/<target>.json), which the paper quotes."""
    return [f"results/{name}.json" for name in FIGURES]


def paper_sources():
    return sorted(str(p) for p in Path("paper").glob("*.typ"))
