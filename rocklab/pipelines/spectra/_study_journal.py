"""A record study that can be stopped and resumed: the rows finished so far, kept beside its table.

``rocklab oas FOLDER -o TABLE.csv`` runs one task per record and h/b. Each finished row is
written at once to ``TABLE.csv.journal.json`` (the whole file rewritten atomically, so a kill
leaves the previous version whole), and a run that was stopped (Ctrl-C, a killed job, a lost
Dask worker) goes on with ``--resume`` from the rows it had. A row is reused only for the same
record content (SHA-256 of the file), the same h/b and the same options and rocklab version; the
journal is removed once the table is written. A journal left by an unfinished run is never
replaced silently: without ``--resume`` the run stops and says what to do.
"""

from __future__ import annotations

import hashlib
import json
import math
from dataclasses import dataclass, field
from pathlib import Path

__all__ = ["StudyJournal", "task_key", "journal_path"]

#: What a journal file holds, checked on reading (a file of another kind is refused).
JOURNAL_KIND = "rocklab oas study journal"


def journal_path(table_path) -> Path:
    """The journal beside a study's table: ``TABLE.csv`` -> ``TABLE.csv.journal.json``."""
    p = Path(table_path)
    return p.with_name(p.name + ".journal.json")


def file_digest(path) -> str:
    """SHA-256 (hex) of a record file's bytes: a row is reused only for the same content."""
    h = hashlib.sha256()
    with open(path, "rb") as f:
        for chunk in iter(lambda: f.read(1 << 20), b""):
            h.update(chunk)
    return h.hexdigest()


def task_key(digest: str, h_over_b: float) -> str:
    """The key of one task: a record's content digest and the block's h/b (``repr``, exact)."""
    return f"{digest}:{float(h_over_b)!r}"


def _canonical(options: dict) -> str:
    # NaN and None both mean "not set" in the options that reach here; sorted keys make the
    # comparison independent of the order the caller built the dict in
    def clean(v):
        if isinstance(v, float) and not math.isfinite(v):
            return None
        if isinstance(v, dict):
            return {k: clean(x) for k, x in sorted(v.items())}
        if isinstance(v, (list, tuple)):
            return [clean(x) for x in v]
        return v

    return json.dumps(clean(options), sort_keys=True, default=str)


@dataclass
class StudyJournal:
    """The finished rows of one study, read from and written to :attr:`path`.

    Attributes
    ----------
    path : Path
        The journal file (``TABLE.csv.journal.json``).
    options : dict
        Everything besides the record and h/b that changes a row (OAS options, units, band,
        rocklab's version), JSON-serialisable.
    rows : dict
        Task key (:func:`task_key`) -> the finished row (dict of the table's columns).
    resumed : int
        Rows taken over from an earlier run.
    """

    path: Path
    options: dict
    rows: dict = field(default_factory=dict)
    resumed: int = 0

    @classmethod
    def open(cls, table_path, options: dict, resume: bool) -> StudyJournal:
        """The journal of the study writing ``table_path``.

        Raises
        ------
        InputError
            A journal of an unfinished run is there and ``resume`` is False (it is kept:
            add ``--resume`` or delete it); with ``resume``, the journal cannot be read or was
            written with other options.
        """
        from ..._errors import InputError

        path = journal_path(table_path)
        j = cls(path=path, options=json.loads(_canonical(options)))
        if not path.exists():
            return j
        try:
            d = json.loads(path.read_text(encoding="utf-8"))
            ok = isinstance(d, dict) and d.get("kind") == JOURNAL_KIND and isinstance(d.get("rows"), dict)
        except (OSError, UnicodeDecodeError, json.JSONDecodeError):
            ok, d = False, {}
        if not resume:
            n = len(d["rows"]) if ok else "?"
            raise InputError(
                f"{path}: an unfinished run's journal ({n} finished rows) is there; add --resume to go "
                "on from it, or delete it to start again"
            )
        if not ok:
            raise InputError(f"{path}: not a readable rocklab study journal; delete it to start again")
        if _canonical(d.get("options", {})) != _canonical(j.options):
            diff = sorted(
                k
                for k in set(d.get("options", {})) | set(j.options)
                if _canonical({k: d.get("options", {}).get(k)}) != _canonical({k: j.options.get(k)})
            )
            raise InputError(
                f"{path}: written by a run with other options ({', '.join(diff)} differ); resume with the "
                "same options, or delete the journal to start again"
            )
        j.rows = dict(d["rows"])
        j.resumed = len(j.rows)
        return j

    def get(self, key: str) -> dict | None:
        """The finished row of a task, or None."""
        return self.rows.get(key)

    def add(self, key: str, row: dict) -> None:
        """Record a finished row and rewrite the journal atomically (a kill keeps the last whole one)."""
        from ..._io import write_text_atomic

        self.rows[key] = row
        text = json.dumps({"kind": JOURNAL_KIND, "options": self.options, "rows": self.rows}, allow_nan=True)
        write_text_atomic(self.path, text + "\n", side=True)

    def close(self) -> None:
        """Remove the journal: the study's table holds every row now."""
        self.path.unlink(missing_ok=True)
