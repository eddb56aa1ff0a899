"""A user's effect files checked at the door, before a model is built from them.

An effect written by the user (``--effects=+FILE.py`` or ``+my_pkg.my_effect``, or named in the environment variable
``PARKSTEER_EFFECT_MODULES``) is loaded once here, each problem a one-line UsageError naming the file:

- its quantities' declarations (:func:`parksteer.parameters.declaration_problem`: bounds present, numbers, ordered,
  finite for a quantity the diagnosis fits, a default within them), each unit one pint knows and SI (every value of
  the model is read in SI: a quantity in ``mm`` would be taken as metres);
- a diagnosis candidate's strength (the quantity whose 0 means absent) bounded above: the ranking probes it at a
  fraction of its upper bound;
- its name: not one of the library's effects (an effect of the same name would replace the library's in the
  registry, unseen) unless the spec removes the library's first (``--effects=-column_friction,+FILE.py``), and not
  a section of the parameter file (``tyre``, ``case``, ``run``), whose keys its quantities would share;
- while the command runs, an exception raised in one of its hooks (``loads``, ``configure``, ``boost_law``, ...),
  in this process or in a worker, becomes one line naming the file, the hook and the line; so does one the model
  raises on what a hook returned, where the package's call of the hook is on the traceback.
"""

from __future__ import annotations

import math
import os
import re
import traceback
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass

from ..errors import UsageError


@dataclass(frozen=True)
class UserEffect:
    """One effect module the user gave: its reference as written, the effect, and its source file."""

    ref: str
    effect: object
    path: str | None


def is_module_ref(name: str) -> bool:
    """An effects spec's item that names a module (a file or a dotted name), not an effect of the registry (as
    :func:`parksteer.model.symbolic.components.resolve_effects` tells them apart)."""
    return "." in name or "/" in name or os.sep in name


def _spec_items(spec: str | None) -> list[tuple[str, str]]:
    """(sign, name) of each item of an effects spec; sign '' for a bare list's item."""
    items = [s.strip() for s in (spec or "").split(",") if s.strip()]
    return [(s[0], s[1:].strip()) if s[0] in "+-" else ("", s) for s in items]


# parksteer.model.symbolic.components.MODULES_ENV, named here so that a command without a user's effect does not
# import the symbolic model to look at the environment (tests/hardening/test_effect_files.py checks they agree)
MODULES_ENV = "PARKSTEER_EFFECT_MODULES"


def _environment_refs() -> list[str]:
    return [ref for ref in os.environ.get(MODULES_ENV, "").split(os.pathsep) if ref]


def user_refs(spec: str | None) -> list[str]:
    """The user's effect modules an effects spec and the environment name."""
    return [name for _, name in _spec_items(spec) if is_module_ref(name)] + _environment_refs()


@contextmanager
def _without_environment_effects() -> Iterator[None]:
    saved = os.environ.pop(MODULES_ENV, None)
    try:
        yield
    finally:
        if saved is not None:
            os.environ[MODULES_ENV] = saved


def library_effects() -> dict:
    """The effects of the package and of installed entry points (not the user's modules)."""
    from ..model.symbolic.components import discover_effects

    with _without_environment_effects():
        return discover_effects()


def _source_path(ref: str) -> str | None:
    """The file a reference's module is read from (absolute), or None when it cannot be found."""
    if ref.endswith(".py") or "/" in ref or os.sep in ref:
        return os.path.abspath(ref)
    import importlib.util

    try:
        spec = importlib.util.find_spec(ref)
    except (ImportError, ValueError):
        return None
    return os.path.abspath(spec.origin) if spec is not None and spec.origin else None


def _load(ref: str) -> UserEffect:
    from ..model.symbolic.components import load_effect_module

    try:
        effect = load_effect_module(ref)
    except UsageError as exc:
        text = str(exc)
        raise UsageError(text if ref in text else f"effect file {ref}: {text}") from None
    return UserEffect(ref, effect, _source_path(ref))


def unit_problem(unit: str) -> str | None:
    """Why `unit` cannot be a model quantity's unit (pint does not know it, or it is not SI), or None."""
    from ..measure.units import unit_registry

    ureg = unit_registry()
    try:
        one = ureg.Quantity(1.0, ureg.parse_units(unit))
        base = one.to_base_units()
    except Exception:  # pint raises several types (undefined unit, syntax, tokenizer) for one mistake
        return f"unit {unit!r} is not a unit pint knows"
    if not math.isclose(float(base.magnitude), 1.0, rel_tol=1e-12):
        si = f"{base.units:~}" or "1"
        return (f"unit {unit!r} is not SI (1 {unit} = {float(base.magnitude):g} {si}): the model reads every value "
                f"in SI units, give {si}")
    return None


