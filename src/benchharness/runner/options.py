"""Strategy options: ``--strategy-option KEY=VALUE`` applied to a strategy's config dataclasses.

Why: every baseline is set by typed configuration dataclasses
(``PR2RubiksConfig``, ``IngraspConfig`` ...). An ablation — the old 3 x 3
pre-touch grid instead of the sweeps, no sideways retreat, another injected
error — has to run from the command line or a sweep file like any other
run, be part of the run key (so its trials never mix with the defaults'),
and be refused before any trial when a key or a value is wrong.

A strategy declares what can be set with ``Registration.options``: a
callable returning ``{keyword: default dataclass instance}``, the keyword
arguments its factory takes. A key is a dotted path of field names:

* ``pretouch_mode`` — a field of the first keyword's dataclass (the
  strategy's main config);
* ``errors.tracking_std`` — a field of a nested dataclass;
* ``exec_config.placement_grip_cone_deg`` — a field of another keyword's
  dataclass.

Values are read by the field's annotation: ``bool`` (true/false, yes/no,
on/off, 1/0), ``int``, ``float`` (``inf`` allowed, ``nan`` refused),
``str``, ``X | None`` (``none``), tuples as comma lists (``0.25,0.35``).
Each accepted value is written back in one canonical spelling, so
``0.10`` and ``0.1`` make the same run key.
"""

from __future__ import annotations

import dataclasses
import math
import types
import typing
from collections.abc import Callable, Mapping, Sequence
from typing import Any

__all__ = [
    "OptionError",
    "apply_options",
    "describe_options",
    "normalise_options",
    "parse_pairs",
]

_TRUE = ("true", "yes", "on", "1")
_FALSE = ("false", "no", "off", "0")


class OptionError(ValueError):
    """A strategy option that cannot be applied (unknown key, unreadable value); the message names it."""


def parse_pairs(pairs: Sequence[str]) -> list[tuple[str, str]]:
    """``KEY=VALUE`` strings as (key, value), keys stripped, each key at most once."""
    out: list[tuple[str, str]] = []
    seen: set[str] = set()
    for p in pairs:
        if "=" not in p:
            raise OptionError(f"--strategy-option {p!r}: expected KEY=VALUE")
        key, value = (s.strip() for s in p.split("=", 1))
        key = key.replace("-", "_")
        if not key:
            raise OptionError(f"--strategy-option {p!r}: empty key")
        if key in seen:
            raise OptionError(f"--strategy-option {key}: given twice")
        seen.add(key)
        out.append((key, value))
    return out


_HINTS: dict[type, dict[str, Any]] = {}
_DOCS: dict[type, dict[str, str]] = {}


def _hints(cls: type) -> dict[str, Any]:
    if cls not in _HINTS:
        _HINTS[cls] = typing.get_type_hints(cls)
    return _HINTS[cls]


def _is_config(obj: Any) -> bool:
    return dataclasses.is_dataclass(obj) and not isinstance(obj, type)


def _fmt(value: Any) -> str:
    """The canonical spelling of a converted value (read back by :func:`_convert` to the same value)."""
    if value is None:
        return "none"
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float):
        return repr(value)
    if isinstance(value, tuple):
        return ",".join(_fmt(v) for v in value)
    return str(value)


