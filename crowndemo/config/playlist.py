"""Playlist files: one preset per line (a name, or a path taken relative to the playlist's
folder); blank lines and ``#`` comments are skipped."""
from __future__ import annotations

from pathlib import Path
from typing import List, Tuple

from .errors import PresetError
from .loader import display, looks_like_path


def _lines(p: Path, label: str) -> List[str]:
    """The playlist's lines; PresetError for a file that cannot be read or is not UTF-8
    (naming the first line that is not)."""
    allowed = "a UTF-8 text file, one preset name or path per line"
    try:
        data = p.read_bytes()
    except OSError as e:
        raise PresetError(label, None, why=f"cannot read the playlist ({e.strerror})",
                          allowed=allowed) from None
    try:
        return data.decode("utf-8").splitlines()
    except UnicodeDecodeError as e:
        no = data.count(b"\n", 0, e.start) + 1
        raise PresetError(f"{label}:{no}", None, why=f"not UTF-8 text (byte "
                          f"0x{data[e.start]:02x})", allowed=allowed) from None


def read_playlist(path: str) -> List[Tuple[str, str]]:
    """(preset spec, source such as 'list.txt:3') per entry; PresetError for a missing,
    unreadable, non-UTF-8 or empty file or a line with more than one word."""
    p = Path(path)
    label = display(p)
    lines = _lines(p, label)
    out = []
    for no, line in enumerate(lines, 1):
        text = line.split("#", 1)[0].strip()
        if not text:
            continue
        if len(text.split()) > 1:
            raise PresetError(f"{label}:{no}", "preset", text, "one preset per line",
                              "a preset name or a path; --quality and --set apply to all")
        if looks_like_path(text) and not Path(text).expanduser().is_absolute():
            text = str(p.parent / text)
        out.append((text, f"{label}:{no}"))
    if not out:
        raise PresetError(label, None, why="the playlist names no preset",
                          allowed="one preset name or path per line (# starts a comment)")
    return out


__all__ = ["read_playlist"]