def check_user_effect(found: UserEffect, library: dict, removed: set[str]) -> None:
    """One user's effect against the door's rules (module docstring); one-line UsageError naming its file."""
    from ..model.symbolic.components import strength_parameter
    from ..parameters import CASE, SCHEMA, VEHICLE_SPEED

    effect, where = found.effect, f"effect file {found.ref}"
    name = effect.name
    if name in SCHEMA or name in (CASE, VEHICLE_SPEED.section):
        raise UsageError(f"{where}: effect name {name!r} is a section of the parameter file's keys; name it otherwise")
    if name in library and type(library[name]) is not type(effect) and name not in removed:
        raise UsageError(f"{where}: effect {name!r} has the name of the library's; name it otherwise, or remove the "
                         f"library's first: --effects=-{name},+{found.ref}")
    for q in effect.quantities:
        problem = unit_problem(q.unit)
        if problem is not None:
            raise UsageError(f"{where}: {q.key}: {problem}")
    if effect.diagnosis_candidate or effect.assist_candidate:
        strength = strength_parameter(effect)
        if strength is not None and not math.isfinite(strength.upper):
            raise UsageError(f"{where}: {strength.key}: a diagnosis candidate's strength needs a finite upper bound, "
                             f"the most its physics allows (the ranking probes a fraction of it; now "
                             f"{strength.bounds_text()} {strength.unit})")


def check_effect_files(spec: str | None) -> list[UserEffect]:
    """Load and check every user's effect module of the effects spec `spec` and of the environment (module
    docstring); return them. Nothing is loaded when there is none."""
    refs = user_refs(spec)
    if not refs:
        return []
    library = library_effects()
    removed: set[str] = set()
    found: list[UserEffect] = []
    items = _spec_items(spec) + [("+", ref) for ref in _environment_refs()]
    bare = [name for sign, name in items if sign == "" and not is_module_ref(name)]
    for sign, name in items:
        if sign == "-" and not is_module_ref(name):
            removed.add(name)
        if not is_module_ref(name):
            continue
        user = _load(name)
        # a bare list names the set exactly: the library's effect of that name is out unless the list names it too
        not_listed = {n for n in library if n not in bare} if sign == "" else set()
        check_user_effect(user, library, removed | not_listed)
        found.append(user)
    return found


_FRAME = re.compile(r'File "([^"]+)", line (\d+), in (\S+)')


def _frames(exc: BaseException) -> list[tuple[str, int, str]]:
    """(file, line, function) of every frame an exception passed, outermost first, through its chain; a worker's
    exception re-raised in this process carries its frames as text (multiprocessing's RemoteTraceback)."""
    out: list[tuple[str, int, str]] = []
    seen: set[int] = set()
    stack: list[BaseException] = [exc]
    while stack:
        e = stack.pop()
        if id(e) in seen:
            continue
        seen.add(id(e))
        out += [(f.filename, f.lineno or 0, f.name) for f in traceback.extract_tb(e.__traceback__)]
        remote = getattr(e, "tb", None)
        if isinstance(remote, str):
            out += [(m[0], int(m[1]), m[2]) for m in _FRAME.findall(remote)]
        stack += [c for c in (e.__cause__, e.__context__) if c is not None]
    return out


def _first_line(exc: BaseException) -> str:
    text = str(exc).strip().splitlines()
    return f"{type(exc).__name__}: {text[0]}" if text else type(exc).__name__


_HOOK_CALL = re.compile(r"\beffect\.(\w+)\(")


def _returned_by_hook(exc: BaseException, users: list[UserEffect]) -> str | None:
    """The one line of an exception raised by the package on what a user's hook returned (a load that is no
    (point, vector) pair, say): the package's frame that called the hook holds the effect as ``effect``, and its line
    names the hook. None when no such frame is on the traceback."""
    modules = {type(u.effect).__module__: u for u in users}
    tb = exc.__traceback__
    while tb is not None:
        effect = tb.tb_frame.f_locals.get("effect")
        user = modules.get(type(effect).__module__) if effect is not None else None
        if user is not None:
            line = traceback.extract_tb(tb, limit=1)[0].line or ""
            match = _HOOK_CALL.search(line)
            hook = f"its hook {match.group(1)}()" if match else "one of its hooks"
            return (f"effect file {user.ref}: {hook} returned what the model cannot use ({_first_line(exc)}); see "
                    "what each hook returns in parksteer.model.symbolic.components.Effect")
        tb = tb.tb_next
    return None


def hook_error(exc: BaseException, users: list[UserEffect]) -> str | None:
    """The one line of an exception raised in a user's effect (its file, the hook the model called, the line) or on
    what one of its hooks returned, or None when the exception has nothing to do with a user's file."""
    for user in users:
        if user.path is None:
            continue
        mine = [(line, func) for file, line, func in _frames(exc) if os.path.abspath(file) == user.path]
        if mine:
            hook, line = mine[0][1], mine[-1][0]
            return f"effect file {user.ref}: its hook {hook}() raised {_first_line(exc)} (line {line})"
    return _returned_by_hook(exc, users)


@contextmanager
def effect_files_checked(spec: str | None, outputs: dict[str, str | None] | None = None) -> Iterator[None]:
    """Check the user's effect files of `spec` and the environment at the door, then run the block with an
    exception in one of their hooks reported as one line (module docstring). `outputs` ({option: path}) are files
    the command writes: none may be one of the effect files it reads (``--suggest-effect`` onto the file given with
    ``--effects=+``)."""
    users = check_effect_files(spec)
    for option, value in (outputs or {}).items():
        if value is not None and any(u.path == os.path.abspath(value) for u in users):
            raise UsageError(f"{option} {value}: the effect file the model is built with; write the new one beside it")
    if not users:
        yield
        return
    try:
        yield
    except UsageError:
        raise
    except Exception as exc:
        line = hook_error(exc, users)
        if line is None:
            raise
        raise UsageError(line) from None
