"""Rules for the strings of a house spec: ids (of the house and of its entries) are used as
file-name components and table cells, names (categories, synsets, open-plan groups) are
printed in tables and prompts; and the number an id ends with (``obj_12``).

Pure functions; the parser (:mod:`sgtool.house.parse`) turns a problem into a
:class:`sgtool.errors.SpecError` naming the field.
"""

from __future__ import annotations

import unicodedata

MAX_ID_LENGTH = 100  # characters of an id: a file-name component with room to spare
_ID_FORBIDDEN = ("/", "\\", "|")  # path separators, the markdown cell separator
_CONTROL_CATEGORIES = ("Cc", "Cs", "Zl", "Zp")  # control, lone surrogate, line/paragraph break
_MAX_DECIMAL_DIGITS = 4000  # int() refuses longer decimal strings (sys.int_info)


def control_character(text: str) -> str | None:
    """The first control character of ``text`` (newline, tab, NUL, DEL, a lone surrogate,
    a line or paragraph separator) shown as ``U+000A``, or None."""
    for c in text:
        if unicodedata.category(c) in _CONTROL_CATEGORIES:
            return f"U+{ord(c):04X}"
    return None


def name_problem(text: str) -> str | None:
    """Why ``text`` cannot be a name (a category, a synset), or None: it holds a control
    character."""
    bad = control_character(text)
    return f"contains the control character {bad}" if bad else None


def folder_id_problem(text: str) -> str | None:
    """Why ``text`` cannot be the id of a house, which names a folder of logs, or None:
    :func:`id_problem`'s rules, and no leading ``.`` (a hidden folder, which listings and
    ``sgtool eval`` pass over)."""
    bad = id_problem(text)
    if bad is None and text.startswith("."):
        bad = "starts with '.' (a house id names a folder of logs, and a hidden one is " \
            "passed over)"
    return bad


def id_problem(text: str) -> str | None:
    """Why ``text`` cannot be an id, or None. An id must be usable as one file-name
    component and one table cell: not empty, at most :data:`MAX_ID_LENGTH` characters,
    not ``.`` or ``..``, without ``/``, ``\\``, ``|`` or control characters."""
    if not text:
        return "is empty"
    if len(text) > MAX_ID_LENGTH:
        return f"{len(text)} characters, more than the limit of {MAX_ID_LENGTH} for an id"
    if text in (".", ".."):
        return "is not allowed as an id"
    for c in _ID_FORBIDDEN:
        if c in text:
            return f"contains {c!r} (an id may not hold '/', '\\', '|')"
    bad = control_character(text)
    return f"contains the control character {bad}" if bad else None


def decimal_int(text: str) -> int | None:
    """``text`` as a non-negative integer when it is made of decimal digits only (those
    ``int()`` accepts: ``str.isdecimal``, so ``'12'`` and ``'١٢'`` but not ``'²'``, ``'+1'``
    or ``' 1'``), else None. The one rule for the running number of an id (``obj_12``,
    ``obj:12``)."""
    if text.isdecimal() and len(text) <= _MAX_DECIMAL_DIGITS:
        return int(text)
    return None


def id_note(key: str, index: int, entry_id: object) -> str:
    """What a message about entry ``index`` of the list ``key`` ends with so that the entry
    can be found by its id, not only by its index: `` (furniture[84] is 'cabinet_3')``;
    empty when ``entry_id`` is not a valid id (the message is then about the id)."""
    if not isinstance(entry_id, str) or id_problem(entry_id) is not None:
        return ""
    return f" ({key}[{index}] is {entry_id!r})"
