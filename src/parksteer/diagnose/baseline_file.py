"""A baseline as a file a person reads: TOML, every value with its 95 % interval and source
(:class:`parksteer.diagnose.baseline.Baseline`). Read back, a file that is not one, or is damaged, is refused in one
line naming the file and the key."""

from __future__ import annotations

import hashlib
import math
import re
import tempfile
import tomllib
from pathlib import Path

from ..errors import UsageError
from ..parameters import Parameters
from .baseline_form import FORMAT, HeldForm, Threshold

HEADER = ("# A car's baseline: what its healthy records fix (parksteer baseline), read by parksteer diagnose "
          "--baseline.\n# Every value with its 95 % interval and source; the threshold of \"as the baseline\" with "
          "how it was found.\n")


def _string(text: str) -> str:
    return '"' + str(text).replace("\\", "\\\\").replace('"', '\\"').replace("\n", "\\n") + '"'


def _key(name: str) -> str:
    """A bare key where TOML allows one, else quoted (a dotted parameter key stays one key)."""
    return name if re.fullmatch(r"[A-Za-z0-9_-]+", name) else _string(name)


def _value(x) -> str:
    if isinstance(x, bool):
        return "true" if x else "false"
    if isinstance(x, int):
        return str(x)
    if isinstance(x, float):
        return repr(x) if math.isfinite(x) else ("nan" if math.isnan(x) else ("inf" if x > 0 else "-inf"))
    if isinstance(x, str):
        return _string(x)
    if isinstance(x, (list, tuple)):
        return "[" + ", ".join(_value(v) for v in x) + "]"
    if isinstance(x, dict):
        return "{ " + ", ".join(f"{_key(k)} = {_value(v)}" for k, v in x.items() if v is not None) + " }"
    return _value(float(x))


def _table(name: str, entries: dict) -> list[str]:
    lines = [f"[{name}]"]
    lines += [f"{_key(k)} = {_value(v)}" for k, v in entries.items() if v is not None]
    return lines + [""]


def baseline_text(baseline) -> str:
    """The TOML text of `baseline`."""
    lines = [HEADER, f"format = {_string(FORMAT)}", ""]
    lines += _table("vehicle", {"file": baseline.vehicle, "fingerprint": baseline.fingerprint})
    lines += _table("records", {"files": list(baseline.records), "model": list(baseline.effects)})
    lines += _table("absolute", {"verdict": baseline.verdict, "over_floor": float(baseline.over_floor),
                                 "source": "the absolute diagnosis of the records above"})
    lines += _table("calibrated", {k: dict(v) for k, v in baseline.calibrated.items()})
    form = baseline.form
    if form is not None:
        lines += _table("form", {"source": form.source, "effect": form.effect, "shape_class": form.shape_class,
                                 "knots": int(form.knots), "orders": [int(m) for m in form.orders],
                                 "signature": form.signature})
        lines += _table("form.places", {k: float(v) for k, v in form.places.items()})
        lines += _table("form.strengths", {k: dict(v) for k, v in form.strengths.items()})
    t = baseline.threshold
    lines += _table("threshold", {"over_floor": float(t.over_floor), "bic_per_sample": float(t.bic_per_sample),
                                  "lead_per_sample": float(t.lead_per_sample), "method": t.method})
    for part in t.parts:
        lines += ["[[threshold.parts]]"] + [f"{_key(k)} = {_value(v)}" for k, v in part.items()
                                            if v is not None] + [""]
    if baseline.identified_vehicle is not None:
        text = baseline.identified_vehicle
        # as it reads, where a literal multi-line string can hold it (TOML drops the newline after the quotes)
        literal = "'''" not in text and "\r" not in text and not text.endswith("'")
        quoted = "'''\n" + text + "'''" if literal else _string(text)
        lines += ["[identified]", "# the vehicle file as parksteer assist identify writes it from the records above",
                  f"vehicle = {quoted}", ""]
    return "\n".join(lines)


def content_hash(data: bytes) -> str:
    return hashlib.sha256(data).hexdigest()[:16]


def _get(table: dict, key: str, kind, where: str, prefix: str = ""):
    name = f"{prefix}{key}"
    if key not in table:
        raise UsageError(f"{where}: key {name!r}: missing")
    value = table[key]
    if kind is float and isinstance(value, int) and not isinstance(value, bool):
        value = float(value)
    if not isinstance(value, kind):
        raise UsageError(f"{where}: key {name!r}: expected {getattr(kind, '__name__', kind)}, got {value!r}")
    return value


