"""Version migration of house-spec documents: a version-1 document becomes the equivalent
version-2 document before validation.

Version 2 (:data:`sgtool.house.spec.SPEC_VERSION`) only adds optional fields: a small
object's parent may be another small object, furniture may have shelf ``levels``, small
objects may have ``affordances`` and a ``state``. A version-1 document is therefore a
version-2 document without them; :func:`upgrade` checks that it does not use them (a
file that says "1.0" but nests objects is refused, naming the field, so a version
mistake does not pass unnoticed) and relabels it. Nothing else changes, so the spec a
version-1 file loads as writes the same text but for ``"version": "2.0"``.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from sgtool.errors import SpecError
from sgtool.house.spec import SPEC_VERSION

KNOWN_VERSIONS = ("1.0", SPEC_VERSION)  # every version a house spec was ever written with
_V2_FURNITURE_FIELDS = ("levels",)
_V2_OBJECT_FIELDS = ("affordances", "state")


def upgrade(d: object) -> Mapping[str, Any]:
    """The document ``d`` as a document of the current version (``d`` itself when it is
    one); raises :class:`SpecError` for a version that is not exactly one of
    :data:`KNOWN_VERSIONS` (``"2"``, ``"2.7"``, ``"2.banana"``, ``2.0``) or a version-1
    document that uses version-2 fields."""
    if not isinstance(d, Mapping):
        raise SpecError("top level: expected a JSON object")
    version = d.get("version")
    if version is None:
        raise SpecError("version: missing")
    if not isinstance(version, str) and f"{version}" in KNOWN_VERSIONS:
        raise SpecError(f"version: {version!r} is a number; give it as text: "
                        f"\"{version}\"")
    if not isinstance(version, str) or version not in KNOWN_VERSIONS:
        shown = repr(version) if len(repr(version)) <= 40 else repr(version)[:37] + "..."
        raise SpecError(f"version: {shown} is not supported (this sgtool reads "
                        f"'MAJOR.MINOR' versions {' and '.join(KNOWN_VERSIONS)})")
    major = version.split(".")[0]
    if major == SPEC_VERSION.split(".")[0]:
        return d
    _check_v1(d)
    return {**d, "version": SPEC_VERSION}


def _check_v1(d: Mapping[str, Any]) -> None:
    """Refuse version-2 fields in a version-1 document (malformed entries and unknown
    parents are left to the validation proper, which names them)."""
    furniture = d.get("furniture")
    furn_ids = set()
    if isinstance(furniture, list):
        for i, f in enumerate(furniture):
            if isinstance(f, Mapping):
                furn_ids.add(f.get("id"))
                _no_v2_field(f"furniture[{i}]", f, _V2_FURNITURE_FIELDS)
    objects = d.get("objects")
    if isinstance(objects, list):
        obj_ids = {o.get("id") for o in objects if isinstance(o, Mapping)}
        for i, o in enumerate(objects):
            if isinstance(o, Mapping):
                _no_v2_field(f"objects[{i}]", o, _V2_OBJECT_FIELDS)
                parent = o.get("parent")
                if isinstance(parent, str) and parent in obj_ids and parent not in furn_ids:
                    raise SpecError(f"objects[{i}].parent: {parent[:40]!r} is a small object "
                                    "(a version-1 parent is furniture; nesting needs "
                                    f"version {SPEC_VERSION})")


def _no_v2_field(where: str, x: Mapping[str, Any], fields: tuple[str, ...]) -> None:
    for k in fields:
        if k in x:
            raise SpecError(f"{where}.{k}: a version-{SPEC_VERSION} field in a version-1 "
                            "house spec")
