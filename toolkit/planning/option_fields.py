"""Typed planner options: the field metadata of the options dataclasses, and the one check
that turns given values (Python objects, or the text of ``-O P.KEY=VALUE``) into them.

A field of an options dataclass carries :func:`option` metadata: its kind (``int``,
``float``, ``bool``, ``str``, ``path``, ``choice``, ``list``: a list of ints, numbers or
texts, comma-separated on the command line, or ``object``: a Python object such as an
encoder, settable from Python only), a help line and its range. :func:`convert_options`
checks a mapping of given values against the fields: an unknown key is one
:class:`UnknownPlannerError` line naming the nearest known key (:mod:`difflib`), a value of
the wrong type or out of range one :class:`PlannerOptionError` line naming the planner,
the option and the rule.
"""

from __future__ import annotations

import dataclasses
import difflib
import math
import os
import pathlib
from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from typing import Any

from sgtool.errors import SgtoolError

KINDS = ("int", "float", "bool", "str", "path", "choice", "list", "object")
ITEM_KINDS = ("int", "float", "str")  # what a ``list`` holds
_ITEM_WORDS = {"int": "integers", "float": "numbers", "str": "texts"}
_TRUE = ("true", "yes", "on", "1")
_FALSE = ("false", "no", "off", "0")
_META = "sgtool_option"


class PlannerOptionError(SgtoolError):
    """A planner option value that does not fit its field (type, range, Python-only)."""


class UnknownPlannerError(PlannerOptionError):
    """A planner name that is not registered, or an option it does not take."""


@dataclass(frozen=True)
class OptionMeta:
    """What a field accepts: ``kind`` (:data:`KINDS`), ``lo``/``hi`` bounds of numbers
    (``lo_open``: strictly above ``lo``), ``choices`` of a ``choice``, ``optional``: None
    is a value (the default: "not set"), ``objects``: a ``path`` also takes Python objects
    (a mapping, a list of paths) as they are; ``path_object``: a ``path`` arrives as a
    ``pathlib.Path`` (a plain field annotated ``Path``), else as text. A ``list`` holds
    ``item`` values (:data:`ITEM_KINDS`, each in the range), ``length`` of them when set,
    and arrives as a tuple (``as_list``: a list)."""

    help: str
    kind: str
    lo: float | None = None
    hi: float | None = None
    lo_open: bool = False
    choices: tuple[str, ...] = ()
    optional: bool = False
    objects: bool = False
    path_object: bool = False
    item: str = ""
    length: int | None = None
    as_list: bool = False

    @property
    def cli(self) -> bool:
        """Settable with ``-O`` (everything but Python objects)."""
        return self.kind != "object"

    def range_text(self) -> str:
        """The accepted values in words (empty when any value of the kind is)."""
        if self.kind == "choice":
            return "one of " + ", ".join(self.choices)
        if self.kind == "list":
            each = dataclasses.replace(self, kind=self.item).range_text()
            count = "any number of" if self.length is None else str(self.length)
            return f"{count} comma-separated {_ITEM_WORDS[self.item]}" + (
                f", each {each}" if each else "")
        if self.lo is not None and self.hi is not None and not self.lo_open:
            return f"{_num(self.lo)}..{_num(self.hi)}"
        parts = []
        if self.lo is not None:
            parts.append(f"{'>' if self.lo_open else '>='} {_num(self.lo)}")
        if self.hi is not None:
            parts.append(f"<= {_num(self.hi)}")
        return " and ".join(parts)


def option(help: str, kind: str, *, lo: float | None = None, hi: float | None = None,
           lo_open: bool = False, choices: Iterable[str] = (), optional: bool = False,
           objects: bool = False, item: str = "",
           length: int | None = None) -> dict[str, OptionMeta]:
    """Metadata for ``dataclasses.field(metadata=...)`` of an options field."""
    if kind not in KINDS:
        raise ValueError(f"kind {kind!r}: one of {KINDS}")
    choices = tuple(choices)
    if (kind == "choice") != bool(choices):
        raise ValueError(f"choices {choices!r}: a choice needs its choices; only a choice "
                         "has them")
    if (kind == "list") != (item in ITEM_KINDS):
        raise ValueError(f"item {item!r}: a list's items are one of {ITEM_KINDS}; only a "
                         "list has items")
    return {_META: OptionMeta(help, kind, lo, hi, lo_open, choices, optional,
                              objects, item=item, length=length)}


