"""The result lines of a batch run, appended to its output file as the answers come.

Identical requests (one key) are computed once: the lines waiting for a key's answer are
``pending`` while it is computed, and a line read after that answer was written gets a copy of
its result line with its own number, read back from the output file (``_first``: where each
planned request's first result line lies, about 200 bytes per distinct request), so that no
answer is held in memory.
"""

from __future__ import annotations

import os
from typing import BinaryIO

import orjson

from toptraj.service.batches.lines import result_line


class ResultWriter:
    """Writes the result lines of one run into ``out`` (the output file, opened to append) at
    ``path``; counts them in ``written``."""

    def __init__(self, out: BinaryIO, path: os.PathLike[str] | str):
        self.out, self.path = out, path
        self.pending: dict[str, list[int]] = {}  # key -> the line numbers waiting for its answer
        self._first: dict[str, tuple[int, int, int, int]] = {}  # key -> (offset, length, line, status) of its first result
        self.written = 0
        out.flush()
        self._end = os.fstat(out.fileno()).st_size  # where the next line goes (the file is only appended to)

    def answered(self, key: str) -> bool:
        """Whether a result of ``key`` is in the file (a later line of it is copied from it)."""
        return key in self._first

    def write(self, number: int, key: str, status: int, body: bytes, shared: bool = True) -> None:
        """Line ``number``'s result line; ``shared``: a later line of the same request may be
        copied from it (a line refused at reading is not planned, and not remembered)."""
        line = result_line(number, key, status, body)
        if shared and key not in self._first:
            self._first[key] = (self._end, len(line), number, status)
        self.out.write(line)
        self._end += len(line)
        self.written += 1

    def answers(self, answers: list[tuple[str, int, bytes]]) -> int:
        """A result line for every line number waiting for each answered request; how many
        were written."""
        before = self.written
        for key, status, body in answers:
            for number in self.pending.pop(key, ()):
                self.write(number, key, status, body)
        self.out.flush()
        return self.written - before

    def copy(self, number: int, key: str) -> None:
        """Line ``number``'s result: that of an earlier line of the same request, read back."""
        offset, length, first, status = self._first[key]
        self.out.flush()
        with open(self.path, "rb") as handle:
            handle.seek(offset)
            raw = handle.read(length)
        head = orjson.dumps({"line": first, "key": key, "status": status})[:-1] + b',"body":'
        if not (raw.startswith(head) and raw.endswith(b"}\n")):
            raise OSError(f"{self.path}: the output file changed while the batch ran")
        self.write(number, key, status, raw[len(head) : -2])
