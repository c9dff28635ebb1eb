"""Atomic file output: a file appears at its final path complete, or not at all.

Every file sgtool writes outside a log (results, summaries, house specs, weights, figures,
golden expectations) goes through :func:`atomic_write` or :func:`atomic_output`: the bytes
go to a temporary file with a unique name in the same folder, are flushed and fsync'ed, get
the mode a plain ``open`` would give (umask applied), and are renamed over the final path.
An error, Ctrl-C or a concurrent writer never leaves a half-written file at the final path;
the temporary file is removed on any exception. Two processes writing the same path each
use their own temporary file; a path that must be new (no ``--force``) is taken by the
first to finish (:mod:`sgtool.publish`; the other's finished file is kept in sight beside
it), elsewhere the last rename wins.

:func:`temp_beside` makes such a unique temporary file for writers that manage it
themselves (the log writer); :class:`OutputError` is the one-line user error for a
destination that cannot be written (read-only, missing, full), made by
:func:`output_error` from the :class:`OSError`.

Folders of outputs (a benchmark's results, a batch of derived logs) go through
:func:`output_folder`: built beside the target and moved in complete, a non-empty target
refused without ``force``, and ``force`` replacing only what sgtool wrote there (the
folder's :data:`MANIFEST` lists it); files a user put in the folder survive.
"""

from __future__ import annotations

import contextlib
import errno
import fnmatch
import hashlib
import json
import os
import shlex
import shutil
import tempfile
from collections.abc import Iterable, Iterator, Sequence
from pathlib import Path
from typing import IO

from sgtool.errors import SgtoolError, deferred_interrupts
from sgtool.publish import keep_in_sight, publish

# OSError numbers that a user's environment causes (a destination that is read-only,
# missing, full, not writable): reported as one line, never as a traceback
ENVIRONMENT_ERRNOS = frozenset({
    errno.EACCES, errno.EPERM, errno.EROFS, errno.ENOSPC, errno.EDQUOT, errno.ENOENT,
    errno.ENOTDIR, errno.EISDIR, errno.EEXIST, errno.EFBIG, errno.ENAMETOOLONG, errno.EIO,
    errno.ENXIO, errno.ETXTBSY, errno.EMFILE, errno.ENFILE, errno.ELOOP, errno.EXDEV,
    errno.ENOTEMPTY, errno.EBUSY,
})


# errors of a write that say the destination is full or failing, whatever file they name
FULL_ERRNOS = frozenset({errno.ENOSPC, errno.EDQUOT, errno.EFBIG, errno.EIO})


class OutputError(SgtoolError):
    """An output could not be written (read-only folder, missing folder, full disk)."""


def quoted(path: str | os.PathLike[str]) -> str:
    """``path`` as a shell word, for a command a message suggests (``rerun 'my run.rrd'``):
    a path of plain characters as it is, any other quoted so that it pastes whole."""
    return shlex.quote(str(path))


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


def is_environment_error(e: BaseException) -> bool:
    """True for an :class:`OSError` a user's environment causes (see ``ENVIRONMENT_ERRNOS``)."""
    return isinstance(e, OSError) and e.errno in ENVIRONMENT_ERRNOS


def concerns(e: OSError, *paths: str | os.PathLike[str]) -> bool:
    """Is ``e`` a failure to write one of ``paths``: it names one of them, or names no file
    and says that the destination is full or failing (a buffered write)?"""
    if e.filename is not None:
        return str(e.filename) in {str(p) for p in paths}
    return e.errno in FULL_ERRNOS


def output_error(e: OSError, path: str | os.PathLike[str] | None = None,
                 note: str = "nothing was written") -> OutputError:
    """The one-line :class:`OutputError` for ``e`` while writing ``path`` (or the file the
    error names): ``cannot write PATH: No space left on device (nothing was written)``."""
    where = path if path is not None else (e.filename or "the output")
    reason = e.strerror or type(e).__name__
    if isinstance(e, (FileExistsError, NotADirectoryError)) and path is not None:
        file = next((p for p in Path(path).parents if p.is_file()), None)
        if file is not None:  # a folder on the way is a file
            reason = f"{file} is a file, not a folder"
    return OutputError(f"cannot write {where}: {reason}" + (f" ({note})" if note else ""))