@dataclass(frozen=True)
class OptionInfo:
    """One option of a planner, as ``--list-planners`` prints it."""

    name: str
    kind: str
    default: Any
    meta: OptionMeta
    required: bool = False  # a field without a default: the planner cannot be made without it

    def line(self) -> str:
        """``name  kind  default  help [range]``; a Python object shows no default."""
        if not self.meta.cli:
            return f"{self.name} (Python only{', required' if self.required else ''}): " \
                f"{self.meta.help}"
        rng = self.meta.range_text()
        default = ", required" if self.required else \
            "" if self.default is None and "[default:" in self.meta.help else \
            ", default " + ("unset" if self.default is None else _text(self.default) or
                            "none")
        kind = f"{self.meta.item} list" if self.kind == "list" else self.kind
        return (f"{self.name} ({kind}{default}): {self.meta.help}"
                + (f" [{rng}]" if rng else ""))


_PLAIN_KINDS = {bool: "bool", int: "int", float: "float", str: "str"}


def plain_meta(default: Any, hint: Any) -> OptionMeta:
    """The metadata of a field without :func:`option` (a plug-in's plain config dataclass,
    or a parameter of a plug-in's factory) with this ``default`` (None: none), from its
    type ``hint`` (the annotation as :func:`_type_hints` resolves it): ``int``, ``float``,
    ``bool`` or ``str`` alone; a ``Literal`` of strings is a choice; a path (``Path``,
    ``os.PathLike``, alone or with ``str``) a path; ``tuple[float, ...]``,
    ``tuple[int, int]`` or ``list[str]`` (of int, float or str) a list; each of these with
    ``| None`` takes None too. Another annotation (``Any``, one that does not resolve)
    takes the kind of a plain default (3: int); anything else (a dict, a class) is a
    Python object, settable from Python only."""
    import types
    import typing

    args: tuple[Any, ...] = (hint,)
    if typing.get_origin(hint) in (typing.Union, types.UnionType):
        args = typing.get_args(hint)
    optional = type(None) in args
    plain = [a for a in args if a is not type(None)]
    bare = [typing.get_origin(a) or a for a in plain]
    paths = (pathlib.Path, os.PathLike)
    kind, choices, as_path = "object", (), False
    listed = _list_of(plain[0]) if len(plain) == 1 else None
    if listed is not None:
        item, length, as_list = listed
        return OptionMeta(f"a field of {_hint_text(hint)}", "list", optional=optional,
                          item=item, length=length, as_list=as_list)
    if len(plain) == 1 and plain[0] in _PLAIN_KINDS:
        kind = _PLAIN_KINDS[plain[0]]
    elif len(plain) == 1 and typing.get_origin(plain[0]) is typing.Literal and all(
            isinstance(c, str) for c in typing.get_args(plain[0])):
        kind, choices = "choice", tuple(typing.get_args(plain[0]))
    elif bare and all(b in paths or b is str for b in bare) and any(b in paths for b in bare):
        kind, as_path = "path", str not in bare  # Path alone: a Path; str | Path: text
    elif not plain or plain[0] is Any or isinstance(plain[0], str):
        kind = _PLAIN_KINDS.get(type(default), "object")
    return OptionMeta(f"a field of {_hint_text(hint)}", kind, choices=choices,
                      optional=optional, path_object=as_path)


def _hint_text(hint: Any) -> str:
    return hint.__name__ if isinstance(hint, type) else str(hint).replace("typing.", "")


def _list_of(hint: Any) -> tuple[str, int | None, bool] | None:
    """(item kind, length or None, a list) of ``tuple[X, ...]``, ``tuple[X, X]`` or
    ``list[X]`` with X int, float or str; None for any other annotation."""
    import typing

    origin, args = typing.get_origin(hint), typing.get_args(hint)
    if origin is list and len(args) == 1:
        items, length = args, None
    elif origin is tuple and len(args) == 2 and args[1] is Ellipsis:
        items, length = args[:1], None
    elif origin is tuple and args and Ellipsis not in args:
        items, length = args, len(args)
    else:
        return None
    kinds = {_PLAIN_KINDS.get(a, "") for a in items}
    kind = kinds.pop()
    if kinds or kind not in ITEM_KINDS:
        return None
    return kind, length, origin is list


def _type_hints(cls: type) -> dict[str, Any]:
    """The resolved annotation of each field of ``cls`` (text under ``from __future__
    import annotations``, evaluated in its module); an annotation naming what cannot be
    resolved there is kept as its text."""
    import sys

    namespace = dict(vars(sys.modules.get(cls.__module__, sys)))
    return {f.name: resolved(f.type, namespace) for f in dataclasses.fields(cls)}


