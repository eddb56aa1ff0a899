"""The reference pages of docs/ written from the code: the effect library, the command line, the vehicle file.

Each page is a function of the code alone (the effect registry, the argument parser, the parameter registry), so
it cannot drift from what the program does: ``tests/test_docs_reference.py`` compares the pages in docs/ with what
these functions give, and ``python -m parksteer.reference docs`` writes them after a change.
"""

from __future__ import annotations

import argparse
import re
import sys
from collections.abc import Callable
from pathlib import Path

GENERATED = ("<!-- Generated from the code by `python -m parksteer.reference docs`; "
             "tests/test_docs_reference.py fails when this page differs from what the code gives. -->")

# Quantities numbered per table point (an assist's boost table: boost_torque_0 ... boost_torque_31) are one row.
_NUMBERED = re.compile(r"(_\d+)+$")


def _cell(text: object) -> str:
    """`text` as one markdown table cell: one line, pipes escaped."""
    return " ".join(str(text).split()).replace("|", "\\|")


def _row(*cells: object) -> str:
    return "| " + " | ".join(_cell(c) for c in cells) + " |"


# --- the effect library ---------------------------------------------------------------------------------------------

def _library_effects() -> dict:
    """The package's own effects by name (not a user's: entry points and PARKSTEER_EFFECT_MODULES are left out)."""
    from .model.symbolic.components import discover_effects

    package = "parksteer.model.symbolic.effects."
    return {name: effect for name, effect in sorted(discover_effects().items())
            if type(effect).__module__.startswith(package)}


def _role(effect) -> str:
    if effect.in_default_set:
        return "the paper's model"
    if effect.power_assist is not None:
        return f"power assist ({effect.power_assist}, at the {effect.location})"
    if effect.rival is not None:
        return f"rival (closest candidate: `{effect.rival.closest}`)"
    if effect.assist_candidate:
        return "candidate of an assisted car"
    if effect.diagnosis_candidate:
        return "candidate"
    return "option"


def _quantity_rows(effect) -> list[str]:
    rows, seen = [], set()
    for q in effect.quantities:
        name = _NUMBERED.sub("_<i>", q.name)
        if name in seen:
            continue
        seen.add(name)
        numbered = name != q.name
        default = "per table point" if numbered else f"{q.default:g}"
        source = q.source.split(";")[0] if numbered else q.source
        rows.append(_row(f"`{effect.name}.{name}`", q.unit, default, q.bounds_text(), source))
    return rows


def effects_page() -> str:
    """Every effect of the library: its role, slot and needs, then each effect's own quantities."""
    effects = _library_effects()
    lines = [
        "# Reference: the effect library",
        "",
        GENERATED,
        "",
        "Every effect the package ships (`src/parksteer/model/symbolic/effects/`, one file each), its role, the slot",
        "it fills and the effects it needs, then the quantities it declares itself (unit, default, bounds, source).",
        "The car's own quantities (`tyre.*`, `steering.*`, ...) are listed with the vehicle file",
        "([vehicle_file.md](vehicle_file.md)); `parksteer effects` prints the same with a parameter file's values.",
        "What an effect is and how to add one: [model.md](model.md).",
        "",
        "| effect | role | fills slot | requires | what it adds |",
        "|---|---|---|---|---|",
    ]
    for name, effect in effects.items():
        lines.append(_row(f"`{name}`", _role(effect), effect.replaces or "", ", ".join(effect.requires),
                          effect.description))
    lines += ["", "## Quantities declared by effects", "",
              "A row `<i>` stands for one quantity per point of the vehicle file's boost table.", "",
              "| quantity | unit | default | bounds | source |", "|---|---|---|---|---|"]
    for effect in effects.values():
        lines += _quantity_rows(effect)
    return "\n".join(lines) + "\n"


# --- the command line -----------------------------------------------------------------------------------------------

def _commands(parser: argparse.ArgumentParser, prefix: str) -> list[tuple[str, str, argparse.ArgumentParser]]:
    """(command, its one-line help, its parser) for every subcommand, depth first, in the parser's order."""
    found = []
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            helps = {choice.dest: choice.help or "" for choice in action._choices_actions}
            for name, child in action.choices.items():
                command = f"{prefix} {name}"
                found.append((command, helps.get(name, ""), child))
                found += _commands(child, command)
    return found


def _invocation(action: argparse.Action) -> str:
    if not action.option_strings:
        if action.choices is not None:
            return "{" + ",".join(str(c) for c in action.choices) + "}"
        return action.metavar or action.dest + (" ..." if action.nargs in ("*", "+") else "")
    if action.nargs == 0:
        return ", ".join(action.option_strings)
    value = action.metavar or action.dest.upper()
    if action.choices is not None:
        value = "{" + ",".join(str(c) for c in action.choices) + "}"
    return ", ".join(f"{option} {value}" for option in action.option_strings)


