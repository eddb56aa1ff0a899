# parksteer: every table, figure and the paper, from data/parameters.toml.
#   snakemake --cores 2            everything, ending with paper/parksteer.pdf
#   snakemake --cores 2 fig3       one figure (any name in FIGURES below)
#   snakemake --cores 2 verify     rebuild and check figures against figures/SHA256SUMS
from snakemake.utils import min_version, validate

min_version("9.0")


configfile: "workflow/config.yaml"


validate(config, "workflow/schemas/config.schema.yaml")


# A defective parameter file is refused before any job runs, with one line naming the file and the key.
from parksteer.parameters import ParameterError, load_parameters

try:
    load_parameters(config["parameters"])
except ParameterError as error:
    sys.exit(f"parksteer: error: {error}")


include: "workflow/rules/common.smk"
include: "workflow/rules/rig.smk"
include: "workflow/rules/lifting.smk"
include: "workflow/rules/model.smk"
include: "workflow/rules/sweep.smk"
include: "workflow/rules/diagnose.smk"
include: "workflow/rules/paper.smk"
include: "workflow/rules/checks.smk"


rule all:
    default_target: True
    input:
        all_figure_files(),
        "paper/parksteer.pdf",
