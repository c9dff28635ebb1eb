"""Plug-in planners: a user's class or factory named ``module:Name``, or a name an installed
package registers in the entry-point group ``sgtool.planners``.

``module:Name`` (``Name`` may be dotted: ``mypkg.planners:Outer.Inner``) is imported with
:mod:`importlib` from ``sys.path`` (``PYTHONPATH``); an entry point ``name = module:Name``
in the group :data:`GROUP` names the same thing. Either is called with the planner's
options as keyword arguments and must return a :class:`~sgtool.planning.base.Planner`
(``name``, ``reset``, ``decide``, ``feedback``). When the class or factory has an
attribute ``Options`` that is a dataclass whose fields carry
:func:`~sgtool.planning.option_fields.option` metadata, the options are checked and
converted against it as a built-in planner's are; otherwise ``-O`` text is converted to the
type its parameter of the factory is annotated with, as a plain ``Options`` field's is
(``weights: tuple[float, float]`` takes ``-O my:P.weights=0.3,0.7``; :func:`signature_metas`),
and parsed as int, float, true/false or text for a parameter with another annotation or none
(from Python, text given for an annotated parameter is converted alike, other values are
passed as given; a key the factory does not take is one line naming the nearest, unless it
takes ``**kwargs``). A plug-in that fails to import,
raises, or returns something else is one :class:`PluginError` line naming it.
"""

from __future__ import annotations

import dataclasses
import importlib
import re
from collections.abc import Callable, Mapping
from importlib import metadata
from typing import Any

from sgtool.errors import raised_text, returned_text
from sgtool.planning.base import Planner
from sgtool.planning.option_fields import (
    OptionMeta,
    PlannerOptionError,
    check_required,
    convert_options,
    convert_value,
    plain_meta,
    resolved,
    unknown_keys_error,
)

GROUP = "sgtool.planners"
_DOTTED = r"[A-Za-z_]\w*(?:\.[A-Za-z_]\w*)*"
SPEC = re.compile(rf"({_DOTTED}):({_DOTTED})")
PLANNER_PARTS = ("name", "reset", "decide", "feedback")


class PluginError(PlannerOptionError):
    """A plug-in planner that cannot be imported, raises, or is no Planner."""


def is_spec(name: str) -> bool:
    """``name`` is written ``module:Name`` (a ':' in it)."""
    return ":" in name


def check_spec(name: str) -> tuple[str, str]:
    """(module, attribute path) of ``module:Name``; anything else is a :class:`PluginError`."""
    m = SPEC.fullmatch(name.strip())
    if m is None:
        raise PluginError(f"planner {name!r}: a plug-in is named module:Name, e.g. "
                          "mypkg.planners:MyPlanner")
    return m.group(1), m.group(2)


def registered() -> dict[str, list[metadata.EntryPoint]]:
    """The planners installed packages register (group :data:`GROUP`), by name: the
    distinct ``module:Name`` values registered under it, in ``importlib.metadata``'s
    order (two when two packages register one name)."""
    out: dict[str, list[metadata.EntryPoint]] = {}
    for ep in metadata.entry_points(group=GROUP):
        same = out.setdefault(ep.name, [])
        if all(e.value != ep.value for e in same):
            same.append(ep)
    return out


def entry_points() -> dict[str, metadata.EntryPoint]:
    """The first entry point registered under each name (:func:`registered`); a name two
    packages register is refused where it is used (:func:`clash_problem`)."""
    return {name: eps[0] for name, eps in registered().items()}


def clash_problem(name: str) -> str | None:
    """When two installed packages register planner ``name`` as different things: one
    line naming both (which one an entry-point lookup finds depends on the install order,
    so neither is taken); None otherwise."""
    eps = registered().get(name, [])
    if len(eps) < 2:
        return None
    shown = ", ".join(f"{e.value} (package {_package(e)})" for e in eps)
    return (f"planner {name!r}: two installed packages register it in {GROUP} ({shown}); "
            "name the one meant as module:Name, or uninstall the other")


def _package(ep: metadata.EntryPoint) -> str:
    dist = getattr(ep, "dist", None)
    return f"{dist.name} {dist.version}" if dist is not None else "unknown"


def load_factory(name: str, entry: metadata.EntryPoint | None = None) -> Callable[..., Any]:
    """The class or factory of plug-in ``name``: ``entry`` loaded, else ``module:Name``
    imported, with the global generators seeded (a module that draws from them at import
    draws the same numbers in the driver and in every worker)."""
    from sgtool.planning.timing import seeded_globals

    if entry is not None:
        where = f"entry point {entry.value!r} of {GROUP}"
        try:
            with seeded_globals():  # a module drawing at import: the same in any process
                obj = entry.load()
        except (Exception, SystemExit) as e:  # noqa: BLE001 - user code failing: one line
            raise PluginError(f"planner {name!r}: cannot load {where} ({raised_text(e)})"
                              ) from None
    else:
        module, attr = check_spec(name)
        try:
            with seeded_globals():  # (as above)
                obj = importlib.import_module(module)
        except (Exception, SystemExit) as e:  # noqa: BLE001
            missing = isinstance(e, ModuleNotFoundError) and e.name is not None and (
                module == e.name or module.startswith(e.name + "."))
            hint = ("is its folder on PYTHONPATH?" if missing else
                    "the module was found and failed while importing: fix it, or install "
                    "what it imports")
            raise PluginError(f"planner {name!r}: cannot import module {module!r} "
                              f"({raised_text(e)}); {hint}") from None
        for part in attr.split("."):
            if not hasattr(obj, part):
                raise PluginError(f"planner {name!r}: {module!r} has no {attr!r}")
            obj = getattr(obj, part)
    if not callable(obj):
        raise PluginError(f"planner {name!r}: {type(obj).__name__} object is not a class "
                          "or factory")
    return obj


