"""The command line's shared conventions."""

from __future__ import annotations

from parksteer.cli import _join_dash_values, build_parser


def test_effects_spec_may_start_with_a_minus():
    """`--effects -rack_friction,+hooke_joint` (the documented form) is read as a value, not as an option."""
    argv = ["simulate", "--case", "unladen", "--effects", "-rack_friction,+hooke_joint", "--out", "x.csv"]
    joined = _join_dash_values(argv)
    assert "--effects=-rack_friction,+hooke_joint" in joined
    args = build_parser().parse_args(joined)
    assert args.effects == "-rack_friction,+hooke_joint"


def test_other_arguments_are_left_alone():
    """Only the listed options are rewritten; everything else passes through in order."""
    argv = ["simulate", "--case", "unladen", "--set", "rack_friction.friction_force=500", "--out", "x.csv"]
    assert _join_dash_values(argv) == argv
