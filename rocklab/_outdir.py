"""Output folders and files that never destroy what rocklab did not make.

Every folder rocklab writes (``run``, ``campaign``, ``synth``, ``demo``) carries
a marker file, :data:`MARKER`. Before any expensive work:

- an ``--out`` that is an existing *file* is refused;
- a non-empty folder without the marker (a user's folder) is refused unless
  ``force``; with ``force`` rocklab writes its outputs beside the user's files
  and deletes nothing of theirs;
- the parent must be writable and hold the estimated free space;
- rocklab's own stale staging folders (``.NAME.tmp-PID-*``, ``.NAME.old-PID-*``
  left by a killed run whose process is gone) are removed.

Outputs are staged in ``.NAME.tmp-PID-*`` next to the target and swapped into
place by renames (:func:`publish_dir`), so a kill at any moment leaves either the
previous output or the new one, never half of one.
"""

from __future__ import annotations

import errno
import json
import os
import re
import shutil
import tempfile
import time
from pathlib import Path

from ._errors import InputError

__all__ = [
    "MARKER",
    "check_output_dir",
    "check_output_file",
    "claim_dir",
    "stage_dir",
    "publish_dir",
    "clean_stale",
    "owned_entries",
    "foreign_entries",
    "pid_alive",
    "stale_prefix",
    "set_aside_user_file",
    "claim_side_file",
    "stamp_output",
    "rocklab_wrote",
]

#: Name of the marker file in every folder rocklab writes.
MARKER = ".rocklab-output"

#: Extended attribute that marks a single output file as rocklab's (the BLAKE2b digest of its content).
STAMP_XATTR = "user.rocklab.output"

_MB = 1024 * 1024


#: A stop asked for while it could not be raised (a SIGTERM during a compiled loop: the CLI's
#: handler leaves it here): raised before any output is published, so a stopped run never
#: publishes even when it finishes before the signal can be delivered again.
_PENDING_STOP: list = []


def defer_stop(exc: BaseException | None) -> None:
    """Raise ``exc`` at the next publication of an output (:func:`raise_pending_stop`); None
    forgets a deferred stop (it was raised another way)."""
    _PENDING_STOP[:] = [] if exc is None else [exc]


def raise_pending_stop() -> None:
    """Raise the stop left by :func:`defer_stop`, if any (before an output is renamed into place)."""
    if _PENDING_STOP:
        raise _PENDING_STOP.pop()


def pid_alive(pid: int) -> bool:
    """Whether process ``pid`` exists on this machine."""
    if pid <= 0:
        return False
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:  # exists, owned by someone else
        return True
    return True


def stale_prefix(name: str, kind: str = "tmp") -> str:
    """The staging-name prefix for ``name`` owned by this process: ``.NAME.KIND-PID-``."""
    return f".{name}.{kind}-{os.getpid()}-"


def clean_stale(parent, name: str) -> list[Path]:
    """Remove rocklab's staging leftovers of ``name`` in ``parent`` whose creating process is gone.

    Returns the removed paths.
    """
    parent = Path(parent)
    removed = []
    if not parent.is_dir():
        return removed
    pat = re.compile(r"^\." + re.escape(name) + r"\.(?:tmp|old)-(\d+)-")
    try:
        entries = list(parent.iterdir())
    except OSError:
        return removed
    for p in entries:
        m = pat.match(p.name)
        if not m or pid_alive(int(m.group(1))):
            continue
        try:
            if p.is_dir() and not p.is_symlink():
                shutil.rmtree(p)
            else:
                p.unlink()
            removed.append(p)
        except OSError:
            pass
    return removed


def owned_entries(path) -> set[str]:
    """Names of the entries in folder ``path`` that rocklab wrote (from its marker)."""
    try:
        d = json.loads((Path(path) / MARKER).read_text(encoding="utf-8"))
        return set(d.get("entries", []))
    except (OSError, ValueError, AttributeError):
        return set()


#: A staging file or folder of rocklab's atomic writes: ``.<name>.tmp-<pid>-...`` / ``.<name>.old-<pid>-...``.
_STAGING = re.compile(r"^\..+\.(?:tmp|old)-(\d+)-")


def foreign_entries(path) -> list[str]:
    """Entries of folder ``path`` that rocklab did not write (sorted names).

    A staging leftover of a rocklab writer that was killed (its process is gone) is rocklab's,
    not the user's: the next write of that output removes it (:func:`clean_stale`).
    """
    owned = owned_entries(path) | {MARKER}

    def ours(name: str) -> bool:
        m = _STAGING.match(name)
        return name in owned or (m is not None and not pid_alive(int(m.group(1))))

    return sorted(p.name for p in Path(path).iterdir() if not ours(p.name))


def _digest(path) -> bytes:
    import hashlib

    h = hashlib.blake2b(digest_size=16)
    with open(path, "rb") as f:
        for chunk in iter(lambda: f.read(1 << 20), b""):
            h.update(chunk)
    return h.hexdigest().encode()