def resolved(hint: Any, namespace: dict[str, Any]) -> Any:
    """An annotation as text (``from __future__ import annotations``) evaluated in
    ``namespace`` (its module's); one naming what cannot be resolved there is kept as its
    text."""
    for _ in range(2):  # "'int'" under postponed annotations is text twice
        if not isinstance(hint, str):
            break
        try:
            hint = eval(hint, namespace, {})  # noqa: S307 - the plug-in's own annotation
        except Exception:  # noqa: BLE001 - a name not importable there
            break
    return hint


def option_infos(cls: type) -> tuple[OptionInfo, ...]:
    """The options of an options dataclass, in field order; a field without
    :func:`option` metadata takes the kind of its type annotation
    (:func:`plain_meta`)."""
    out = []
    hints = _type_hints(cls)
    for f in dataclasses.fields(cls):
        default = f.default if f.default is not dataclasses.MISSING else None
        meta = f.metadata.get(_META) or plain_meta(default, hints.get(f.name, f.type))
        if meta.kind == "list" and f.default_factory is not dataclasses.MISSING:
            default = f.default_factory()  # (a list field's default needs a factory)
        required = f.init and f.default is dataclasses.MISSING and \
            f.default_factory is dataclasses.MISSING
        out.append(OptionInfo(f.name, meta.kind, default, meta, required))
    return tuple(out)


def parse_text(text: str) -> Any:
    """A value of ``-O`` without a known field: int, float, true/false, else the text."""
    for cast in (int, float):
        try:
            return cast(text)
        except ValueError:
            pass
    if text.lower() in ("true", "false"):
        return text.lower() == "true"
    return text


def nearest(key: str, known: Iterable[str]) -> str | None:
    """The known name closest to ``key`` (difflib), or None when none is close."""
    hits = difflib.get_close_matches(key, list(known), n=1, cutoff=0.6)
    return hits[0] if hits else None


def unknown_keys_error(planner: str, unknown: Iterable[str],
                       known: Iterable[str]) -> UnknownPlannerError:
    """``planner 'P' does not take option(s): k; nearest known: 'x'`` (or the known keys)."""
    bad = sorted(unknown)
    names = list(known)
    near = nearest(bad[0], names)
    hint = f"did you mean {near!r}?" if near else \
        ("it takes: " + ", ".join(names) if names else "it takes no options")
    return UnknownPlannerError(f"planner {planner!r} does not take option(s): "
                               f"{', '.join(bad)}; {hint}")


def convert_options(planner: str, cls: type, given: Mapping[str, Any],
                    from_cli: bool = False) -> dict[str, Any]:
    """``given`` checked against the fields of ``cls`` and converted to their kinds (only
    the given keys); ``from_cli``: the values are ``-O`` text (Python objects refused)."""
    infos = {i.name: i for i in option_infos(cls)}
    unknown = [k for k in given if k not in infos]
    if unknown:
        raise unknown_keys_error(planner, unknown, infos)
    return {k: convert_value(planner, k, infos[k].meta, v, from_cli) for k, v in given.items()}


def check_required(planner: str, cls: type, given: Mapping[str, Any]) -> None:
    """Every option of ``cls`` without a default is in ``given`` (the whole set the
    planner is built with), else one :class:`PlannerOptionError` line naming them."""
    infos = {i.name: i for i in option_infos(cls)}
    missing = [n for n, i in infos.items() if i.required and n not in given]
    if missing:
        how = ", ".join(f"-O {planner}.{n}=..." if infos[n].meta.cli else f"{n}= from Python"
                        for n in missing)
        raise PlannerOptionError(f"planner {planner!r}: option {', '.join(missing)} is "
                                 f"required ({how})")


def build_options(planner: str, cls: type, given: Mapping[str, Any]) -> Any:
    """An instance of ``cls`` from ``given`` (checked, converted), defaults elsewhere."""
    check_required(planner, cls, given)
    return cls(**convert_options(planner, cls, given))


