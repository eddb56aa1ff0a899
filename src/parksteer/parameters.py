"""The parameters of a run: the parameter file (src/parksteer/data/parameters.toml, shipped as package data) that
gives the car's values, and the effects' quantities a :class:`Parameters` knows.

Every quantity has one key (``section.name``), one SI unit and one pair of physical bounds. The car's quantities
are listed in :mod:`parksteer.quantities` (:data:`SCHEMA`) and the file gives each its value and source as
``{value, unit, source}`` (checked by :mod:`parksteer.parameter_entries`); an effect's own quantities
(``<effect>.<name>``) are declared on the effect, with default and source, and a :class:`Parameters` knows those
of the effects it is used with (:attr:`Parameters.declared`, :meth:`Parameters.declaring`: the model's effects
add theirs, :func:`parksteer.model.symbolic.components.with_effect_quantities`); the run's vehicle speed
(``run.vehicle_speed``, :data:`VEHICLE_SPEED`), which several effects read, is declared here and known to every
Parameters. Overrides (``--set``, sweeps, diagnosis, the workflow's config) use the same keys, plus
``case.<name>`` for the active Table B1 case (:meth:`Parameters.with_overrides`). Any unknown key, missing key,
wrong unit, non-physical value or wheel loads that contradict the chassis statics are refused with a
:class:`ParameterError` whose message is one line naming the file and the key.
"""
from __future__ import annotations

import dataclasses
import math
import numbers
import tomllib
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from .errors import UsageError, cannot_read
from .frozen import FrozenDict
from .parameter_entries import check_statics, check_table, provenance_key
from .quantities import CASE, CASE_SCHEMA, FILE_AND_CASE_KEYS, RENAMED, SCHEMA, ParameterError, Quantity
from .resources import data_file

DEFAULT_PATH = data_file("parameters.toml")

def registry(declared: Mapping[str, Quantity] | None = None) -> dict[str, Quantity]:
    """Every key known: the parameter file's, ``case.*``, the run's and those `declared` in code (an effect's own:
    :attr:`Parameters.declared`)."""
    return {**FILE_AND_CASE_KEYS, **RUN_QUANTITIES, **(declared or {})}


def quantity(key: str, declared: Mapping[str, Quantity] | None = None) -> Quantity:
    """The quantity of `key` (a key of the file, ``case.*``, the run's, or one of `declared`); an unknown or
    renamed key is a one-line UsageError."""
    found = FILE_AND_CASE_KEYS.get(key) or RUN_QUANTITIES.get(key) or (declared or {}).get(key)
    if found is None:
        raise UsageError(unknown_key_message(key))
    return found


def unknown_key_message(key: str) -> str:
    if key in RENAMED:
        return f"{key}: unknown key; this quantity is {RENAMED[key]}"
    return f"{key}: unknown key (a key of the parameter file, case.<name>, or an effect's own quantity)"


def _is_number(value: Any) -> bool:
    """A real number as code writes one (int, float, a NumPy scalar), not a boolean, a string or None."""
    kind = type(value)  # a plain float or int first: the abstract class's check is the slow path
    return kind is float or kind is int or (kind is not bool and isinstance(value, numbers.Real))


def declaration_problem(q: Quantity) -> str | None:
    """What is wrong with the declaration of `q` (an effect's own quantity, written in code), or None: a unit
    given as text, both bounds numbers and not NaN, the lower below the upper, finite bounds for a quantity a
    diagnosis fits (``free``: the fit may take any value between them), a default and a source."""
    if not isinstance(q.unit, str) or not q.unit.strip():
        return f"unit {q.unit!r}: give its SI unit as text, e.g. 'N m'"
    for side, bound in (("lower", q.lower), ("upper", q.upper)):
        if not _is_number(bound):
            return (f"{side} bound {bound!r} is not a number: give both bounds, the range the physics allows "
                    "(Quantity(key, unit, lower, upper, ...))")
        if math.isnan(bound):
            return f"{side} bound is NaN: give the range the physics allows"
    if not q.lower < q.upper:
        return f"bounds out of order: the lower bound {q.lower:g} must be below the upper {q.upper:g}"
    if q.free and not (math.isfinite(q.lower) and math.isfinite(q.upper)):
        return (f"free within {q.bounds_text()} {q.unit}: a quantity the diagnosis fits needs finite bounds, the "
                "range its physics allows (a friction's from 0)")
    if q.default is None or not isinstance(q.source, str) or not q.source.strip():
        return "a quantity declared in code needs a default and a source"
    if not _is_number(q.default):
        return f"default {q.default!r} is not a number"
    return None


