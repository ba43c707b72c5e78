"""The booth loop: recordings played one after another with a title card before each, forever
or N loops, in a GGUI window or (headless) into a video file.

A recording is a folder ``ROOT/NAME`` holding ``frames/frame_*.png`` (preferred) or a video,
and usually ``metadata.json``. It is complete when its metadata says ``"status": "complete"``
(or ``"complete": true``); without metadata, when ``video.mp4`` exists (the frame sink names a
video of an unfinished recording ``video.partial.mp4``). Incomplete recordings are skipped
with a warning, or with ``partial=True`` played with an "incomplete" marker on every frame.
A folder with metadata.json but no frames or video (recorded with --no-render) has nothing to
play: it is skipped with a warning too.
"""
from __future__ import annotations

import fnmatch
import glob
import itertools
import os
import sys
import time
from dataclasses import dataclass, field
from typing import Dict, Iterator, List, Optional, Sequence, Tuple

import numpy as np
from PIL import Image

from ..record.files import (FRAME_GLOB, FRAMES, METADATA, VIDEO, VIDEO_GLOB, rendered_frames,
                            video_names)
from ..record.metadata import read as read_metadata
from ..record.sinks import COMPLETE, INTERRUPTED
from . import video
from .captions import effective_lang, mark, title_card
from .window import close_window, open_window

DEFAULT_ROOT = "recordings"
CARD_SECONDS = 3.0
# --card-seconds: 0 shows no title cards; a minute is already far longer than a booth card
# needs, and a huge or non-finite one never gets to the recordings (or cannot be counted).
CARD_RANGE = (0.0, 60.0)
NO_FRAMES = "no frames (recorded with --no-render)"
MARKER = {"en": "INCOMPLETE RECORDING", "ja": "未完了の記録"}


class PlayError(ValueError):
    """A recording that cannot be found or read."""


@dataclass
class Recording:
    name: str
    path: str
    frames: List[str]                 # PNG paths, in order; empty when a video is played
    video: Optional[str]              # a video file, when there are no PNG frames
    complete: bool
    title: object                     # a string or {en: ..., ja: ...}
    description: object = ""
    metadata: Dict = field(default_factory=dict)

    def images(self) -> Iterator[np.ndarray]:
        if self.frames:
            return (video.read_image(p) for p in self.frames)
        return video.read_video(self.video)


def _read_metadata(path: str) -> Dict:
    """The recording's metadata.json ({} without one); PlayError when it is damaged."""
    meta_path = os.path.join(path, METADATA)
    try:
        return read_metadata(meta_path) or {}
    except (OSError, ValueError) as e:
        raise PlayError(f"{meta_path}: cannot read ({e})") from None


def _is_complete(meta: Dict, path: str) -> bool:
    if "status" in meta:
        return meta["status"] == COMPLETE
    if "complete" in meta:
        return bool(meta["complete"])
    return os.path.isfile(os.path.join(path, VIDEO))


def _preset_texts(name: str, meta: Dict) -> Tuple[object, object]:
    """Title and description: from metadata.json (``title``, and ``description`` or
    ``parameters.values.description``), else from the preset named there (or the folder's
    name), else the folder's name."""
    values = (meta.get("parameters") or {}).get("values") or {}
    title = meta.get("title") or values.get("title")
    description = meta.get("description") or values.get("description")
    if title and description:
        return title, description
    from .. import config
    from ..config import schema
    try:
        preset = meta.get("preset") if isinstance(meta.get("preset"), str) else name
        v = schema.validate(config.load_document(preset))
        return title or v["title"], description or v.get("description", "")
    except (config.PresetError, OSError, ValueError):   # no such preset: what there is will do
        return title or name, description or ""


def open_recording(spec: str, root: str = DEFAULT_ROOT) -> Recording:
    """A recording by folder path or by name under ``root``."""
    path = spec if os.path.isdir(spec) and os.sep in spec.rstrip(os.sep) else \
        os.path.join(root, spec)
    if not os.path.isdir(path):
        from ..config.errors import did_you_mean
        names = list_recordings(root)
        have = ", ".join(names) or "none"
        raise PlayError(f"no recording {spec!r} in {root}/{did_you_mean(spec, names)} "
                        f"(recordings there: {have})")
    name = os.path.basename(os.path.normpath(path))
    meta = _read_metadata(path)
    complete = _is_complete(meta, path)
    frames = rendered_frames(path)
    vid = None
    if not frames:
        names = [VIDEO] + ([] if complete else [video_names(INTERRUPTED)["video"]])
        vid = next((os.path.join(path, n) for n in names
                    if os.path.isfile(os.path.join(path, n))), None)
        if vid is None:
            why = (f"{NO_FRAMES}; record it again without --no-render to play it" if meta
                   else f"no frames ({FRAMES}/{FRAME_GLOB}) and no {VIDEO}")
            raise PlayError(f"{path}: {why}")
    title, description = _preset_texts(name, meta)
    return Recording(name, path, frames, vid, complete, title, description, meta)


def list_recordings(root: str = DEFAULT_ROOT) -> List[str]:
    """The names of the folders under ``root`` that hold frames or a video."""
    if not os.path.isdir(root):
        return []
    return sorted(n for n in os.listdir(root)
                  if glob.glob(os.path.join(root, n, FRAMES, FRAME_GLOB))
                  or glob.glob(os.path.join(root, n, VIDEO_GLOB)))


