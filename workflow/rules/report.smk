# `snakemake --report report.html`: every figure and table of FIGURES (plot and data) and the article, each with
# its caption (workflow/report/<caption>.rst, rendered with the job's wildcards and params) in the category of
# the part of the study it belongs to. A figure rule marks its outputs with figure_report(path, category); a file
# of FIGURES left unmarked fails tests/workflow/test_report.py. A wildcard rule's caption is one template for all
# its jobs (Jinja: `snakemake.wildcards`, `snakemake.params`); category, subcategory and labels take the job's
# wildcards too. `snakemake --report vehicle.html vehicle_study --config vehicle=<name>` reports a vehicle study.

report: "../report/workflow.rst"

REPORT_CATEGORIES = {
    "rig": "1 Static tyre rig",
    "lifting": "2 Lifting the body",
    "model": "3 Multibody model",
    "sweep": "4 Design sweep",
    "diagnose": "5 Model against measurement",
    "bands": "6 Bands on the headline numbers",
    "paper": "7 Article",
    "vehicle": "Vehicle {vehicle}",  # a vehicle study (rule vehicle_study), never part of `all`
}


def figure_report(path, category, caption=None):
    """`path` marked for the report: subcategory and label the figure's name (wildcards filled in by Snakemake),
    caption workflow/report/<name>.rst unless named."""
    name = Path(path).stem
    return report(
        path,
        caption=f"../report/{caption or name}.rst",  # relative to workflow/rules/, where every rule file lives
        category=REPORT_CATEGORIES[category],
        subcategory=name,
        labels={"figure": name, "file": "data (CSV)" if path.endswith(".csv") else "plot"},
    )
