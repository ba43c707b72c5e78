"""GGUI windows: the Vulkan check, opening offscreen or on-screen windows, and closing them.

Facts of Taichi 1.7.4 that this module handles in one place:

- GGUI needs Vulkan (even on the CPU arch); without a driver ``ti.ui.Window`` raises
  ``RuntimeError("Vulkan must be available for GGUI")``. ``check_available`` turns that into a
  RenderError that says how to install one, before any simulation time is spent.
- A window must be destroyed before the interpreter exits, or the process crashes in the
  driver at exit; every window opened here is destroyed by ``close_window`` or at exit.
- Two windows that have both drawn cannot both be destroyed (the second destroy crashes the
  process), so one window is open at a time: opening a second is a RenderError. Share one
  Renderer (``FrameSink(renderer=...)``) or close the first.
- A window must be created after ``ti.init`` (``crowndemo.backend.init``).
"""
from __future__ import annotations

import atexit
import glob
import os
from typing import List, Optional, Tuple

INSTALL_HINT = ("install a Vulkan driver: on Debian/Ubuntu 'apt-get install "
                "mesa-vulkan-drivers' (lavapipe, a software driver that needs no GPU), or "
                "your GPU vendor's driver")
ICD_DIRS = ("/usr/share/vulkan/icd.d", "/etc/vulkan/icd.d", "/usr/local/share/vulkan/icd.d")

_open: List[object] = []            # windows not yet destroyed
IMGUI_INI = "imgui.ini"             # Dear ImGui (inside GGUI) writes this into the cwd
_ini_existed: Optional[bool] = None
_checked: Optional[bool] = None


class RenderError(RuntimeError):
    """Rendering cannot run here (no Vulkan driver, no display), or a renderer was misused."""


def _ensure_backend() -> None:
    from .. import backend
    backend.current()                # starts the default backend if none runs yet


def open_window(title: str, resolution: Tuple[int, int], show: bool = False,
                position: Tuple[int, int] = (100, 100)):
    """A GGUI window (offscreen unless ``show``); RenderError when Vulkan is unavailable."""
    import taichi as ti
    global _ini_existed
    _ensure_backend()
    if _ini_existed is None:
        _ini_existed = os.path.exists(IMGUI_INI)
    if _open:
        raise RenderError("a GGUI window is already open; Taichi 1.7.4 crashes when two "
                          "windows that both drew are closed, so close it first or reuse "
                          "its Renderer")
    w, h = (int(v) for v in resolution)
    if w < 2 or h < 2:
        raise RenderError(f"resolution {w}x{h} is too small (at least 2x2)")
    try:
        window = ti.ui.Window(title, (w, h), vsync=False, show_window=show, pos=position)
    except RuntimeError as e:
        raise RenderError(f"cannot open a GGUI window ({e}); {INSTALL_HINT}") from None
    _open.append(window)
    return window


def close_window(window) -> None:
    """Destroy a window opened by ``open_window`` (safe to call twice)."""
    if window in _open:
        _open.remove(window)
        window.destroy()
    if not _open and _ini_existed is False and os.path.isfile(IMGUI_INI):
        os.remove(IMGUI_INI)            # ours: do not leave ImGui's settings file behind


@atexit.register
def _close_all() -> None:
    while _open:
        close_window(_open[-1])


def icd_files() -> List[str]:
    """The Vulkan driver manifests the loader would find (VK_ICD_FILENAMES wins)."""
    env = os.environ.get("VK_ICD_FILENAMES") or os.environ.get("VK_DRIVER_FILES")
    if env:
        return [p for p in env.split(os.pathsep) if os.path.isfile(p)]
    return sorted(f for d in ICD_DIRS for f in glob.glob(os.path.join(d, "*.json")))


def check_available() -> None:
    """Raise RenderError (with how to install a driver) unless an offscreen GGUI window can be
    opened; opens a tiny one once per process."""
    global _checked
    if not icd_files():
        raise RenderError(f"no Vulkan driver found (GGUI renders through Vulkan); {INSTALL_HINT}")
    if _checked or _open:            # a window is open: Vulkan works
        return
    close_window(open_window("crowndemo check", (8, 8)))
    _checked = True


def has_display() -> bool:
    """Whether an on-screen window can be shown (X11 or Wayland)."""
    return bool(os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY"))


__all__ = ["RenderError", "INSTALL_HINT", "open_window", "close_window", "check_available",
           "icd_files", "has_display"]
