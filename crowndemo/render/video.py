"""Image files and videos, each written under a temporary name and renamed when whole, so a
half-written file never stands under its final name: PNG frames, H.264 MP4 (imageio-ffmpeg,
yuv420p, even dimensions) and a small GIF preview."""
from __future__ import annotations

import os
from typing import Iterable, List, Sequence

import numpy as np
from PIL import Image

GIF_WIDTH = 320          # pixels: the preview's width
GIF_FRAMES = 24          # at most this many frames in the preview
GIF_MAX_DELAY_MS = 655350   # a GIF frame's delay is 16 bits of 1/100 s
VIDEO_SUFFIXES = (".mp4",)   # what VideoWriter writes: H.264 in an MP4 container


def _tmp(path: str) -> str:
    """A hidden temporary name beside ``path`` with the same extension (ffmpeg and Pillow
    choose the format by it)."""
    d, base = os.path.split(path)
    stem, ext = os.path.splitext(base)
    return os.path.join(d, f".{stem}.tmp{os.getpid()}{ext}")


def write_png(image: np.ndarray, path: str) -> None:
    tmp = _tmp(path)
    Image.fromarray(image).save(tmp, format="PNG", compress_level=1)
    os.replace(tmp, path)


def read_image(path: str) -> np.ndarray:
    return np.asarray(Image.open(path).convert("RGB"))


def even(image: np.ndarray) -> np.ndarray:
    """Crop a row and/or a column so both dimensions are even (yuv420p needs that)."""
    h, w = image.shape[:2]
    return image[: h - h % 2, : w - w % 2]


def is_video_path(path: str) -> bool:
    """Whether ``path`` names a kind of video file that VideoWriter writes."""
    return os.path.splitext(path)[1].lower() in VIDEO_SUFFIXES


def check_video_path(path: str) -> None:
    """ValueError unless ``path`` names a kind of video file that VideoWriter writes."""
    if not is_video_path(path):
        raise ValueError(f"{path}: a video file must end in " + " or ".join(VIDEO_SUFFIXES)
                         + " (H.264 MP4)")


class VideoWriter:
    """An H.264 MP4 written frame by frame to a temporary name; ``close(keep=True)`` renames
    it to ``path``, ``close(keep=False)`` deletes it."""

    def __init__(self, path: str, fps: float):
        import imageio.v2 as iio
        check_video_path(path)
        self.path, self.tmp = path, _tmp(path)
        self.frames = 0
        self._writer = iio.get_writer(self.tmp, format="FFMPEG", fps=fps, codec="libx264",
                                      pixelformat="yuv420p", macro_block_size=1,
                                      ffmpeg_log_level="error", quality=8)

    def append(self, image: np.ndarray) -> None:
        self._writer.append_data(even(image))
        self.frames += 1

    def close(self, keep: bool = True) -> None:
        if self._writer is None:
            return
        self._writer.close()
        self._writer = None
        if keep and self.frames:
            os.replace(self.tmp, self.path)
        elif os.path.exists(self.tmp):
            os.remove(self.tmp)

    def __enter__(self) -> "VideoWriter":
        return self

    def __exit__(self, exc_type, *rest) -> None:
        self.close(keep=exc_type is None)


def encode_mp4(frames: Iterable[np.ndarray], path: str, fps: float) -> int:
    """Encode images into ``path``; returns the frame count."""
    with VideoWriter(path, fps) as w:
        for f in frames:
            w.append(f)
    return w.frames


def encode_gif(paths: Sequence[str], path: str, fps: float, width: int = GIF_WIDTH,
               max_frames: int = GIF_FRAMES) -> int:
    """A small looping GIF: at most ``max_frames`` evenly chosen frames, ``width`` wide, shown
    over the same time as the video. Returns the frame count."""
    if not paths:
        return 0
    step = max(1, -(-len(paths) // max_frames))          # ceil
    chosen: List[str] = list(paths[::step])
    images = []
    for p in chosen:
        im = Image.open(p).convert("RGB")
        h = max(2, round(im.height * width / im.width))
        images.append(im.resize((width, h), Image.LANCZOS).quantize(colors=128))
    # Pillow merges identical frames, adding up their delays: keep even the sum in 16 bits
    delay = min(GIF_MAX_DELAY_MS // len(images), max(20, int(1000 * step / fps)))
    tmp = _tmp(path)
    try:
        images[0].save(tmp, format="GIF", save_all=True, append_images=images[1:], loop=0,
                       duration=delay, optimize=True)
        os.replace(tmp, path)
    finally:
        if os.path.exists(tmp):          # a failed save leaves no temporary file
            os.remove(tmp)
    return len(images)


def read_video(path: str) -> Iterable[np.ndarray]:
    """The frames of a video file, one by one."""
    import imageio.v2 as iio
    reader = iio.get_reader(path, format="FFMPEG")
    try:
        for frame in reader:
            yield np.asarray(frame)[..., :3]
    finally:
        reader.close()


__all__ = ["write_png", "read_image", "even", "is_video_path", "check_video_path", "VIDEO_SUFFIXES",
           "VideoWriter", "encode_mp4", "encode_gif", "read_video"]