def frameless_recordings(root: str = DEFAULT_ROOT) -> List[str]:
    """The names of the folders under ``root`` with a metadata.json but no frames or video:
    recordings made with --no-render, which have nothing to play."""
    if not os.path.isdir(root):
        return []
    playable = set(list_recordings(root))
    return sorted(n for n in os.listdir(root) if n not in playable
                  and os.path.isfile(os.path.join(root, n, METADATA)))


def warn_frameless(names: Sequence[str]) -> None:
    """A warning for each recording skipped for having no frames, as ``select`` warns."""
    for n in names:
        print(f"crowndemo: warning: recording {n} has {NO_FRAMES}; skipping it (record it "
              "again without --no-render to play it)", file=sys.stderr)


def owner_of(out: str, folders: Sequence[str]) -> Optional[Tuple[str, str]]:
    """(the folder, the file's name) when the video file ``out`` (links followed) is one of
    the videos of the recording in one of ``folders``, there or not yet (a reel written there
    would replace the recording's video, or be played as the recording); else None. Of a
    recording's files only its videos are MP4s, the one kind of file --out writes."""
    target = os.path.realpath(out)
    for folder in folders:
        if os.path.dirname(target) == os.path.realpath(folder) and \
                fnmatch.fnmatch(os.path.basename(target), VIDEO_GLOB):
            return folder, os.path.basename(target)
    return None


def select(recordings: Sequence[Recording], partial: bool) -> List[Recording]:
    """The recordings to play: incomplete ones only with ``partial`` (a warning either way)."""
    chosen = []
    for r in recordings:
        if not r.complete:
            what = "playing it with a marker" if partial else "skipping it (--partial plays it)"
            print(f"crowndemo: warning: recording {r.name} is incomplete; {what}",
                  file=sys.stderr)
            if not partial:
                continue
        chosen.append(r)
    return chosen


def fit(image: np.ndarray, size: Tuple[int, int]) -> np.ndarray:
    """``image`` scaled to fit ``size`` (w, h), centred on black."""
    w, h = size
    ih, iw = image.shape[:2]
    if (iw, ih) == (w, h):
        return image
    s = min(w / iw, h / ih)
    nw, nh = max(1, round(iw * s)), max(1, round(ih * s))
    scaled = np.asarray(Image.fromarray(image).resize((nw, nh), Image.LANCZOS))
    out = np.zeros((h, w, 3), np.uint8)
    y, x = (h - nh) // 2, (w - nw) // 2
    out[y:y + nh, x:x + nw] = scaled
    return out


def reel(recordings: Sequence[Recording], size: Tuple[int, int], loops: Optional[int],
         card_frames: int, lang: str = "en") -> Iterator[np.ndarray]:
    """Every frame of the loop: for each recording, its title card ``card_frames`` times, then
    its frames; ``loops`` times (None: forever)."""
    if not recordings:
        raise PlayError("no recording to play")
    lang = effective_lang(lang)
    for _ in (range(loops) if loops is not None else itertools.count()):
        for r in recordings:
            marker = None if r.complete else MARKER[lang]
            card = title_card(size, r.title, r.description, lang, marker)
            for _ in range(card_frames):
                yield card
            for img in r.images():
                img = fit(img, size)
                if marker:
                    img = mark(img, marker, lang)
                yield img


def play_to_file(frames: Iterator[np.ndarray], out: str, fps: float) -> int:
    """Write the reel to a video file; returns the number of frames."""
    d = os.path.dirname(os.path.abspath(out))
    os.makedirs(d, exist_ok=True)
    return video.encode_mp4(frames, out, fps)


def play_in_window(frames: Iterator[np.ndarray], size: Tuple[int, int], fps: float) -> int:
    """Show the reel in a GGUI window at the top-left corner of the screen (GGUI 1.7.4 has no
    full-screen mode: give the screen's size). Esc or closing the window stops it."""
    import taichi as ti
    window = open_window("crowndemo", size, show=True, position=(0, 0))
    canvas, shown, period = window.get_canvas(), 0, 1.0 / fps
    try:
        next_t = time.perf_counter()
        for img in frames:
            if not window.running or window.get_event(ti.ui.PRESS) and \
                    window.event.key == ti.ui.ESCAPE:
                break
            canvas.set_image(np.ascontiguousarray(
                np.transpose(img[::-1], (1, 0, 2)).astype(np.float32) / 255.0))
            window.show()
            shown += 1
            next_t += period
            time.sleep(max(0.0, next_t - time.perf_counter()))
    finally:
        close_window(window)
    return shown


def require_display() -> None:
    """RenderError unless the booth window can open, saying how to play without one."""
    from .window import require_display as require
    require("use --headless --out FILE.mp4 to play into a video file")


__all__ = ["Recording", "PlayError", "open_recording", "list_recordings",
           "frameless_recordings", "warn_frameless", "owner_of", "select", "reel", "fit",
           "play_to_file", "play_in_window", "require_display", "DEFAULT_ROOT", "CARD_SECONDS",
           "CARD_RANGE", "MARKER"]