def convert_value(planner: str, key: str, meta: OptionMeta, value: Any,
                  from_cli: bool = False) -> Any:
    """One value converted to its field's kind and checked against its range."""
    def fail(why: str) -> PlannerOptionError:
        return PlannerOptionError(f"planner {planner!r}: option {key}={_shown(value)}: {why}")

    if meta.kind == "object":
        if from_cli:
            raise fail(f"a Python object, set from Python only (make_planner(..., {key}=...))")
        return value
    if value is None and (meta.optional or meta.objects):
        return None
    if from_cli and meta.optional and meta.kind in ("int", "float", "choice", "list") and \
            isinstance(value, str) and not value.strip():
        return None  # `-O NAME.k=` sets an optional number or choice to None
    if meta.kind == "list":
        return _convert_list(planner, key, meta, value, from_cli)
    if meta.kind == "int":
        out: Any = _to_int(value)
        if out is None:
            raise fail("must be an integer")
    elif meta.kind == "float":
        out = _to_float(value)
        if out is None:
            raise fail("must be a number")
        if not math.isfinite(out):
            raise fail("must be a finite number" + (f" {meta.range_text()}"
                                                    if meta.range_text() else ""))
    elif meta.kind == "bool":
        out = _to_bool(value)
        if out is None:
            raise fail("must be true or false")
        return out
    elif meta.kind == "choice":
        text = value.strip().lower() if isinstance(value, str) else None
        match = next((c for c in meta.choices if c.lower() == text), None)
        if match is None:  # any case given, the choice as declared returned
            raise fail(f"must be one of {', '.join(meta.choices)}")
        return match
    elif meta.kind == "path":
        if isinstance(value, str) and not value.strip():  # empty: not set, as before
            return None if meta.optional else value
        if isinstance(value, str | os.PathLike):
            return pathlib.Path(value) if meta.path_object else os.fspath(value)
        if meta.objects and not from_cli:
            return value
        raise fail("must be a path")
    else:  # str
        if isinstance(value, str):
            return value
        if isinstance(value, int | float) and not isinstance(value, bool):
            return str(value)
        raise fail("must be text")
    if (meta.lo is not None and (out < meta.lo or (meta.lo_open and out == meta.lo))) or \
            (meta.hi is not None and out > meta.hi):
        raise fail(f"must be {meta.range_text()}")
    return out


def _convert_list(planner: str, key: str, meta: OptionMeta, value: Any,
                  from_cli: bool) -> tuple[Any, ...] | list[Any]:
    """A ``list`` option's value: text split at commas (empty: no items), or a list or
    tuple, each item converted to ``meta.item`` and checked against the range."""
    if isinstance(value, str):
        items: list[Any] = [v.strip() for v in value.split(",")] if value.strip() else []
    elif isinstance(value, list | tuple) and not from_cli:
        items = list(value)
    else:
        raise PlannerOptionError(f"planner {planner!r}: option {key}={_shown(value)}: must "
                                 f"be {meta.range_text()}")
    if meta.length is not None and len(items) != meta.length:
        raise PlannerOptionError(f"planner {planner!r}: option {key}={_shown(value)}: must "
                                 f"be {meta.range_text()}, not {len(items)}")
    each = dataclasses.replace(meta, kind=meta.item, optional=False)
    out = [convert_value(planner, f"{key}[{i}]", each, v, from_cli)
           for i, v in enumerate(items)]
    return out if meta.as_list else tuple(out)


def _to_int(value: Any) -> int | None:
    if isinstance(value, bool):
        return None
    if isinstance(value, int):
        return value
    if isinstance(value, float) and math.isfinite(value) and value.is_integer():
        return int(value)
    if isinstance(value, str):
        try:
            return int(value.strip())
        except ValueError:
            return None
    return None


def _to_float(value: Any) -> float | None:
    if isinstance(value, bool):
        return None
    if isinstance(value, int | float):
        return float(value)
    if isinstance(value, str):
        try:
            return float(value.strip())
        except ValueError:
            return None
    return None


def _to_bool(value: Any) -> bool | None:
    if isinstance(value, bool):
        return value
    if isinstance(value, int) and value in (0, 1):
        return bool(value)
    if isinstance(value, str):
        low = value.strip().lower()
        if low in _TRUE:
            return True
        if low in _FALSE:
            return False
    return None


def _num(x: float) -> str:
    return str(int(x)) if float(x).is_integer() else str(x)


def _text(value: Any) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, list | tuple):
        return ",".join(_text(v) for v in value)
    return str(value)


def _shown(value: Any) -> str:
    """A value in a message: text as given, objects by their type (no long reprs)."""
    if isinstance(value, str):
        return value
    if isinstance(value, int | float | bool):
        return _text(value)
    if isinstance(value, list | tuple) and all(isinstance(v, str | int | float) for v in value):
        return repr(value)  # (from Python: a list is no number, however short)
    return f"<{type(value).__name__}>"
