"""The booth loop: `crowndemo play --headless` over recordings made here from a few frames."""
import json
import os
import shutil

import numpy as np
import pytest

from crowndemo.cli import main
from crowndemo.cli import play as play_cli
from crowndemo.render import player, window
from crowndemo.render.video import encode_mp4, read_video, write_png

SIZE = (64, 36)
FPS = 10.0
CARD_SECONDS = 0.3                 # 3 frames at 10 fps


def make_recording(root, name, colour, n, status="complete", title=None):
    """A recording folder as the recorder leaves it: frames, a video, metadata.json."""
    d = root / name
    (d / "frames").mkdir(parents=True)
    frame = np.zeros((SIZE[1], SIZE[0], 3), np.uint8) + np.array(colour, np.uint8)
    for i in range(n):
        write_png(frame, str(d / "frames" / f"frame_{i:05d}.png"))
    suffix = "" if status == "complete" else ".partial"
    encode_mp4([frame] * n, str(d / f"video{suffix}.mp4"), FPS)
    (d / "metadata.json").write_text(json.dumps({
        "status": status, "complete": status == "complete", "preset": name,
        "title": title or {"en": f"Recording {name}", "ja": f"記録 {name}"},
        "description": {"en": "a test recording", "ja": "試験用の記録"}}))
    return d


@pytest.fixture
def recordings(tmp_path):
    root = tmp_path / "recordings"
    make_recording(root, "red", (220, 30, 30), 3)
    make_recording(root, "green", (30, 220, 30), 2)
    make_recording(root, "broken", (30, 30, 220), 4, status="interrupted")
    return root


def play(root, out, *extra):
    return main(["play", "--headless", "--out", str(out), "--recordings", str(root),
                 "--fps", str(FPS), "--card-seconds", str(CARD_SECONDS), "--resolution",
                 "%dx%d" % SIZE, *extra])


def is_colour(img, colour):
    return np.abs(img.astype(int) - np.array(colour)).mean() < 25


def test_play_headless_two_loops(recordings, tmp_path, capsys):
    out = tmp_path / "reel.mp4"
    assert play(recordings, out, "red", "green", "--loops", "2") == 0
    frames = list(read_video(str(out)))
    card = round(CARD_SECONDS * FPS)
    one_loop = (card + 3) + (card + 2)
    assert len(frames) == 2 * one_loop
    for start in (0, one_loop):
        cards = frames[start:start + card] + frames[start + card + 3:start + 2 * card + 3]
        assert all(not is_colour(f, (220, 30, 30)) and not is_colour(f, (30, 220, 30))
                   for f in cards)
        assert all(is_colour(f, (220, 30, 30)) for f in frames[start + card:start + card + 3])
        assert all(is_colour(f, (30, 220, 30)) for f in frames[start + 2 * card + 3:
                                                               start + one_loop])


def test_incomplete_recordings_are_skipped_unless_partial(recordings, tmp_path, capsys):
    out = tmp_path / "all.mp4"
    card = round(CARD_SECONDS * FPS)
    assert play(recordings, out) == 0               # every recording, one loop
    assert "broken is incomplete; skipping" in capsys.readouterr().err
    assert len(list(read_video(str(out)))) == (card + 2) + (card + 3)   # green, red
    assert play(recordings, out, "--partial") == 0
    frames = list(read_video(str(out)))
    assert len(frames) == (card + 4) + (card + 2) + (card + 3)       # broken, green, red
    # its frames carry the marker: not the plain recorded colour everywhere
    marked = frames[card:card + 4]
    corner = marked[0][-8:, -20:].astype(int)
    assert np.abs(corner - np.array([30, 30, 220])).mean() > 40


def test_completeness_without_metadata(tmp_path):
    d = make_recording(tmp_path, "bare", (200, 200, 200), 2)
    (d / "metadata.json").unlink()
    assert player.open_recording(str(d)).complete           # video.mp4 is there
    (d / "video.mp4").unlink()
    assert not player.open_recording(str(d)).complete


def test_damaged_metadata_is_named(tmp_path):
    """A metadata.json that is not a recording's (a JSON list, or not JSON) is an error that
    names the file, not a recording silently taken as one without metadata."""
    d = make_recording(tmp_path, "damaged", (200, 200, 200), 2)
    for text in ("[1, 2]", "{not json"):
        (d / "metadata.json").write_text(text)
        with pytest.raises(player.PlayError, match="metadata.json: cannot read"):
            player.open_recording(str(d))


def test_play_errors(recordings, tmp_path):
    assert play(recordings, tmp_path / "x.mp4", "nosuch") == 2
    assert play(recordings, tmp_path / "x.mp4", "broken") == 2      # only incomplete ones
    assert main(["play", "--headless", "--recordings", str(recordings)]) == 2   # no --out
    # --out without --headless would be ignored by the window: refused
    assert main(["play", "--out", str(tmp_path / "x.mp4"), "--recordings", str(recordings)]) == 2
    assert not (tmp_path / "x.mp4").exists()