def _convert(raw: str, tp: Any, key: str) -> Any:
    """``raw`` as a value of annotation ``tp`` (``OptionError`` naming ``key`` if it is not one)."""
    origin = typing.get_origin(tp)
    args = typing.get_args(tp)
    if origin in (typing.Union, types.UnionType):
        rest = [a for a in args if a is not type(None)]
        if type(None) in args and raw.strip().lower() in ("none", "null", ""):
            return None
        if len(rest) == 1:
            return _convert(raw, rest[0], key)
        # several types (``float | Literal["friction"]``): the first that reads the text, text last
        errors = []
        for a in sorted(rest, key=lambda a: a is str):
            try:
                return _convert(raw, a, key)
            except OptionError as exc:
                errors.append(str(exc).split(": ", 1)[-1])
        raise OptionError(f"--strategy-option {key}={raw}: {' / '.join(errors)}")
    if origin is typing.Literal:
        for a in args:
            if str(a) == raw.strip():
                return a
        choices = ", ".join(str(a) for a in args)
        raise OptionError(f"--strategy-option {key}={raw}: not one of {choices}")
    if origin is tuple:
        parts = [p.strip() for p in raw.split(",")] if raw.strip() else []
        if len(args) == 2 and args[1] is Ellipsis:
            return tuple(_convert(p, args[0], key) for p in parts)
        if len(parts) != len(args):
            raise OptionError(
                f"--strategy-option {key}={raw}: expected {len(args)} comma-separated values"
            )
        return tuple(_convert(p, a, key) for p, a in zip(parts, args))
    text = raw.strip()
    if tp is bool:
        if text.lower() in _TRUE:
            return True
        if text.lower() in _FALSE:
            return False
        raise OptionError(f"--strategy-option {key}={raw}: not a yes/no value (true or false)")
    if tp is int:
        try:
            return int(text)
        except ValueError:
            raise OptionError(f"--strategy-option {key}={raw}: not an integer") from None
    if tp is float:
        try:
            value = float(text)
        except ValueError:
            raise OptionError(f"--strategy-option {key}={raw}: not a number") from None
        if math.isnan(value):
            raise OptionError(f"--strategy-option {key}={raw}: not a number")
        return value
    if tp is str:
        return text
    raise OptionError(f"--strategy-option {key}: its type {tp} cannot be set from text")


def _fields(obj: Any) -> dict[str, dataclasses.Field]:
    return {f.name: f for f in dataclasses.fields(obj) if f.init}


def _set(obj: Any, path: list[str], raw: str, key: str) -> tuple[Any, str]:
    """``obj`` with the field at ``path`` set from ``raw``; and the value's canonical spelling."""
    name = path[0]
    fields = _fields(obj)
    if name not in fields:
        import difflib

        near = difflib.get_close_matches(name, list(fields), n=3)
        hint = (
            f"did you mean {', '.join(near)}?"
            if near
            else f"options here are {', '.join(sorted(fields))}"
        )
        raise OptionError(f"--strategy-option {key}: no option {name!r}; {hint}")
    current = getattr(obj, name)
    if len(path) > 1:
        if not _is_config(current):
            raise OptionError(f"--strategy-option {key}: {name!r} has no fields")
        new, text = _set(current, path[1:], raw, key)
    else:
        if _is_config(current):
            sub = ", ".join(f"{name}.{f}" for f in sorted(_fields(current)))
            raise OptionError(f"--strategy-option {key}: {name!r} is a group; set one of {sub}")
        new = _convert(raw, _hints(type(obj))[name], key)
        text = _fmt(new)
    try:
        return dataclasses.replace(obj, **{name: new}), text
    except (TypeError, ValueError) as exc:
        raise OptionError(f"--strategy-option {key}={raw}: {exc}") from None


def _resolve(defaults: Mapping[str, Any], key: str) -> tuple[str, list[str]]:
    """(factory keyword, field path) of a key: a leading keyword name, else the first keyword."""
    parts = key.split(".")
    first = next(iter(defaults))
    if len(parts) > 1 and parts[0] in defaults and parts[0] not in _fields(defaults[first]):
        return parts[0], parts[1:]
    return first, parts


def apply_options(
    defaults: Mapping[str, Any], pairs: Sequence[tuple[str, str]]
) -> tuple[dict[str, Any], tuple[tuple[str, str], ...]]:
    """The factory keywords with ``pairs`` applied, and the pairs in canonical form (sorted).

    ``defaults``: keyword -> default config dataclass instance, as
    ``Registration.options`` returns them. Raises :class:`OptionError`.
    """
    configs = dict(defaults)
    canon: list[tuple[str, str]] = []
    first = next(iter(defaults), None)
    for key, raw in pairs:
        if first is None:
            raise OptionError(f"--strategy-option {key}: this strategy has no options")
        kw, path = _resolve(defaults, key)
        configs[kw], text = _set(configs[kw], path, raw, key)
        canon.append((".".join(path) if kw == first else f"{kw}.{'.'.join(path)}", text))
    return configs, tuple(sorted(canon))