def _stamp_entry(path) -> Path:
    """Where the stamp of ``path`` is kept when its file system holds no extended attributes: one
    small file per output under the user's cache folder (``$XDG_CACHE_HOME`` or ``~/.cache``),
    named by a digest of the output's real path, so nothing is written beside the user's files."""
    import hashlib

    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    key = hashlib.blake2b(os.fsencode(os.path.realpath(path)), digest_size=16).hexdigest()
    return Path(base) / "rocklab" / "output-stamps" / key


def stamp_output(path, registry: bool = True) -> bool:
    """Mark the file ``path`` as rocklab's output: its content digest in the extended attribute
    :data:`STAMP_XATTR`.

    A file rocklab writes beside the user's files (``-o`` into a folder of inputs, side files) is
    known as rocklab's by this stamp rather than by a marker file, so nothing but the outputs asked
    for is written into the user's folders. Where the file system keeps no extended attributes the
    digest goes to :func:`_stamp_entry` in the user's cache folder; where that cannot be written
    either, the file stays unmarked and later counts as the user's (kept, never overwritten).

    Parameters
    ----------
    registry : bool
        Whether to fall back on the cache folder (False for a temporary file about to be renamed:
        the entry is named by the path, which the extended attribute is not).

    Returns
    -------
    bool
        Whether the stamp was made.
    """
    digest = _digest(path)
    try:
        os.setxattr(path, STAMP_XATTR, digest)
        return True
    except (AttributeError, OSError):  # no extended attributes on this system or file system
        if not registry:
            return False
    entry = _stamp_entry(path)
    try:
        entry.parent.mkdir(parents=True, exist_ok=True)
        tmp = entry.with_name(f".{entry.name}.{os.getpid()}")
        tmp.write_bytes(digest)
        os.replace(tmp, entry)
    except OSError:
        return False
    return True


def rocklab_wrote(path) -> bool:
    """Whether the file ``path`` is an output rocklab wrote and nobody changed since (its stamp,
    :func:`stamp_output`, matches its content). A symlink is never rocklab's."""
    if os.path.islink(path):
        return False
    try:
        stamp = os.getxattr(path, STAMP_XATTR, follow_symlinks=False)
    except (AttributeError, OSError):
        try:
            stamp = _stamp_entry(path).read_bytes()
        except OSError:
            return False
    try:
        return stamp == _digest(path)
    except OSError:
        return False


def _check_parent(path: Path, option: str, need_bytes: int) -> None:
    parent = path.parent
    probe = parent
    while not probe.exists():  # the folder will be created: its first existing ancestor decides
        probe = probe.parent
    if not probe.is_dir():
        raise InputError(f"{option} {path}: {probe} is a file, not a folder; choose another path")
    try:  # probe the folder (or the ancestor it will be created in) without creating anything
        fd, tmp = tempfile.mkstemp(prefix=stale_prefix(path.name, "tmp") + "probe", dir=probe)
        os.close(fd)
        os.unlink(tmp)
    except PermissionError:
        raise InputError(f"{option} {path}: folder {probe} is not writable; choose a writable location") from None
    except OSError as e:
        if e.errno == errno.ENOSPC:
            raise InputError(
                f"{option} {path}: no space left on {probe}; free space or choose another location"
            ) from None
        raise InputError(f"{option} {path}: cannot write in {probe} ({e.strerror}); choose another location") from None
    if need_bytes > 0:
        free = shutil.disk_usage(probe).free
        if free < need_bytes:
            raise InputError(
                f"{option} {path}: {free / _MB:.4g} MB free on {probe} but this run needs "
                f"about {need_bytes / _MB:.4g} MB; free space or choose another location"
            )


def check_output_file(path, option: str = "-o", need_bytes: int = 0) -> Path:
    """Check an output *file* path before the work: not a folder, its folder writable.

    Raises
    ------
    InputError
        ``path`` is a folder, or its folder cannot be written.
    """
    path = Path(path)
    if path.is_dir():
        raise InputError(f"{option} {path}: is a folder; give a file name (e.g. {path / 'out.csv'})")
    _check_parent(path, option, need_bytes)
    clean_stale(path.parent, path.name)
    return path


def check_output_dir(path, *, force: bool = False, option: str = "--out", need_bytes: int = 0) -> Path:
    """Check an output *folder* before the work (see the module docstring for the rules).

    Returns the resolved path.
    """
    path = Path(path).resolve()
    if path.exists() and not path.is_dir():
        raise InputError(
            f"{option} {path}: is an existing file; rocklab writes a folder there and never "
            "replaces a file; choose another path"
        )
    if path.is_dir() and not force:
        try:
            names = foreign_entries(path)
        except OSError as e:
            raise InputError(f"{option} {path}: cannot list the folder ({e.strerror})") from None
        if names:
            shown = ", ".join(names[:3]) + (", ..." if len(names) > 3 else "")
            raise InputError(
                f"{option} {path}: folder holds files rocklab did not write ({shown}); choose a "
                "new or empty folder, or pass --force to write beside them (nothing of "
                "yours is deleted)"
            )
    _check_parent(path, option, need_bytes)
    clean_stale(path.parent, path.name)
    return path


