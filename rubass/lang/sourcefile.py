"""Reading spec and library files: every way a file can be unusable becomes one Diagnostic."""
from __future__ import annotations

import os
import stat
from typing import BinaryIO, Optional, Tuple

from .errors import Diagnostic
from .source import Source, Span

MAX_BYTES = 4 * 1024 * 1024


def read_source(path: str, what: str = "spec") -> Tuple[Optional[Source], Optional[Diagnostic]]:
    """The file as a Source, or None and a diagnostic that says what is wrong with it."""
    here = Span(path, 0, 0)
    if path.startswith("package://"):  # one its caller could not resolve (file_arg): why, not "no such file"
        from .paths import PathError, resolve

        try:
            resolve(path, "/")
        except PathError as exc:
            return None, Diagnostic(here, f"cannot read {what}: {exc}")
    try:
        if os.path.isdir(path):
            return None, Diagnostic(here, f"cannot read {what}: it is a directory")
        mode = os.stat(path).st_mode
        if not stat.S_ISREG(mode):  # a FIFO would block the reader forever, /dev/zero never ends
            return None, Diagnostic(here, f"cannot read {what}: not a regular file")
        size = os.path.getsize(path)
        if size > MAX_BYTES:
            return None, Diagnostic(here, f"cannot read {what}: {size} bytes is over the limit of "
                                          f"{MAX_BYTES} bytes")
        with open(path, "rb") as fh:
            data = read_at_most(fh, MAX_BYTES + 1)
        if len(data) > MAX_BYTES:
            return None, Diagnostic(here, f"cannot read {what}: it grew past the limit of {MAX_BYTES} bytes "
                                          f"while being read")
    except FileNotFoundError:
        return None, Diagnostic(here, f"cannot read {what}: no such file")
    except PermissionError:
        return None, Diagnostic(here, f"cannot read {what}: permission denied")
    except OSError as exc:
        return None, Diagnostic(here, f"cannot read {what}: {exc.strerror or exc}")
    return decode_source(path, data, what)


def read_at_most(fh: BinaryIO, limit: int) -> bytes:
    """Up to `limit` bytes of an open file, in a buffer the size of the file, not of the limit.

    fh.read(limit) allocates `limit` bytes first: 4 MiB for every spec and library a reload
    reads. A file that grows while it is read is read on, up to the limit."""
    size = os.fstat(fh.fileno()).st_size
    parts = [fh.read(min(size, limit - 1) + 1)]
    got = len(parts[0])
    while got > size and got < limit:  # it grew: read on in small steps
        more = fh.read(min(1 << 16, limit - got))
        if not more:
            break
        parts.append(more)
        got += len(more)
    return parts[0] if len(parts) == 1 else b"".join(parts)


def decode_source(name: str, data: bytes, what: str = "spec") -> Tuple[Optional[Source], Optional[Diagnostic]]:
    """Bytes to a Source: UTF-8 text without NUL bytes, or a diagnostic at the bad byte."""
    if data.startswith(b"\xef\xbb\xbf"):
        data = data[3:]
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as exc:
        good = Source(name, data[: exc.start].decode("utf-8"))
        line, col = good.position(len(good.text))
        return None, Diagnostic(Span(name, line, col), f"{what} is not UTF-8 text: invalid byte "
                                                       f"0x{data[exc.start]:02x}", line_text=_shown_line(data, line))
    nul = text.find("\x00")
    if nul >= 0:
        src = Source(name, text)
        line, col = src.position(nul)
        return None, Diagnostic(Span(name, line, col), f"{what} is not text: it contains a NUL byte",
                                line_text=_shown_line(data, line))
    return Source(name, text.replace("\r\n", "\n")), None


def _shown_line(data: bytes, line: int) -> str:
    """Line `line` (1-based) of undecodable bytes, shown with one mark per bad byte or NUL, so the
    caret under the column points at it."""
    raw = data.split(b"\n")[line - 1] if line - 1 < data.count(b"\n") + 1 else b""
    return raw.decode("utf-8", errors="replace").replace("\x00", "\u2400")