def checked_declaration(q: Quantity, known: Mapping[str, Quantity]) -> Quantity:
    """`q`, a quantity declared in code (an effect's own, with default and source), checked to join `known`: a
    declaration :func:`declaration_problem` finds wrong, or one whose unit or bounds differ from those `known` has
    for its key, is a one-line UsageError naming the key."""
    if q.section in SCHEMA or q.section == CASE:
        raise UsageError(f"{q.key}: section {q.section} belongs to the parameter file; declare {q.section}.* there")
    problem = declaration_problem(q)
    if problem is not None:
        raise UsageError(f"{q.key}: {problem}")
    before = known.get(q.key)
    # the same effect's file loaded again (a suggested effect written again with its fitted values as defaults)
    # declares its quantities anew: the latest default, source and freedom win; another unit or bounds is a clash
    if before is not None and (before.unit, before.lower, before.upper, before.lower_inclusive,
                               before.upper_inclusive, before.is_list) != (q.unit, q.lower, q.upper, q.lower_inclusive,
                                                                           q.upper_inclusive, q.is_list):
        raise UsageError(f"{q.key}: declared twice with different unit or bounds ({before.unit} "
                         f"{before.bounds_text()}, then {q.unit} {q.bounds_text()}): another effect named "
                         f"{q.section!r} is loaded")
    if not (math.isfinite(q.default) and q.within(q.default)):
        raise UsageError(f"{q.key}: default {q.default:g} {q.unit} is outside its bounds {q.bounds_text()}")
    return q


# The car's speed while it steers: one quantity of the run that every effect depending on it reads (the rolling
# tyre's turn slip, the electric assist's speed-dependent boost curve), set once per run (`parksteer simulate
# --speed-kmh`, the sizing study: parksteer.vehicle.creeping_overrides). It describes the run, not the car, so
# neither the parameter file nor a vehicle file gives it, and a run without such an effect has it neither in its
# parameter vector nor in its header; it is declared here, with its default 0 (standstill, the paper's test), in
# the lowest layer, which the model, the sweeps and the measurements (whose speed channel is vehicle_speed_mps)
# all reach.
VEHICLE_SPEED = checked_declaration(Quantity(
    "run.vehicle_speed", "m/s", 0.0, 3.0, lower_inclusive=True, default=0.0,
    description="the car's speed while it steers (constant over the run)",
    source="input of the run: 0 = standstill (the paper), up to 3 m/s (10.8 km/h) of creeping"), {})


class DeclaredQuantities(FrozenDict):
    """Quantities declared in code by key, read-only (it pickles, so parameters holding it may cross a process)."""

    refusal = "declared quantities are read-only: Parameters.declaring makes parameters knowing more"


# The quantities declared in code that every Parameters knows: the run's.
RUN_QUANTITIES: Mapping[str, Quantity] = DeclaredQuantities({VEHICLE_SPEED.key: VEHICLE_SPEED})

def declared_with(quantities: Iterable[Quantity], known: Mapping[str, Quantity] = RUN_QUANTITIES
                  ) -> Mapping[str, Quantity]:
    """`known` with `quantities` (declared in code), each checked to join it (:func:`checked_declaration`; a later one
    of a key replaces an earlier one); `known` itself when it holds each already."""
    new = [q for q in quantities if known.get(q.key) is not q]
    if not new:
        return known
    out = dict(known)
    for q in new:
        out[q.key] = checked_declaration(q, out)
    return out


# A run's overrides (--set, a sweep point) may move the loads off the printed statics a little (a study of one
# load), but loads more than a tenth off the front-end weight are a typo or a wrong unit: the body would not be
# in vertical equilibrium and a wheel load can come out negative. Such an override is refused.
OVERRIDE_LOAD_FRACTION = 0.10