def _estimate(entry, where: str, name: str) -> dict:
    if not isinstance(entry, dict):
        raise UsageError(f"{where}: key {name!r}: expected {{ value, ci95, standard_error }}")
    value = _get(entry, "value", float, where, f"{name}.")
    ci = _get(entry, "ci95", list, where, f"{name}.")
    if len(ci) != 2 or not all(isinstance(c, (int, float)) for c in ci):
        raise UsageError(f"{where}: key {name + '.ci95'!r}: expected two numbers")
    out = {"value": value, "ci95": [float(c) for c in ci]}
    if "standard_error" in entry:
        out["standard_error"] = float(_get(entry, "standard_error", float, where, f"{name}."))
    if "source" in entry:
        out["source"] = str(entry["source"])
    return out


def parse_baseline(data: dict, where: str) -> dict:
    """The fields of the :class:`~parksteer.diagnose.baseline.Baseline` of parsed TOML `data` (`where`: its file)."""
    if data.get("format") != FORMAT:
        raise UsageError(f"{where}: key 'format': not a parksteer baseline ({FORMAT!r} expected)")
    vehicle = _get(data, "vehicle", dict, where)
    records = _get(data, "records", dict, where)
    absolute = _get(data, "absolute", dict, where)
    calibrated = {k: _estimate(v, where, f"calibrated.{k}")
                  for k, v in _get(data, "calibrated", dict, where).items()}
    form = None
    if "form" in data:
        f = _get(data, "form", dict, where)
        source = _get(f, "source", str, where, "form.")
        if source not in ("candidate", "signature"):
            raise UsageError(f"{where}: key 'form.source': {source!r} (candidate or signature)")
        strengths = {k: _estimate(v, where, f"form.strengths.{k}")
                     for k, v in _get(f, "strengths", dict, where, "form.").items()}
        places = {k: float(_get(f.get("places", {}), k, float, where, "form.places."))
                  for k in f.get("places", {})}
        form = HeldForm(source, _get(f, "effect", str, where, "form."), strengths, places,
                        f.get("shape_class"), int(f.get("knots", 0)), tuple(int(m) for m in f.get("orders", ())),
                        f.get("signature"))
        if source == "signature" and form.shape_class is None:
            raise UsageError(f"{where}: key 'form.shape_class': missing (a signature's form)")
    t = _get(data, "threshold", dict, where)
    threshold = Threshold(_get(t, "over_floor", float, where, "threshold."),
                          _get(t, "bic_per_sample", float, where, "threshold."),
                          _get(t, "method", str, where, "threshold."), tuple(dict(p) for p in t.get("parts", ())),
                          # a file written before the lead was learnt: the settings' band alone
                          _get(t, "lead_per_sample", float, where, "threshold.") if "lead_per_sample" in t else 0.0)
    identified = data.get("identified", {}).get("vehicle")
    return {"vehicle": vehicle.get("file"), "fingerprint": _get(vehicle, "fingerprint", str, where, "vehicle."),
            "records": tuple(_get(records, "files", list, where, "records.")),
            "effects": tuple(_get(records, "model", list, where, "records.")), "calibrated": calibrated,
            "verdict": _get(absolute, "verdict", str, where, "absolute."),
            "over_floor": _get(absolute, "over_floor", float, where, "absolute."), "form": form,
            "threshold": threshold, "identified_vehicle": identified}


def read_bytes(path) -> tuple[bytes, dict]:
    """(the bytes of the file `path`, its TOML parsed); a file that cannot be read or is not TOML: one line."""
    where = str(path)
    try:
        data = Path(path).read_bytes()
    except OSError as exc:
        raise UsageError(f"{where}: cannot read ({exc.strerror})") from None
    try:
        return data, tomllib.loads(data.decode("utf-8"))
    except (UnicodeDecodeError, tomllib.TOMLDecodeError) as exc:
        raise UsageError(f"{where}: not a baseline file ({exc})") from None


def identified_parameters(text: str) -> Parameters:
    """The parameters of an identified vehicle file held in a baseline."""
    from ..vehicle import load_vehicle

    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "identified.toml"
        path.write_text(text, encoding="utf-8")
        return load_vehicle(path)

