"""What the column balance of `parksteer assist identify` reads the product k_t eta N as, on baselines of the independent
assisted truth's cars (not a test): the balance's own product at the owner's file's tyre-ground friction, and the
friction at which it would read the data sheet's, against the car's own.

Each design seed is a car (its base parameters moved as the benchmarks move them, the tyre-ground friction within
10 % of the file's 0.666) logged once on the baseline hand (``TruthDesign.baseline_variation``), rack logged;
docs/assist_identify.md quotes the spread. Run:

    PYTHONPATH=src python benchmarks/bench_identify_product.py [--seeds 4242,777,31337,1,2,3]
"""

from __future__ import annotations

import argparse
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def main(argv=None) -> int:
    from parksteer.diagnose.identify.assist_identify import identify_boost
    from parksteer.experiments.assisted_truth import _write, baseline_record
    from parksteer.experiments.assisted_truth_design import TruthDesign, case_seed
    from parksteer.experiments.assisted_truth_owner import owner_file
    from parksteer.synthetic.datasets import BASE_PERTURBATION
    from parksteer.synthetic.datasets import perturbed_base
    from parksteer.vehicle import load_vehicle

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", default="4242,777,31337,1,2,3")
    args = parser.parse_args(argv)
    vehicle = ROOT / "data" / "vehicles" / "polo_vi.toml"
    params = load_vehicle(vehicle)
    worst = 0.0
    for seed in (int(s) for s in args.seeds.split(",")):
        design = TruthDesign(seed=seed, tiers=("rack",))
        with tempfile.TemporaryDirectory() as folder:
            owner = owner_file(vehicle, design, folder)
            record = Path(folder) / "baseline.csv"
            _write(record, baseline_record(params, design, "rack"), owner.params)
            found = identify_boost([record], Path(folder) / "owner.toml", case=None, quiet=True)
        own = perturbed_base(params, case_seed(design, design.baseline_variation) + 77,
                             BASE_PERTURBATION)["tyre.friction_coefficient"]
        sheet = found.file_values["product"]
        agree = found.tyre_friction + (sheet - found.balance_product) / found.product_per_tyre_friction
        worst = max(worst, abs(agree - own))
        print(f"seed {seed}: balance {found.balance_product:.4f} N m/A (data sheet {sheet:.4f}, "
              f"{'kept' if 'torque_constant' in found.kept else 'replaced'}); the car's friction {own:.3f}, the "
              f"balance agrees with the data sheet at {agree:.3f} ({agree - own:+.3f})", flush=True)
    print(f"largest difference between the agreeing friction and the car's own: {worst:.3f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