@dataclass(frozen=True)
class Parameters:
    """Validated parameter values in SI units, with the source of each.

    `declared` holds the quantities declared in code that these parameters know beyond the file's: the run's,
    and those of the effects they are used with (:meth:`declaring`); a quantity declared there and given no value
    reads its default."""

    path: Path
    sections: dict[str, dict[str, Any]]
    cases: dict[str, dict[str, float]]
    sources: dict[str, str] = field(repr=False)
    declared: Mapping[str, Quantity] = field(default_factory=lambda: RUN_QUANTITIES, repr=False, compare=False)

    def __getitem__(self, dotted: str) -> Any:
        """``params["tyre.friction_coefficient"]`` or ``params["cases.unladen.load_left"]``.

        A quantity declared in code that these parameters know (:attr:`declared`; no file entry) reads its default.
        """
        parts = dotted.split(".")
        if parts[0] == "cases" and len(parts) == 3:
            return self.case(parts[1])[parts[2]]
        if len(parts) == 2 and parts[0] in self.sections and parts[1] in self.sections[parts[0]]:
            return self.sections[parts[0]][parts[1]]
        declared = self.declared.get(dotted)
        if declared is not None:
            return declared.default
        raise KeyError(dotted)

    def quantity(self, key: str) -> Quantity:
        """The quantity of `key` (:func:`quantity` with the quantities these parameters know)."""
        return quantity(key, self.declared)

    def declaring(self, quantities: Iterable[Quantity]) -> Parameters:
        """These parameters knowing `quantities` too (each an effect's own, checked: :func:`checked_declaration`;
        a later declaration of a key replaces an earlier one); these very parameters when they know each already."""
        known = declared_with(quantities, self.declared)
        return self if known is self.declared else dataclasses.replace(self, declared=DeclaredQuantities(known))

    def knowing(self, known: DeclaredQuantities) -> Parameters:
        """These parameters knowing `known`, quantities declared in code already checked together, the run's among
        them (:func:`parksteer.model.symbolic.components.known_quantities`), besides those they know that `known`
        lacks; where both declare a key, `known`'s replaces theirs (checked)."""
        if known is self.declared:
            return self
        extra = {key: q for key, q in self.declared.items() if known.get(key) is not q}
        if not extra:
            return dataclasses.replace(self, declared=known)
        for key in extra.keys() & known.keys():
            checked_declaration(known[key], extra)
        return dataclasses.replace(self, declared=DeclaredQuantities({**extra, **known}))

    def value(self, key: str, case: str) -> float:
        """The value of any registry key, ``case.<name>`` read from the case `case`."""
        section, _, name = key.partition(".")
        if section == CASE:
            return self.case(case)[name]
        return self[key]

    def case(self, name: str) -> dict[str, float]:
        if name not in self.cases:
            known = ", ".join(sorted(self.cases))
            raise ParameterError(f"{self.path}: unknown case {name!r} (known: {known})")
        return dict(self.cases[name])

    def source(self, dotted: str) -> str:
        if dotted not in self.sources and dotted in self.declared:
            return self.declared[dotted].source
        return self.sources[dotted]

    def provenance(self, dotted: str) -> str:
        """How the value of `dotted` was obtained, as its file declares it (:data:`parksteer.parameter_entries.
        PROVENANCES`); "assumed" where the file declares none or gives no entry (a quantity at its effect's default)."""
        return self.sources.get(provenance_key(dotted), "assumed")

    @property
    def case_names(self) -> list[str]:
        """Case names in file order (unladen first)."""
        return list(self.cases)

    def with_overrides(self, overrides: dict[str, float] | None, case: str | None = None) -> Parameters:
        """These values with `overrides` ({key: value}) applied, each checked against its quantity's bounds.

        ``case.<name>`` changes the case `case` (every case when None). A list quantity cannot be overridden.
        """
        if not overrides:
            return self
        sections = {k: dict(v) for k, v in self.sections.items()}
        cases = {k: dict(v) for k, v in self.cases.items()}
        if case is not None:
            self.case(case)
        for key, value in overrides.items():
            q = self.quantity(key)
            if q.is_list:
                raise UsageError(f"{key}: a list; it cannot be overridden by one value")
            value = q.check(value, where=key)
            if q.section == CASE:
                for name in ([case] if case is not None else list(cases)):
                    cases[name][q.name] = value
            else:
                sections.setdefault(q.section, {})[q.name] = value
        statics_keys = {"vehicle.gravity", "vehicle.unsprung_mass"} | {f"{CASE}.{n}" for n in
                                                                        ("chassis_mass", "load_left", "load_right")}
        changed = [key for key in overrides if key in statics_keys]
        if changed:
            g = sections["vehicle"]["gravity"]
            for name in ([case] if case is not None else list(cases)):
                c = cases[name]
                weight_N = (c["chassis_mass"] + sections["vehicle"]["unsprung_mass"]) * g
                total_N = c["load_left"] + c["load_right"]
                if abs(total_N - weight_N) > OVERRIDE_LOAD_FRACTION * weight_N:
                    raise UsageError(
                        f"{', '.join(changed)}: case {name}'s wheel loads sum to {total_N:.0f} N, but (chassis_mass + "
                        f"vehicle.unsprung_mass) g is {weight_N:.0f} N; set the loads and the mass together"
                    )
        return dataclasses.replace(self, sections=sections, cases=cases)


def load_parameters(path: str | Path = DEFAULT_PATH) -> Parameters:
    """Read and validate a parameter file; raise :class:`ParameterError` on any defect."""
    path = Path(path)
    try:
        raw = path.read_bytes()
    except OSError as exc:
        raise ParameterError(cannot_read(path, exc)) from None
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise ParameterError(f"{path}: not UTF-8 text (byte {exc.start})") from None
    text = text.removeprefix("\ufeff")  # a byte-order mark, as some editors write
    try:
        doc = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ParameterError(f"{path}: not valid TOML ({exc})") from None

    sources: dict[str, str] = {}
    known_top = set(SCHEMA) | {"cases"}
    unknown = sorted(doc.keys() - known_top)
    if unknown:
        raise ParameterError(f"{path}: {unknown[0]}: unknown key (an effect's own quantities are declared on the "
                             "effect, see `parksteer effects`; change one with --set <effect>.<name>=<value>)")
    sections = {}
    for name, schema in SCHEMA.items():
        if name not in doc:
            raise ParameterError(f"{path}: {name}: missing section")
        sections[name] = check_table(path, name, doc[name], schema, sources)

    cases_doc = doc.get("cases")
    if not isinstance(cases_doc, dict) or not cases_doc:
        raise ParameterError(f"{path}: cases: missing section")
    cases = {name: check_table(path, f"cases.{name}", table, CASE_SCHEMA, sources) for name, table in cases_doc.items()}
    check_statics(path, sections, cases)
    return Parameters(path=path, sections=sections, cases=cases, sources=sources)


