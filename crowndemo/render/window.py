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
- An on-screen window goes through GLFW, built for X11 only on Linux; when DISPLAY names no
  X server it prints "cannot initialize GLFW" and may crash the process, so
  ``require_display`` checks that an X server answers first.
"""
from __future__ import annotations

import atexit
import glob
import os
import socket
import sys
from typing import TYPE_CHECKING, List, Optional, Tuple, Union

if TYPE_CHECKING:
    import taichi as ti

INSTALL_HINT = ("install a Vulkan driver: on Debian/Ubuntu 'apt-get install "
                "mesa-vulkan-drivers' (lavapipe, a software driver that needs no GPU), or "
                "your GPU vendor's driver")
ICD_DIRS = ("/usr/share/vulkan/icd.d", "/etc/vulkan/icd.d", "/usr/local/share/vulkan/icd.d")

X11_SOCKET_DIR = "/tmp/.X11-unix"   # a local X server's socket X<N> for DISPLAY=:N
X11_TCP_PORT = 6000                 # + N: a remote X server (DISPLAY=HOST:N, e.g. over ssh -X)
CONNECT_TIMEOUT_S = 1.0

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
                position: Tuple[int, int] = (100, 100)) -> ti.ui.Window:
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


def close_window(window: ti.ui.Window) -> None:
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


def _connects(address: Union[str, Tuple[str, int]]) -> bool:
    """Whether a stream socket connects to ``address`` (a unix socket path, or (host, port))
    within CONNECT_TIMEOUT_S."""
    try:
        if isinstance(address, tuple):
            socket.create_connection(address, CONNECT_TIMEOUT_S).close()
        else:
            with socket.socket(socket.AF_UNIX, socket.SOCK_STREAM) as s:
                s.settimeout(CONNECT_TIMEOUT_S)
                s.connect(address)
        return True
    except (OSError, ValueError):                         # ValueError: a NUL in a path
        return False


def x11_problem(display: str) -> Optional[str]:
    """None when an X server answers on ``display`` ([HOST]:N[.S]), else why not: the local
    socket X11_SOCKET_DIR/XN (or its abstract twin) when HOST is empty or "unix", else TCP
    port 6000 + N on HOST."""
    host, colon, rest = display.rpartition(":")
    number = rest.split(".", 1)[0]
    if not colon or not number.isdigit():
        return "not of the form [HOST]:N[.S]"
    if host in ("", "unix"):
        path = os.path.join(X11_SOCKET_DIR, "X" + number)
        if _connects("\0" + path) or _connects(path):   # Linux servers listen on both
            return None
        return f"no X server answers on {path}"
    port = X11_TCP_PORT + int(number)
    if _connects((host, port)):
        return None
    return f"no X server answers at {host}:{port}"


def display_problem() -> Optional[str]:
    """None when an on-screen GGUI window can open, else why not. Taichi 1.7.4's GLFW talks
    X11 only on Linux, so a Wayland session needs XWayland (which sets DISPLAY)."""
    if sys.platform in ("darwin", "win32"):
        return None                                       # the system's own windows
    display = os.environ.get("DISPLAY")
    if display:
        problem = x11_problem(display)
        return problem and f"cannot open a window on DISPLAY {display} ({problem})"
    if os.environ.get("WAYLAND_DISPLAY"):
        return ("cannot open a window: WAYLAND_DISPLAY is set but DISPLAY is not, and "
                "Taichi's GGUI opens windows through X11 only (start XWayland)")
    return "no display (DISPLAY unset)"


def has_display() -> bool:
    """Whether an on-screen window can be shown (an X server answers on $DISPLAY)."""
    return display_problem() is None


def require_display(advice: str) -> None:
    """RenderError ("<why not>; <advice>") unless an on-screen window can open; call it
    before GLFW is touched (Taichi crashes when GLFW cannot reach the display)."""
    problem = display_problem()
    if problem:
        raise RenderError(f"{problem}; {advice}")


__all__ = ["RenderError", "INSTALL_HINT", "open_window", "close_window", "check_available",
           "icd_files", "has_display", "display_problem", "require_display", "x11_problem"]