def options_class(factory: Callable[..., Any]) -> type | None:
    """The factory's ``Options`` dataclass, or None."""
    cls = getattr(factory, "Options", None)
    return cls if isinstance(cls, type) and dataclasses.is_dataclass(cls) else None


def signature_metas(factory: Callable[..., Any], declared: bool = False
                    ) -> dict[str, OptionMeta]:
    """The options a factory without ``Options`` types by its parameters' annotations (a
    class: its ``__init__``'s): those whose annotation gives a kind the command line sets
    (:func:`~sgtool.planning.option_fields.plain_meta`: not a Python object); none when
    the annotations do not resolve."""
    import inspect

    try:
        params = inspect.signature(factory).parameters.values()
    except (TypeError, ValueError):
        return {}
    code = getattr(factory, "__init__", None) if isinstance(factory, type) else factory
    namespace = dict(getattr(inspect.unwrap(code), "__globals__", {})) if code else {}
    out = {}
    for p in params:
        if p.kind in (p.VAR_POSITIONAL, p.VAR_KEYWORD) or p.annotation is p.empty:
            continue
        hint = resolved(p.annotation, namespace)  # each on its own
        if isinstance(hint, str) or (declared and hint is Any):  # untyped; Any: any value
            continue
        meta = plain_meta(None if p.default is p.empty else p.default, hint)
        if meta.cli:
            out[p.name] = meta
    return out


def plugin_options(name: str, factory: Callable[..., Any], given: Mapping[str, Any],
                   from_cli: bool = False) -> dict[str, Any]:
    """``given`` checked against the factory's ``Options`` when it has one, else against its
    parameters (module doc)."""
    cls = options_class(factory)
    if cls is None:
        known = parameter_names(factory)
        if known is not None and (unknown := set(given) - set(known)):
            raise unknown_keys_error(name, unknown, known)
        metas = signature_metas(factory, declared=True) \
            if any(isinstance(v, str) for v in given.values()) else {}
        return {k: convert_value(name, k, metas[k], v, from_cli=True)  # text as -O gives it
                if isinstance(v, str) and k in metas else v for k, v in given.items()}
    return convert_options(name, cls, given, from_cli=from_cli)


def parameter_names(factory: Callable[..., Any]) -> list[str] | None:
    """The keyword parameters of a factory without ``Options`` (a class: its
    ``__init__``'s); None when it takes ``**kwargs`` or Python cannot tell."""
    import inspect

    try:
        params = list(inspect.signature(factory).parameters.values())
    except (TypeError, ValueError):
        return None
    if any(p.kind is p.VAR_KEYWORD for p in params):
        return None
    return [p.name for p in params if p.kind in (p.POSITIONAL_OR_KEYWORD, p.KEYWORD_ONLY)]


def build_plugin(name: str, factory: Callable[..., Any], options: Mapping[str, Any]) -> Planner:
    """``factory(**options)``, checked to be a Planner; every failure one line."""
    from sgtool.planning.timing import seeded_globals

    kw = plugin_options(name, factory, options)
    if (cls := options_class(factory)) is not None:
        check_required(name, cls, kw)
    try:
        with seeded_globals():  # a constructor drawing from random: the same in any run
            planner = factory(**kw)
    except (Exception, SystemExit) as e:  # noqa: BLE001 - a user's planner failing: one line
        raise PluginError(f"planner {name!r}: {raised_text(e)}" if isinstance(e, SystemExit)
                          else f"planner {name!r}: raised {raised_text(e)}") from None
    missing = missing_parts(planner)
    if missing:
        raise PluginError(f"planner {name!r}: returned {returned_text(planner)}, not a "
                          f"Planner (it lacks {', '.join(missing)})")
    return planner


def held_to_contract(planner: Planner) -> Planner:
    """A user's planner object held to the contract a plug-in is (what it lacks, raises or
    returns wrongly is one line: :class:`~sgtool.planning.timing.TimedPlanner`, its
    decision time not measured); sgtool's own planners as they are (their exceptions are
    bugs, with their tracebacks)."""
    from sgtool.planning.timing import PlannerContractError, TimedPlanner

    if isinstance(planner, TimedPlanner) or type(planner).__module__.startswith("sgtool."):
        return planner
    if missing := missing_parts(planner, PLANNER_PARTS[1:]):
        raise PlannerContractError(f"planner: a {type(planner).__name__} is not a Planner "
                                   f"(it lacks {', '.join(missing)})")
    return TimedPlanner(planner, plugin=True, measure=False)


def missing_parts(planner: object, parts: tuple[str, ...] = PLANNER_PARTS) -> list[str]:
    """The members of the Planner protocol (``parts`` of :data:`PLANNER_PARTS`) that
    ``planner`` lacks: an attribute for ``name``, a method for the others."""
    return [p for p in parts if not hasattr(planner, p)
            or (p != "name" and not callable(getattr(planner, p)))]


def file_name(name: str) -> str:
    """The planner's folder or file-name component in log paths: the name, a ':' written
    ``__`` (``mymod:MyPlanner`` -> ``mymod__MyPlanner``), the same for every run."""
    return name.replace(":", "__")