@pytest.mark.parametrize("name", ["r.txt", "reel", "reel.gif"])
def test_out_must_be_an_mp4_file(tmp_path, capsys, name):
    """Checked first: even before finding that there are no recordings."""
    out = tmp_path / name
    assert play(tmp_path / "none", out) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"crowndemo: error: --out {out}: ") and "ending in .mp4" in err
    assert err.count("\n") == 1 and not out.exists()


def test_out_in_a_folder_that_cannot_be_made(recordings, tmp_path, capsys):
    blocker = tmp_path / "file"
    blocker.write_text("")
    assert play(recordings, blocker / "reel.mp4") == 2
    assert f"--out {blocker / 'reel.mp4'}: cannot write into {blocker}" in \
        capsys.readouterr().err
    assert play(recordings, tmp_path / "new" / "sub" / "reel.mp4") == 0   # made when missing


def test_recordings_default_follows_the_environment(recordings, tmp_path, monkeypatch,
                                                   capsys):
    """As record: --recordings, else $CROWNDEMO_RECORDINGS, else ./recordings."""
    def play_default(out):
        return main(["play", "--headless", "--out", str(out), "--resolution", "%dx%d" % SIZE,
                     "--fps", str(FPS), "--card-seconds", "0"])
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    monkeypatch.chdir(elsewhere)                       # no ./recordings here
    monkeypatch.setenv("CROWNDEMO_RECORDINGS", str(recordings))
    assert play_default(tmp_path / "env.mp4") == 0
    assert len(list(read_video(str(tmp_path / "env.mp4")))) == 2 + 3     # green, red
    monkeypatch.delenv("CROWNDEMO_RECORDINGS")
    assert play_default(tmp_path / "none.mp4") == 2
    assert "no recordings in recordings/" in capsys.readouterr().err
    monkeypatch.chdir(tmp_path)                        # ./recordings is the fixture's
    assert play_default(tmp_path / "cwd.mp4") == 0


def test_help_names_the_recordings_default(capsys):
    assert main(["play", "--help"]) == 0
    help_text = " ".join(capsys.readouterr().out.split())
    assert "--recordings DIR the folder of recordings (default: $CROWNDEMO_RECORDINGS, " \
           "else ./recordings)" in help_text


def test_window_needs_an_x_server(recordings, tmp_path, monkeypatch, capsys):
    """DISPLAY set but no server (ssh without X forwarding): an error before GLFW or Taichi."""
    monkeypatch.setattr(window, "X11_SOCKET_DIR", str(tmp_path / "no-x11"))
    monkeypatch.setenv("DISPLAY", ":99")
    monkeypatch.setattr(play_cli, "start_backend", lambda args: pytest.fail("backend started"))
    monkeypatch.setattr(player, "play_in_window", lambda *a: pytest.fail("window opened"))
    assert main(["play", "--recordings", str(recordings)]) == 2
    err = capsys.readouterr().err
    assert "crowndemo: error: cannot open a window on DISPLAY :99 (no X server answers" in err
    assert err.rstrip().endswith("use --headless --out FILE.mp4 to play into a video file")


@pytest.mark.parametrize("option, value, allowed", [
    ("--fps", "nan", "from 0.1 to 240"), ("--fps", "inf", "from 0.1 to 240"),
    ("--fps", "1e-9", "from 0.1 to 240"), ("--fps", "0", "from 0.1 to 240"),
    ("--fps", "1000", "from 0.1 to 240"), ("--card-seconds", "nan", "from 0 to 60"),
    ("--card-seconds", "inf", "from 0 to 60"), ("--card-seconds", "-1", "from 0 to 60"),
    ("--card-seconds", "61", "from 0 to 60")])
def test_fps_and_card_seconds_out_of_range(recordings, tmp_path, capsys, option, value,
                                           allowed):
    """Refused when parsed, with the range: not a traceback from round() or ffmpeg after the
    recordings are read (NaN, inf, a rate ffmpeg cannot write), nor a reel of 1000 fps."""
    out = tmp_path / "reel.mp4"
    assert play(recordings, out, f"{option}={value}") == 2
    err = capsys.readouterr().err
    assert err.startswith(f"crowndemo: error: argument {option}: '{value}': allowed: a number "
                          f"{allowed} (") and err.count("\n") == 1
    assert not out.exists()


def test_fps_and_card_seconds_at_the_ends_of_their_ranges(recordings, tmp_path):
    out = tmp_path / "reel.mp4"
    assert play(recordings, out, "red", "--fps", "0.1", "--card-seconds", "0") == 0
    assert len(list(read_video(str(out)))) == 3                    # no title card
    assert play(recordings, out, "green", "--fps", "240", "--card-seconds", "0.05") == 0
    assert len(list(read_video(str(out)))) == 12 + 2               # 0.05 s at 240 fps