NAME_MAX = 255  # bytes of one name in a folder (ext4, xfs, btrfs, tmpfs, APFS, NTFS: 255)
TEMP_RANDOM = 8  # the characters tempfile.mkstemp and mkdtemp put between prefix and suffix
NAME_TAG = 8  # hex digits of the whole name's hash that a cut temporary name ends in


def appeared_error(path: str | os.PathLike[str], kept: str | os.PathLike[str] | None = None
                   ) -> OutputError:
    """The one line for an output that another run wrote while this one ran."""
    tail = f"; this run's output is kept in {kept}" if kept else " (nothing was written)"
    return OutputError(f"{path} appeared while this run wrote it (another run?); not "
                       f"overwriting it (use --force){tail}")


def temp_prefix(name: str, suffix: str, hidden: bool = True) -> str:
    """The prefix of a temporary name beside ``name``: ``.NAME.`` (``NAME.`` when not
    ``hidden``). When the whole temporary name (the prefix, tempfile's 8 random
    characters, ``suffix``) would pass :data:`NAME_MAX` bytes, ``NAME`` is cut before a
    character and followed by ``~`` and 8 hex digits of a hash of the whole name, so that
    two long names that begin alike keep apart."""
    lead = "." if hidden else ""
    room = NAME_MAX - len(lead) - 1 - TEMP_RANDOM - len(os.fsencode(suffix))
    raw = os.fsencode(name)
    if len(raw) > room:
        end = max(room - 1 - NAME_TAG, 1)
        while end > 1 and raw[end] & 0xC0 == 0x80:  # not inside a UTF-8 character
            end -= 1
        tag = hashlib.blake2b(raw, digest_size=NAME_TAG // 2).hexdigest()
        name = f"{os.fsdecode(raw[:end])}~{tag}"
    return f"{lead}{name}."


def temp_beside(path: str | os.PathLike[str], suffix: str = ".partial",
                hidden: bool = True) -> tuple[int, Path]:
    """A new, uniquely named, empty file in the folder of ``path`` (``.NAME.XXXXXXXX`` +
    ``suffix``, or ``NAME.XXXXXXXX`` + ``suffix`` when not ``hidden``; a long ``NAME``
    cut: :func:`temp_prefix`) with the mode a plain ``open`` would give; returns its open
    descriptor and path. Two callers never get the same name."""
    path = Path(path)
    prefix = temp_prefix(path.name, suffix, hidden)
    fd, name = tempfile.mkstemp(prefix=prefix, suffix=suffix, dir=path.parent)
    try:
        os.fchmod(fd, 0o666 & ~_umask())  # mkstemp makes 0600; give the usual mode
    except BaseException:
        os.close(fd)
        os.unlink(name)
        raise
    return fd, Path(name)


@contextlib.contextmanager
def atomic_output(path: str | os.PathLike[str], suffix: str = ".partial") -> Iterator[Path]:
    """Yield a temporary path beside ``path``; on a clean exit it is renamed to ``path``.

    For writers that need a path (a library that opens the file itself); the temporary
    file exists (empty) when the block starts. The parent folder is created. A file that
    another run wrote at a ``path`` that must be new stays; this one is kept beside it.
    """
    path = Path(path)
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = temp_beside(path, suffix)
    except OSError as e:
        raise output_error(e, path) from None
    os.close(fd)
    try:
        yield tmp
        with open(tmp, "rb+") as fh:
            os.fsync(fh.fileno())
        os.chmod(tmp, 0o666 & ~_umask())  # a library may have made its own file anew
        publish(tmp, path)
    except OSError as e:
        if isinstance(e, FileExistsError) and str(e.filename) == str(path):
            # (publish: another run wrote it) this run's finished file is kept in sight
            raise appeared_error(path, kept=keep_in_sight(tmp)) from None
        tmp.unlink(missing_ok=True)
        if concerns(e, tmp, path):
            raise output_error(e, path) from None
        raise
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise


@contextlib.contextmanager
def atomic_open(path: str | os.PathLike[str], mode: str = "w") -> Iterator[IO]:
    """``open(path, mode)`` ("w", "wb", "wt") that becomes ``path`` only on a clean exit."""
    if mode not in ("w", "wt", "wb"):
        raise ValueError(f"atomic_open writes a new file; mode {mode!r}")
    with atomic_output(path) as tmp:
        encoding = None if "b" in mode else "utf-8"
        with open(tmp, mode, encoding=encoding) as fh:
            yield fh
            fh.flush()


def atomic_write(path: str | os.PathLike[str], data: str | bytes) -> Path:
    """Write ``data`` (text is UTF-8) to ``path`` atomically; return the path."""
    with atomic_open(path, "wb") as fh:
        fh.write(data.encode("utf-8") if isinstance(data, str) else data)
    return Path(path)


# ----------------------------------------------------------------------------------------
# output folders
# ----------------------------------------------------------------------------------------
# the file in an output folder that lists what sgtool wrote there: JSON
# {"command": NAME, "files": [top-level names, sorted]}
MANIFEST = ".sgtool-output"


def _plain_name(name: object) -> bool:
    """One entry of a folder (no separator, not ``.``/``..``, not the manifest)."""
    return (isinstance(name, str) and name not in ("", ".", "..", MANIFEST)
            and "/" not in name and os.sep not in name and "\0" not in name)


def read_manifest(folder: str | os.PathLike[str]) -> tuple[str | None, frozenset[str]]:
    """The command and the entry names the :data:`MANIFEST` of ``folder`` lists;
    ``(None, frozenset())`` when there is none or it cannot be read. Only plain names
    (one entry of the folder) are returned, whatever the file holds."""
    try:
        doc = json.loads(Path(folder, MANIFEST).read_text(encoding="utf-8"))
    except (OSError, ValueError, RecursionError):
        return None, frozenset()
    if not isinstance(doc, dict):
        return None, frozenset()
    command = doc.get("command")
    files = doc.get("files")
    names = frozenset(n for n in files if _plain_name(n)) if isinstance(files, list) \
        else frozenset()
    return (command if isinstance(command, str) else None), names


def manifest_text(command: str, names: Sequence[str]) -> str:
    """The :data:`MANIFEST` of a folder ``command`` wrote ``names`` into."""
    files = sorted({n for n in names if _plain_name(n)})
    return json.dumps({"command": command, "files": files}, indent=1, sort_keys=True) + "\n"


def note_written(folder: str | os.PathLike[str], command: str, names: Iterable[str]) -> None:
    """List ``names`` (entries ``command`` just wrote into ``folder``) in its
    :data:`MANIFEST`, as a command's own output folder lists them, so that the command
    later replaces them (``--force``) as its own; a folder of another command keeps its
    manifest as it is."""
    owner, listed = read_manifest(folder)
    if owner not in (None, command):
        return
    atomic_write(Path(folder) / MANIFEST, manifest_text(command, sorted(listed | set(names))))


def _matches(name: str, known: Sequence[str]) -> bool:
    return any(fnmatch.fnmatchcase(name, pattern) for pattern in known)


def sgtool_entries(folder: Path, known: Sequence[str] = ()) -> set[str]:
    """The entries of ``folder`` sgtool wrote: those its :data:`MANIFEST` lists, those
    matching a pattern of ``known`` (a command's fixed output names), and the manifest."""
    try:
        present = set(os.listdir(folder))
    except FileNotFoundError:
        return set()
    _, listed = read_manifest(folder)
    ours = {n for n in present if n in listed or _matches(n, known)}
    if MANIFEST in present:
        ours.add(MANIFEST)
    return ours


def _refuse_unlisted(folder: Path, target: str | os.PathLike[str], option: str,
                     known: Sequence[str]) -> None:
    """``--force`` into ``folder`` that has no :data:`MANIFEST` but entries named as the
    command's outputs: sgtool did not write them (or an sgtool before manifests did), and
    a user's files there would be replaced; one line naming them."""
    owner, _ = read_manifest(folder)
    if owner is not None:
        return
    clash = sorted(n for n in os.listdir(folder) if _matches(n, known))
    if clash:
        shown = ", ".join(clash[:4]) + (f" and {len(clash) - 4} more" if len(clash) > 4 else "")
        raise SgtoolError(f"{option} {target}: holds {shown}, named as this command's "
                          f"outputs but not listed as sgtool's ({MANIFEST} is missing); not "
                          "replacing them: move them away, or give another folder")


def _is_own(folder: Path, command: str, known: Sequence[str]) -> bool:
    """A folder ``command`` wrote (its manifest says so; without one, every entry matches
    ``known``), or an empty one."""
    present = os.listdir(folder)
    owner, _ = read_manifest(folder)
    if owner is not None:
        return owner == command
    return all(_matches(n, known) for n in present)


def output_dir(path: str | os.PathLike[str]) -> Path:
    """The folder ``path``, made (with its parents) when missing; a file there, or on the
    way, or a folder that cannot be made is one :class:`OutputError` line (an empty
    ``path`` too: it is no name for the working folder)."""
    if not os.fspath(path):
        raise OutputError("an empty path: give a folder")
    out = Path(path)
    if out.exists() and not out.is_dir():
        raise OutputError(f"cannot write into {path}: it is a file, not a folder")
    try:
        out.mkdir(parents=True, exist_ok=True)
    except OSError as e:
        raise output_error(e, out) from None
    return out


def _folder_target(target: str | os.PathLike[str], option: str) -> Path:
    if not os.fspath(target):  # ("" would be the working folder)
        raise SgtoolError(f"{option} '': an empty path; give a folder")
    path = Path(os.path.abspath(target))  # "." has a name and a parent to build beside
    if path.is_symlink() and path.is_dir():  # a link to a folder: the folder is the target
        path = Path(os.path.realpath(path))
    if path.exists() and not path.is_dir():
        raise SgtoolError(f"{option} {target}: is a file, not a folder")
    return path


def refuse_input_folder(target: str | os.PathLike[str],
                        inputs: Iterable[str | os.PathLike[str]], *, option: str = "-o",
                        what: str = "input") -> None:
    """One :class:`~sgtool.errors.SgtoolError` line when an input folder (whose files are
    all read as inputs) is the output folder ``target``: with ``--force`` the run would
    write its outputs among them, and the next run would read those as inputs. A single
    input file in the output folder is no problem (``--force`` keeps a user's files)."""
    folder = Path(target).resolve()
    for p in inputs:
        if Path(p).is_dir() and Path(p).resolve() == folder:
            raise SgtoolError(f"{option} {target} is the {what} folder {p}, whose files are "
                              "read as inputs; write the outputs to another folder")


@contextlib.contextmanager
def output_folder(target: str | os.PathLike[str], *, force: bool, command: str = "sgtool",
                  option: str = "-o", known: Sequence[str] = (),
                  resume: bool = False, inner: Sequence[str] = ()) -> Iterator[Path]:
    """Yield the folder to write a command's outputs into; ``target`` gets them complete.

    Build (the default): the yielded folder is new and empty, a uniquely named hidden
    folder beside ``target`` (``.NAME.XXXXXXXX.partial``, same parent, so the same file
    system); on a clean exit it becomes ``target``:

    - a missing or empty ``target`` is replaced by it in one rename;
    - a non-empty ``target`` is refused in one line (:class:`~sgtool.errors.SgtoolError`
      naming ``option`` and ``--force``) before the block runs, unless ``force``; with
      ``force`` (of the command that wrote it: another command's folder is refused, its
      results are not this command's to delete) the entries sgtool wrote there before
      (:func:`sgtool_entries`: the :data:`MANIFEST`'s list, names matching ``known``)
      and the entries of the same name
      as a new output are moved aside, the new entries moved in, and the moved-aside ones
      deleted; any other entry (a user's file) stays. A folder without a manifest that
      holds entries named as outputs is refused (:func:`_refuse_unlisted`: they may be a
      user's). A failure or Ctrl-C while moving puts every entry back where it was;
    - a ``target`` missing or empty at the start that another run filled meanwhile is
      left alone: the outputs become ``NAME.1`` (the first free suffix) and a one-line
      :class:`~sgtool.errors.SgtoolError` says so; entries named in ``inner`` are this
      run's (``--log-dir OUT/logs``, another ``output_folder``'s), left as they are.

    The new :data:`MANIFEST` lists the top-level entries of the yielded folder, for the
    next ``--force``. On any exception (Ctrl-C included) the yielded folder is removed and
    ``target`` is as it was; a :class:`KeyboardInterrupt` gets a ``note`` saying so (what
    the CLI prints). A Ctrl-C while the outputs go in takes effect once they are in (its
    note says the target holds them). The yielded folder's entries are moved, not copied:
    paths into it are stale once the block ends (name outputs as ``target / name``). Only
    SIGKILL can leave the hidden folder behind. A parent that cannot be written is one
    :class:`OutputError` line.

    Resume (``resume=True``, for a command that keeps writing into a folder of its own,
    such as ``run-bench``'s episode logs): when ``target`` is missing, empty, or a folder
    of the same ``command`` (its :data:`MANIFEST` says so; without one, every entry
    matches ``known``), the yielded folder is ``target`` itself, created when missing, and
    the command must write every file atomically (:func:`atomic_write`, a log writer's
    partial file): an interruption then leaves complete files only, which the next run
    takes up. On exit, clean or not, the manifest lists what it listed plus the entries
    that appeared; an exception before any entry appeared leaves ``target`` as it was
    (a folder created for the run is removed again). With ``force`` it builds as above: a
    fresh run that replaces what sgtool wrote; another command's folder is refused, with
    or without ``force``.
    """
    path = _folder_target(target, option)
    exists = path.is_dir()
    busy = exists and any(os.scandir(path))
    if resume and not force and (not busy or _is_own(path, command, known)):
        with _in_place(path, command, known) as out:
            yield out
        return
    owner = read_manifest(path)[0] if busy else None
    owner, me = (None if c is None else c.removeprefix("sgtool ")  # ("sgtool golden")
                 for c in (owner, command))
    if busy and not force:
        raise SgtoolError(f"{option} {target}: the folder is not empty"
                          + (f" (a `sgtool {owner}` folder)" if owner else "")
                          + "; not writing into it (--force, force=True from Python, "
                          "replaces what sgtool wrote there and keeps other files)")
    if busy and owner is not None and owner != me:
        raise SgtoolError(f"{option} {target}: a `sgtool {owner}` folder; --force of "
                          f"`sgtool {me}` would delete its results: give another folder, "
                          "or remove that one first")
    if busy:
        _refuse_unlisted(path, target, option, known)
    parent = path.parent
    made: list[Path] = []
    try:
        made = _make_folders(parent)
        stage = Path(tempfile.mkdtemp(prefix=temp_prefix(path.name, ".partial"),
                                      suffix=".partial", dir=parent))
        os.chmod(stage, 0o777 & ~_umask())  # mkdtemp makes 0700; give the usual mode
    except OSError as e:
        _remove_empty(made)
        raise output_error(e, target) from None
    committed = False
    try:
        yield stage
        atomic_write(stage / MANIFEST, manifest_text(command, os.listdir(stage)))
        if not busy and path.is_dir() and any(e.name not in inner for e in os.scandir(path)):
            kept = _free_sibling(path)  # filled meanwhile (another run): not mixed, not lost
            os.replace(stage, kept)
            raise SgtoolError(f"{option} {target}: another run wrote into it while this one "
                              f"ran; this run's outputs are in {kept} instead")
        try:
            with deferred_interrupts():  # a Ctrl-C in the moves: once they are done
                _commit(stage, path, sgtool_entries(path, known) if path.is_dir() else set())
                committed = True
        except OSError as e:
            if is_environment_error(e):
                raise output_error(e, target, note=f"{target} is as it was") from None
            raise
    except BaseException as e:
        if isinstance(e, KeyboardInterrupt):  # what the CLI prints
            e.note = (f"{target} holds this run's complete outputs (they went in as it was "  # type: ignore[attr-defined]
                      "interrupted)" if committed else
                      f"{target} is as it was: the outputs of the interrupted run "
                      "were discarded")
        shutil.rmtree(stage, ignore_errors=True)  # (emptied by the moves when committed)
        if committed:
            raise
        _remove_empty(made)  # the folders made for the target, when still empty
        _name_target(e, stage, path)
        raise
    shutil.rmtree(stage, ignore_errors=True)  # emptied by the moves, or moved in whole


def _free_sibling(path: Path) -> Path:
    """``path`` with the first suffix ``.1``, ``.2``, ... that names nothing yet."""
    n = 1
    while path.with_name(f"{path.name}.{n}").exists():
        n += 1
    return path.with_name(f"{path.name}.{n}")


def _name_target(e: BaseException, stage: Path, target: Path) -> None:
    """A failure to write into the hidden ``stage`` names the file in ``target`` instead
    (the stage is gone, and the user never gave its name); a full disk met by a buffered
    write, which names no file, names ``target``."""
    if isinstance(e, SgtoolError) and len(e.args) == 1 and str(stage) in str(e.args[0]):
        e.args = (str(e.args[0]).replace(str(stage), str(target)),)
    elif isinstance(e, OSError) and e.filename is not None and str(stage) in str(e.filename):
        e.filename = str(e.filename).replace(str(stage), str(target))
    elif isinstance(e, OSError) and e.filename is None and e.errno in FULL_ERRNOS:
        e.filename = str(target)  # a buffered write: the disk the outputs went to


def _make_folders(folder: Path) -> list[Path]:
    """``folder.mkdir(parents=True, exist_ok=True)``; the folders it made, outermost
    first."""
    missing = [p for p in (folder, *folder.parents) if not p.exists()][::-1]
    folder.mkdir(parents=True, exist_ok=True)
    return missing


def _remove_empty(folders: list[Path]) -> None:
    """Remove ``folders`` (made by :func:`_make_folders`) again, innermost first, as long
    as they are empty."""
    for p in reversed(folders):
        try:
            p.rmdir()
        except OSError:
            return


def remove_empty_folders(root: str | os.PathLike[str]) -> None:
    """Remove every folder under ``root`` (``root`` included) that holds no file, innermost
    first: what a run that failed before writing leaves of its folder tree. A folder that
    cannot be removed (it filled meanwhile, no permission) stays."""
    top = Path(root)
    if not top.is_dir():
        return
    for folder, _, _ in sorted(os.walk(top), key=lambda entry: -len(Path(entry[0]).parts)):
        with contextlib.suppress(OSError):
            os.rmdir(folder)


def _commit(stage: Path, target: Path, old: set[str]) -> None:
    """Move the entries of ``stage`` into ``target`` (module doc of :func:`output_folder`);
    ``old`` are the entries of ``target`` that sgtool wrote."""
    if not target.exists() or not any(os.scandir(target)):
        os.replace(stage, target)  # one rename; an empty folder is replaced by it
        return
    new = sorted(os.listdir(stage))
    away = sorted((old | set(new)) & set(os.listdir(target)))
    backup = Path(tempfile.mkdtemp(prefix=".sgtool-previous.", dir=target))
    moved: list[str] = []
    placed: list[str] = []
    try:
        for name in away:
            os.replace(target / name, backup / name)
            moved.append(name)
        for name in new:
            os.replace(stage / name, target / name)
            placed.append(name)
    except BaseException:
        for name in reversed(placed):
            os.replace(target / name, stage / name)
        for name in reversed(moved):
            os.replace(backup / name, target / name)
        shutil.rmtree(backup, ignore_errors=True)
        raise
    shutil.rmtree(backup, ignore_errors=True)


@contextlib.contextmanager
def _in_place(target: Path, command: str, known: Sequence[str]) -> Iterator[Path]:
    """:func:`output_folder`'s resume: ``target`` itself, its manifest kept up to date."""
    made: list[Path] = []
    try:
        made = _make_folders(target)
        before = set(os.listdir(target))
    except OSError as e:
        _remove_empty(made)
        raise output_error(e, target) from None
    ours = sgtool_entries(target, known) - {MANIFEST}
    marked = MANIFEST not in before
    if marked:  # mark the folder as this command's first
        atomic_write(target / MANIFEST, manifest_text(command, sorted(ours)))

    def mark() -> None:
        now = set(os.listdir(target))
        atomic_write(target / MANIFEST, manifest_text(command, sorted((ours | (now - before))
                                                                      & now)))
    try:
        yield target
    except BaseException:
        with contextlib.suppress(OSError, SgtoolError):  # the first error is the one to tell
            if marked and set(os.listdir(target)) - before <= {MANIFEST}:
                (target / MANIFEST).unlink()  # nothing written: the folder as it was
                _remove_empty(made)
            else:
                mark()
        raise
    mark()


def sha256_file(path: str | os.PathLike[str]) -> str:
    """The sha256 of a file's bytes, hex."""
    h = hashlib.sha256()
    with open(path, "rb") as f:
        for block in iter(lambda: f.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


def path_text(path: str | os.PathLike[str]) -> str:
    """A path as results record it, one spelling however it was typed: normalised
    (``./hs/`` is ``hs``), and relative to the working folder when it lies inside it
    (``$PWD/hs`` is ``hs``); symbolic links are left as given, an empty path empty."""
    text = os.fspath(path)
    if not text:
        return text
    text = os.path.normpath(text)
    if os.path.isabs(text):
        rel = os.path.relpath(text)
        if rel != ".." and not rel.startswith(".." + os.sep):
            return rel
    return text