def _help(action: argparse.Action) -> str:
    """The option's help as --help prints it, without a machine's default (an absolute path, a CPU count)."""
    text = action.help or ""
    return text.replace("%(default)s", "its default").replace("%%", "%")


def cli_page() -> str:
    """Every subcommand of ``parksteer`` and its arguments, as the parser defines them."""
    from .cli import build_parser

    lines = [
        "# Reference: the command line",
        "",
        GENERATED,
        "",
        "Every subcommand of `parksteer` and its arguments, in the order of `parksteer --help`. Every subcommand",
        "refuses a bad file or value with one line naming the file and the key (exit status 2), and shows its",
        "progress on stderr unless given `--quiet`; `-h` prints the same help.",
    ]
    for command, summary, parser in _commands(build_parser(), "parksteer"):
        arguments = [a for a in parser._actions
                     if not isinstance(a, (argparse._HelpAction, argparse._SubParsersAction))]
        lines += ["", f"## `{command}`", "", _cell(summary[:1].upper() + summary[1:]) + "."]
        if parser.description and parser.description != summary:
            lines += ["", " ".join(parser.description.split())]
        if arguments and not any(isinstance(a, argparse._SubParsersAction) for a in parser._actions):
            lines += ["", "| argument | meaning |", "|---|---|"]
            lines += [_row(f"`{_invocation(a)}`", _help(a)) for a in arguments]
    return "\n".join(lines) + "\n"


# --- the vehicle file -----------------------------------------------------------------------------------------------

def vehicle_file_page() -> str:
    """The sections and keys of a vehicle file: required keys, load cases, the assist and its boost table."""
    from .parameter_entries import PROVENANCES
    from .parameters import CASE_SCHEMA, SCHEMA, load_parameters
    from .vehicle import ASSIST_EFFECTS, BOOST_ASSIST_UNITS, BOOST_UNITS, REQUIRED

    paper = load_parameters()
    effects = _library_effects()
    lines = [
        "# Reference: the vehicle file",
        "",
        GENERATED,
        "",
        "The keys of a vehicle file (`data/vehicles/<name>.toml`), as `parksteer vehicle check` reads it. Every entry",
        "is `{ value, unit, source }` in the unit given or one pint converts to it, optionally with",
        f"`provenance` (one of {', '.join(f'`{p}`' for p in PROVENANCES)}). Bounds are the registry's: a value outside",
        "them is refused in one line naming the file and the key. The column \"the paper's car\" is the packaged",
        "parameter file's value (SI). Writing one from a specification and using it: [vehicles.md](vehicles.md).",
        "",
        "## The car",
        "",
        "Required keys must be given; the others take the packaged parameter file's value unless the file gives them.",
        "",
        "| key | unit | bounds | required | the paper's car |",
        "|---|---|---|---|---|",
    ]
    for section in ("vehicle", "steering", "geometry", "tyre", "input"):
        for name, q in SCHEMA[section].items():
            value = paper[q.key]
            shown = ", ".join(f"{v:g}" for v in value) if q.is_list else f"{value:g}"
            lines.append(_row(f"`{q.key}`", q.unit, q.bounds_text(), "yes" if q.key in REQUIRED else "", shown))
    lines += ["", "## Load cases: `[cases.<name>]`", "",
              "One or more load cases, each with every key below.", "",
              "| key | unit | bounds |", "|---|---|---|"]
    lines += [_row(f"`{name}`", q.unit, q.bounds_text()) for name, q in CASE_SCHEMA.items()]
    lines += ["", "## Power assistance: `[assist]`", "",
              "`type` names the assist; every other entry is a quantity of that assist's effect, by its name (the",
              "effect's quantities: [effects.md](effects.md)).", "",
              "| `type` | effect | boost table's `assist` unit |", "|---|---|---|"]
    for kind, effect in ASSIST_EFFECTS.items():
        lines.append(_row(f"`{kind}`", f"`{effect}`" if effect in effects else effect,
                          " or ".join(BOOST_ASSIST_UNITS[kind])))
    lines += ["", "## The boost table: `[assist.boost]`", "",
              "The control unit's table: the assist against the torsion-bar torque, one row per vehicle speed when",
              "`vehicle_speed` is given.", "",
              "| key | units |", "|---|---|"]
    lines += [_row(f"`{key}`", " or ".join(units)) for key, units in BOOST_UNITS.items()]
    return "\n".join(lines) + "\n"


PAGES: dict[str, Callable[[], str]] = {
    "effects.md": effects_page,
    "cli.md": cli_page,
    "vehicle_file.md": vehicle_file_page,
}


def write_pages(folder: str | Path) -> list[Path]:
    """Write every reference page into `folder` (docs/); returns the paths written."""
    written = []
    for name, page in PAGES.items():
        path = Path(folder) / name
        path.write_text(page(), encoding="utf-8")
        written.append(path)
    return written


if __name__ == "__main__":
    for path in write_pages(sys.argv[1] if len(sys.argv) > 1 else "docs"):
        print(path)