def test_help_gives_the_ranges(capsys):
    assert main(["play", "--help"]) == 0
    help_text = " ".join(capsys.readouterr().out.split())
    assert "--fps FPS frames per second, 0.1 to 240 (default: 12)" in help_text
    assert "how long each title card shows, 0 to 60 seconds; 0: no cards (default: 3)" \
        in help_text


def test_out_may_not_be_a_recordings_own_video(recordings, tmp_path, capsys):
    """The reel written over a recording's video would replace the recording (played from its
    frames, or played next time as that recording): refused, whether played or not."""
    red, broken = recordings / "red", recordings / "broken"
    (red / "reel.mp4").symlink_to(red / "video.mp4")
    before = {p: p.read_bytes() for p in (red / "video.mp4", broken / "video.partial.mp4")}
    (recordings / "green" / "video.mp4").unlink()                   # --no-video: frames only
    for out, shown in [(red / "video.mp4", red), (red / "frames" / ".." / "video.mp4", red),
                       (red / "reel.mp4", red), (broken / "video.partial.mp4", broken),
                       (recordings / "green" / "video.mp4", recordings / "green")]:
        for names in ([], ["red"]):
            assert play(recordings, out, *names) == 2
            err = capsys.readouterr().err
            assert err == f"crowndemo: error: --out {out}: is the recording {shown}'s own " \
                          f"video ({os.path.basename(os.path.realpath(out))}): the reel " \
                          "would replace it; give a file outside the recordings' folders\n"
    assert {p: p.read_bytes() for p in before} == before
    assert not (recordings / "green" / "video.mp4").exists()
    (red / "reel.mp4").unlink()
    assert play(recordings, red / "reel.mp4", "red") == 0          # another name is fine
    # a video*.mp4 in a new folder of the recordings would be played next time as a recording
    new = recordings / "reel" / "video.mp4"
    assert play(recordings, new, "red") == 2
    err = capsys.readouterr().err
    assert "would be played next time as a recording named reel" in err
    assert not new.parent.exists()


def make_frameless(root, name):
    """A recording made with --no-render: metadata.json (and snapshots), no frames or video."""
    d = make_recording(root, name, (0, 0, 0), 1)
    shutil.rmtree(d / "frames")
    (d / "video.mp4").unlink()
    return d


def test_recordings_without_frames(recordings, tmp_path, monkeypatch, capsys):
    only = tmp_path / "dry"
    make_frameless(only, "drop")
    make_frameless(only, "splash")
    assert play(only, tmp_path / "x.mp4") == 2
    err = capsys.readouterr().err
    assert err == f"crowndemo: error: the recordings in {only}/ (drop, splash) have no frames " \
                  "(recorded with --no-render); record one again without --no-render to " \
                  f"play it, e.g. 'crowndemo record drop --recordings {only}' (with the " \
                  "--quality and --set it was made with)\n"
    monkeypatch.setenv("CROWNDEMO_RECORDINGS", str(only))          # the default: no option
    assert main(["play", "--headless", "--out", str(tmp_path / "x.mp4")]) == 2
    assert "e.g. 'crowndemo record drop' (with" in capsys.readouterr().err
    assert play(only, tmp_path / "x.mp4", "drop") == 2             # named
    assert f"{only / 'drop'}: no frames (recorded with --no-render); record it again " \
           "without --no-render to play it\n" in capsys.readouterr().err
    # beside recordings that play: skipped with a warning, as an incomplete one is
    make_frameless(recordings, "dry")
    out = tmp_path / "reel.mp4"
    assert play(recordings, out) == 0
    err = capsys.readouterr().err
    assert "crowndemo: warning: recording dry has no frames (recorded with --no-render); " \
           "skipping it (record it again without --no-render to play it)\n" in err
    assert "broken is incomplete; skipping" in err
    card = round(CARD_SECONDS * FPS)
    assert len(list(read_video(str(out)))) == (card + 2) + (card + 3)   # green, red
    assert play(recordings, recordings / "dry" / "video.mp4") == 2     # would make it play
    assert not (recordings / "dry" / "video.mp4").exists()


def test_misspelt_recording_name_suggests_the_closest(recordings, tmp_path, capsys):
    assert play(recordings, tmp_path / "reel.mp4", "gren") == 2
    err = capsys.readouterr().err
    assert "no recording 'gren'" in err and "(did you mean 'green'?)" in err


def test_summary_line_uses_singular_for_one(recordings, tmp_path, capsys):
    assert play(recordings, tmp_path / "one.mp4", "red", "--loops", "1") == 0
    assert "(1 recording x 1 loop)" in capsys.readouterr().err
    assert play(recordings, tmp_path / "two.mp4", "red", "green", "--loops", "2") == 0
    assert "(2 recordings x 2 loops)" in capsys.readouterr().err
