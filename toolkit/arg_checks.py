"""Checks of the arguments a Python caller gives the API: a value of the wrong type or range
is one :class:`~sgtool.errors.SgtoolError` line naming the parameter (``every='x': a whole
number >= 1``), not an error deep inside a stage."""

from __future__ import annotations

import dataclasses
import inspect
import math
import sys
import types
import typing
from typing import Any

import numpy as np

from sgtool.errors import SgtoolError


def whole(name: str, value: Any, least: int | None = None, *, optional: bool = False
          ) -> int | None:
    """``value`` as an int (an int or numpy integer, not a bool), at least ``least``; None
    passes when ``optional``."""
    if value is None and optional:
        return None
    ok = isinstance(value, int | np.integer) and not isinstance(value, bool)
    if not ok or (least is not None and value < least):
        bound = "" if least is None else f" >= {least}"
        raise SgtoolError(f"{name}={value!r}: a whole number{bound}"
                          + (", or None" if optional else ""))
    return int(value)


def number(name: str, value: Any, least: float | None = None, *, optional: bool = False
           ) -> float | None:
    """``value`` as a finite float (an int or float, not a bool), at least ``least``; None
    passes when ``optional``."""
    if value is None and optional:
        return None
    ok = isinstance(value, int | float | np.integer | np.floating) and \
        not isinstance(value, bool) and math.isfinite(value)
    if not ok or (least is not None and value < least):
        bound = "" if least is None else f" >= {least:g}"
        raise SgtoolError(f"{name}={value!r}: a finite number{bound}"
                          + (", or None" if optional else ""))
    return float(value)


def of_type(name: str, value: Any, kind: type | tuple[type, ...], what: str) -> Any:
    """``value`` when it is a ``kind``, else one line: ``{name}: {what}, got {type}``
    (``what`` says what to give, e.g. "a HouseSpec (sgtool.load_house(path))")."""
    if not isinstance(value, kind):
        raise SgtoolError(f"{name}: {what}, got {type(value).__name__}")
    return value


def function(name: str, value: Any, takes: tuple[str, ...] | None = None) -> Any:
    """``value`` when it is None or callable, else one line: ``{name}: a function, got
    {type}``. With ``takes`` (the names of the arguments it is called with, positionally)
    a function that cannot be called so is one line too, now rather than at its first
    call (a function whose signature Python cannot read passes)."""
    if value is None:
        return value
    if not callable(value):
        raise SgtoolError(f"{name}: a function, got {type(value).__name__}")
    if takes is not None:
        try:
            inspect.signature(value).bind(*takes)
        except (ValueError, TypeError) as e:
            if isinstance(e, TypeError):
                own = getattr(value, "__name__", type(value).__name__)
                raise SgtoolError(f"{name}: called as {name}({', '.join(takes)}), which "
                                  f"{own} cannot take ({e})") from None
    return value


def progress(name: str, value: Any, *, method: str = "update") -> Any:
    """A progress argument that takes an object with ``update(n)`` (a tqdm bar) or, with
    ``method=""``, a function: the value itself, None for None or False (no progress), else
    one line saying what to give (True has no bar of its own here: pass ``tqdm()``)."""
    if value is None or value is False:
        return None
    ok = callable(value) if not method else callable(getattr(value, method, None))
    if value is True or not ok:
        what = f"an object with {method}(n) such as a tqdm bar" if method else "a function"
        raise SgtoolError(f"{name}={value!r}: {what}, or None")
    return value


def typed_fields(obj: Any) -> None:
    """Every field of the dataclass ``obj`` annotated with one type (``int``, ``float``,
    ``bool``, ``str`` or a class, or that type ``| None``) holds a value of it: one line
    naming the field otherwise (an int passes for a float). Fields of other annotations
    are the class's own to check."""
    try:
        hints = typing.get_type_hints(type(obj))
    except (NameError, TypeError):  # an annotation only a type checker resolves: the others
        hints = _field_hints(obj)
    for f in dataclasses.fields(obj):
        t = hints.get(f.name)
        union = typing.get_origin(t) in (typing.Union, types.UnionType)
        args = typing.get_args(t) if union else (t,)
        optional = type(None) in args
        kinds = [a for a in args if a is not type(None)]
        value = getattr(obj, f.name)
        if len(kinds) != 1 or (value is None and optional):
            continue
        kind = kinds[0]
        if kind is int:
            whole(f.name, value, optional=optional)
        elif kind is float:
            number(f.name, value, optional=optional)
        elif isinstance(kind, type) and typing.get_origin(kind) is None and \
                not _instance(value, kind):
            raise SgtoolError(f"{f.name}={value!r}: a {kind.__name__}"
                              + (", or None" if optional else ""))


def _instance(value: Any, kind: type) -> bool:
    """``isinstance``, true for what it cannot check (``Any``, a Protocol that is not
    runtime-checkable: the class's own to check)."""
    try:
        return isinstance(value, kind)
    except TypeError:
        return True


def _field_hints(obj: Any) -> dict[str, Any]:
    """The annotations of ``obj``'s fields that resolve one by one in its module (a class
    defined in a function, an import only a type checker sees: those fields are left)."""
    module = sys.modules.get(type(obj).__module__)
    names = dict(vars(module)) if module is not None else {}
    out = {}
    for f in dataclasses.fields(obj):
        try:
            out[f.name] = eval(f.type, names) if isinstance(f.type, str) else f.type  # noqa: S307
        except Exception:  # noqa: BLE001 - an annotation that does not resolve: not checked
            continue
    return out
