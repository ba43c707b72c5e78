"""Whether an on-screen window can open: an X server must answer on $DISPLAY (Taichi 1.7.4's
GLFW talks X11 only, and crashes when DISPLAY names no server). Sockets are made here."""
import socket
import tempfile

import pytest

from crowndemo.render import window


@pytest.fixture
def x11_dir(monkeypatch):
    """An empty X11 socket folder (short path: unix socket paths are limited to 107 bytes)."""
    with tempfile.TemporaryDirectory(dir="/tmp") as d:
        monkeypatch.setattr(window, "X11_SOCKET_DIR", d)
        monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
        yield d


def listening(family, address):
    s = socket.socket(family, socket.SOCK_STREAM)
    s.bind(address)
    s.listen(16)                      # never accepts: room for every probe
    return s


def test_display_with_no_x_server(x11_dir, monkeypatch):
    monkeypatch.setenv("DISPLAY", ":99")
    assert not window.has_display()
    assert window.display_problem() == \
        f"cannot open a window on DISPLAY :99 (no X server answers on {x11_dir}/X99)"
    with pytest.raises(window.RenderError, match=r"DISPLAY :99 .*; do this instead$"):
        window.require_display("do this instead")


def test_display_with_a_listening_unix_socket(x11_dir, monkeypatch):
    server = listening(socket.AF_UNIX, f"{x11_dir}/X5")
    for value in (":5", ":5.0", "unix:5.1"):
        monkeypatch.setenv("DISPLAY", value)
        assert window.has_display(), value
        window.require_display("unused")
    monkeypatch.setenv("DISPLAY", ":6")                  # another display number
    assert not window.has_display()
    server.close()                                       # a stale socket file is no server
    monkeypatch.setenv("DISPLAY", ":5")
    assert "no X server answers" in window.display_problem()


def test_display_on_another_host_over_tcp(x11_dir, monkeypatch):
    server = listening(socket.AF_INET, ("127.0.0.1", 0))
    port = server.getsockname()[1]
    monkeypatch.setattr(window, "X11_TCP_PORT", port - 10)
    monkeypatch.setenv("DISPLAY", "127.0.0.1:10.0")      # as ssh -X sets it: localhost:10.0
    assert window.has_display()
    server.close()
    assert window.display_problem() == ("cannot open a window on DISPLAY 127.0.0.1:10.0 "
                                        f"(no X server answers at 127.0.0.1:{port})")


def test_no_display_or_a_malformed_one(x11_dir, monkeypatch):
    monkeypatch.delenv("DISPLAY", raising=False)
    assert window.display_problem() == "no display (DISPLAY unset)"
    monkeypatch.setenv("WAYLAND_DISPLAY", "wayland-0")   # GLFW here has no Wayland: X needed
    assert "XWayland" in window.display_problem()
    monkeypatch.setenv("DISPLAY", "screen")
    assert window.display_problem().endswith("(not of the form [HOST]:N[.S])")
