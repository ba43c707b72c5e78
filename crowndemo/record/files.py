"""Where recordings live and how their files are written: every file goes to a temporary name
in the same folder and is renamed into place, so a file that stands under its name is whole."""
from __future__ import annotations

import json
import os
import tempfile
from pathlib import Path
from typing import Any, BinaryIO, Callable, Dict, List, Optional, Tuple, Union

from .sinks import COMPLETE

PathLike = Union[str, "os.PathLike[str]"]

METADATA = "metadata.json"
CHECKPOINT = "checkpoint.npz"
SNAPSHOTS = "snapshots"


# what rendering writes into a recording's folder (render/sink.py): FRAMES/frame_NNNNN.png,
# and when the recording closes video.mp4 and preview.gif, or video.partial.mp4 and
# preview.partial.gif when it did not complete (``video_names``)
FRAMES = "frames"
FRAME_GLOB = "frame_*.png"
VIDEO_GLOB = "video*.mp4"
PREVIEW_GLOB = "preview*.gif"
VIDEO = "video.mp4"


def video_names(status: str) -> Dict[str, str]:
    """The video and preview names for a recording that closed with ``status``."""
    tag = "" if status == COMPLETE else ".partial"
    return {"video": f"video{tag}.mp4", "preview": f"preview{tag}.gif"}


def remove_rendered(folder: PathLike, keep_frames: bool = False) -> int:
    """Delete the rendered frames (unless ``keep_frames``), videos and previews in ``folder``;
    returns how many."""
    patterns = [VIDEO_GLOB, PREVIEW_GLOB] + ([] if keep_frames else [f"{FRAMES}/{FRAME_GLOB}"])
    gone = [p for pattern in patterns for p in Path(folder).glob(pattern)]
    for p in gone:
        p.unlink()
    return len(gone)


def rendered_frames(folder: PathLike) -> List[str]:
    """The rendered frames of the recording in ``folder``, in order (paths as strings)."""
    return sorted(str(p) for p in Path(folder, FRAMES).glob(FRAME_GLOB))


def recordings_root() -> Path:
    """``$CROWNDEMO_RECORDINGS``, else ``recordings/`` in the working directory."""
    return Path(os.environ.get("CROWNDEMO_RECORDINGS") or "recordings")


def recording_dir(name: str, root: PathLike = None) -> Path:
    return Path(root if root is not None else recordings_root()) / name


def folder_problem(folder: PathLike) -> Optional[Tuple[Path, str]]:
    """Why recordings cannot be written into ``folder``, as (the path at fault, what is
    wrong), or None when they can. Tried for real: the missing folders are created and a
    temporary file written, then what was created is removed again."""
    folder = Path(folder)
    missing = []                      # deepest first
    existing = folder
    while not existing.exists() and existing != existing.parent:
        missing.append(existing)
        existing = existing.parent
    if not existing.is_dir():
        return existing, "not a folder"
    try:
        return _try_writing(folder)
    finally:
        for p in missing:
            try:
                p.rmdir()
            except OSError:
                break


def _try_writing(folder: Path) -> Optional[Tuple[Path, str]]:
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError as e:
        return Path(e.filename or folder), f"cannot create it ({e.strerror})"
    try:
        with tempfile.TemporaryFile(dir=folder):
            pass
    except OSError as e:
        return folder, f"cannot write in it ({e.strerror})"
    return None


def frame_name(index: int, suffix: str = ".npz") -> str:
    """The file of frame ``index``: a snapshot (.npz) or a rendered frame (.png)."""
    return f"frame_{index:05d}{suffix}"


def atomic_write(path: PathLike, write: Callable[[BinaryIO], None]) -> None:
    """Call ``write(file)`` on a temporary file next to ``path``, then rename it to ``path``."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f".{path.name}.tmp{os.getpid()}")
    try:
        with open(tmp, "wb") as f:
            write(f)
            f.flush()
            os.fsync(f.fileno())
        os.replace(tmp, path)
    finally:
        if tmp.exists():
            tmp.unlink()


def atomic_write_text(path: PathLike, text: str) -> None:
    atomic_write(path, lambda f: f.write(text.encode("utf-8")))


def atomic_write_json(path: PathLike, data: Any) -> None:
    atomic_write_text(path, json.dumps(data, indent=2, default=_jsonable) + "\n")


def _jsonable(x):
    """numpy scalars and other numbers json does not know."""
    if hasattr(x, "item"):
        return x.item()
    if isinstance(x, Path):
        return str(x)
    raise TypeError(f"{type(x).__name__} is not JSON serialisable")