def normalise_options(
    options: Callable[[], Mapping[str, Any]] | None,
    name: str,
    pairs: Sequence[str],
    factory: Callable[..., Any] | None = None,
) -> tuple[tuple[str, str], ...]:
    """Check ``KEY=VALUE`` strings against a strategy's options; their canonical form for the run key.

    ``name`` is the strategy, for the messages. With ``factory``, the
    strategy is also built once with the options, so that what its
    constructor refuses (an unknown ``pretouch_mode``) is refused here,
    before any trial, rather than as every trial's ``strategy_error``.
    """
    parsed = parse_pairs(pairs)
    if not parsed:
        return ()
    if options is None:
        raise OptionError(
            f"--strategy-option: strategy {name!r} declares no options"
            " (its registration has no 'options')"
        )
    kwargs, canon = apply_options(options(), parsed)
    if factory is not None:
        try:
            factory(**kwargs)
        except (TypeError, ValueError) as exc:
            given = " ".join(f"{k}={v}" for k, v in canon)
            raise OptionError(
                f"--strategy-option {given}: strategy {name!r} refuses it: {exc}"
            ) from None
    return canon


def field_docs(cls: type) -> dict[str, str]:
    """Each field's ``#:`` comment (the lines above it, or on its line), through the class's bases.

    The same convention Sphinx autodoc reads; a field without one gets no entry.
    """
    import inspect
    import re

    if cls in _DOCS:
        return _DOCS[cls]
    docs: dict[str, str] = _DOCS.setdefault(cls, {})
    for klass in reversed(cls.__mro__):
        if not dataclasses.is_dataclass(klass):
            continue
        try:
            lines = inspect.getsource(klass).splitlines()
        except (OSError, TypeError):
            continue
        pending: list[str] = []
        for line in lines:
            text = line.strip()
            if text.startswith("#:"):
                pending.append(text[2:].strip())
                continue
            m = re.match(r"([A-Za-z_]\w*)\s*:[^=]*(=.*)?$", text)
            if m and line.startswith("    ") and not line.startswith("     "):
                inline = text.split("#:", 1)[1].strip() if "#:" in text else ""
                doc = " ".join(pending) or inline
                if doc:
                    docs[m.group(1)] = doc
            pending = []
    return docs


def _label(tp: Any) -> str:
    """An annotation as a person writes it: ``float | 'friction' | None``, ``tuple[float, ...]``."""
    origin, args = typing.get_origin(tp), typing.get_args(tp)
    if tp is type(None):
        return "None"
    if origin in (typing.Union, types.UnionType):
        return " | ".join(_label(a) for a in args)
    if origin is typing.Literal:
        return " | ".join(repr(a) for a in args)
    if origin is tuple:
        return "tuple[" + ", ".join("..." if a is Ellipsis else _label(a) for a in args) + "]"
    return tp.__name__ if isinstance(tp, type) else str(tp).replace("typing.", "")


def describe_options(defaults: Mapping[str, Any]) -> list[tuple[str, str, str, str]]:
    """Every settable key in declaration order: (key, type, default, its ``#:`` comment)."""
    rows: list[tuple[str, str, str, str]] = []
    first = next(iter(defaults), None)

    def walk(obj: Any, prefix: str) -> None:
        hints = _hints(type(obj))
        docs = field_docs(type(obj))
        for name, _ in _fields(obj).items():
            value = getattr(obj, name)
            if _is_config(value):
                walk(value, f"{prefix}{name}.")
                continue
            rows.append((f"{prefix}{name}", _label(hints[name]), _fmt(value), docs.get(name, "")))

    for kw, obj in defaults.items():
        walk(obj, "" if kw == first else f"{kw}.")
    return rows