def stage_dir(out_dir) -> Path:
    """A new private staging folder next to ``out_dir`` (``.NAME.tmp-PID-*``)."""
    out_dir = Path(out_dir)
    out_dir.parent.mkdir(parents=True, exist_ok=True)
    return Path(tempfile.mkdtemp(prefix=stale_prefix(out_dir.name, "tmp"), dir=out_dir.parent))


def _write_marker(folder: Path, command: str, entries) -> None:
    from . import __version__

    # written here, not through rocklab._io (which uses this module's stale-file helpers): a temporary
    # file renamed over the marker, so a killed writer leaves the old marker or the new one
    text = (
        json.dumps(
            {
                "written_by": f"rocklab {__version__}",
                "command": command,
                "time_unix_s": time.time(),
                "entries": sorted(entries),
            },
            indent=2,
        )
        + "\n"
    )
    fd, tmp = tempfile.mkstemp(prefix=stale_prefix(MARKER, "tmp"), dir=folder)
    try:
        with os.fdopen(fd, "w", encoding="utf-8") as f:
            f.write(text)
        os.replace(tmp, folder / MARKER)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise


def claim_dir(path, entries, command: str = "") -> Path:
    """Create folder ``path`` (if needed) for outputs written in place and record ``entries``
    (names rocklab will write there) in its marker, next to any recorded before."""
    path = Path(path)
    path.mkdir(parents=True, exist_ok=True)
    _write_marker(path, command, owned_entries(path) | set(entries))
    return path


def _user_copy_name(path: Path, stamp: str, k: int) -> Path:
    return path.with_name(f"{path.name}.user-{stamp}" + (f"-{k}" if k else ""))


def set_aside_user_file(path) -> Path | None:
    """Keep a user's file at ``path`` as ``NAME.user-<time>`` before rocklab writes a side file there.

    Side files (``<stem>_table.csv``, ``audit.json``, ``points.csv``, ``<stem>.parquet``,
    default output names) follow the rule of folder outputs: a file rocklab wrote there
    before (stamped, :func:`rocklab_wrote`, or recorded in the folder's :data:`MARKER`) and
    unchanged since is replaced; anything else is the user's and is kept under a new name,
    never overwritten. Returns the new name, or None when there was nothing of the user's to keep.
    """
    path = Path(path)
    if not (path.exists() or path.is_symlink()) or path.name in owned_entries(path.parent) or rocklab_wrote(path):
        return None
    stamp = time.strftime("%Y%m%dT%H%M%S")
    for k in range(1000):
        dest = _user_copy_name(path, stamp, k)
        try:  # a hard link cannot replace an existing name: two runs in one second keep both copies
            os.link(path, dest, follow_symlinks=False)
        except FileExistsError:
            continue
        except OSError:  # no hard links on this file system: a rename onto a name checked free
            if dest.exists() or dest.is_symlink():
                continue
            os.rename(path, dest)
        return dest
    raise InputError(f"{path}: too many kept copies ({path.name}.user-*); tidy the folder")


def claim_side_file(path, command: str = "") -> None:
    """Record the side file ``path`` as rocklab's in its folder's marker when the folder is rocklab's
    (it has a :data:`MARKER`); a user's folder gets no marker (the file's stamp says it is rocklab's)."""
    path = Path(path)
    if (path.parent / MARKER).is_file():
        claim_dir(path.parent, [path.name], command=command)


def _swap(src: Path, dest: Path) -> None:
    """Put ``src`` at ``dest`` (a folder rocklab owns there is replaced whole, by renames)."""
    if dest.is_dir() and not dest.is_symlink():
        old = Path(tempfile.mkdtemp(prefix=stale_prefix(dest.name, "old"), dir=dest.parent))
        os.rmdir(old)
        os.rename(dest, old)
        os.rename(src, dest)
        shutil.rmtree(old, ignore_errors=True)
    else:
        os.replace(src, dest)


def publish_dir(stage, out_dir, command: str = "") -> Path:
    """Move the finished ``stage`` folder onto ``out_dir`` by renames.

    A folder holding only what rocklab wrote (or nothing) is replaced whole. A
    folder that also holds the user's files (``--force``) receives rocklab's
    entries one by one: rocklab's own earlier entries are replaced, a user's entry
    of the same name is kept under ``NAME.user-<time>``; nothing of the user's is
    deleted.
    """
    raise_pending_stop()
    stage, out_dir = Path(stage), Path(out_dir)
    umask = os.umask(0)
    os.umask(umask)
    os.chmod(stage, 0o777 & ~umask)  # mkdtemp made it private
    new = [p.name for p in stage.iterdir() if p.name != MARKER]
    if not out_dir.exists() or not foreign_entries(out_dir):
        _write_marker(stage, command, new)
        _swap(stage, out_dir)
        return out_dir
    owned = owned_entries(out_dir)
    stamp = time.strftime("%Y%m%dT%H%M%S")
    for name in sorted(new):
        dest = out_dir / name
        if (dest.exists() or dest.is_symlink()) and name not in owned:
            os.rename(dest, out_dir / f"{name}.user-{stamp}")
        _swap(stage / name, dest)
    _write_marker(out_dir, command, owned | set(new))
    shutil.rmtree(stage, ignore_errors=True)
    return out_dir
