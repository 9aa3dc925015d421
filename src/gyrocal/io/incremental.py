"""A CSV file written row by row while data arrive, complete and in place whichever way the run ends.

Rows go to a temporary file beside the target; :meth:`IncrementalCSV.finish` flushes it to disk
and renames it over the target in one step, so a reader never sees a half-written file under the
target's name. A process killed outright (SIGKILL, power loss) leaves the temporary file, with
everything up to the last flush, for the user to recover.
"""

from __future__ import annotations

import os
import secrets
from collections.abc import Iterable, Sequence
from pathlib import Path

__all__ = ["IncrementalCSV"]


class IncrementalCSV:
    """Write a CSV with a fixed header incrementally; ``finish()`` puts it in place atomically.

    Parameters
    ----------
    path : path-like
        The final file.
    columns : sequence of str
        Header names.
    header_comment : str, optional
        Lines written first, each prefixed with ``# `` (readers of gyrocal skip them).
    """

    def __init__(self, path: str | os.PathLike, columns: Sequence[str], header_comment: str | None = None):
        from .writer import check_csv_name

        check_csv_name(path)
        self.path = Path(path)
        self.path.parent.mkdir(parents=True, exist_ok=True)
        while True:
            tmp = self.path.parent / f".{self.path.name}.{secrets.token_hex(4)}.part"
            try:
                fd = os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o666)
                break
            except FileExistsError:
                continue
        self.tmp_path = tmp
        self._f = os.fdopen(fd, "w", encoding="utf-8", newline="")
        self.rows = 0
        for line in (header_comment or "").splitlines():
            self._f.write(f"# {line}\n")
        self._f.write(",".join(columns) + "\n")

    def write_rows(self, rows: Iterable[Sequence[str]]) -> None:
        """Append rows of already formatted cells."""
        lines = [",".join(r) for r in rows]
        if lines:
            self._f.write("\n".join(lines) + "\n")
            self.rows += len(lines)

    def flush(self) -> None:
        """Hand what was written to the operating system (it survives the process, not a power cut)."""
        self._f.flush()

    def finish(self) -> Path:
        """Flush to disk and move the file into place; returns the final path."""
        self._f.flush()
        os.fsync(self._f.fileno())
        self._f.close()
        if self.path.exists():
            os.chmod(self.tmp_path, self.path.stat().st_mode & 0o7777)
        os.replace(self.tmp_path, self.path)
        return self.path

    def discard(self) -> None:
        """Close and delete the temporary file (nothing worth keeping was written)."""
        self._f.close()
        self.tmp_path.unlink(missing_ok=True)
