"""The rendering options' ranges: a bad --fps or --orbit is one line and exit 2 at parse
time, before Taichi starts or a recording folder is made."""
import argparse

import pytest

from crowndemo.cli import main
from crowndemo.render.options import FPS_RANGE, ORBIT_RANGE, add_render_options, bounded


@pytest.fixture
def no_backend(monkeypatch):
    def refuse(args):
        raise AssertionError("Taichi started before the options were checked")
    monkeypatch.setattr("crowndemo.cli.record.start_backend", refuse)


@pytest.mark.parametrize("option, value, allowed", [
    ("--fps", "inf", "0.1 to 240"), ("--fps", "nan", "0.1 to 240"),
    ("--fps", "0.001", "0.1 to 240"), ("--fps", "0", "0.1 to 240"),
    ("--fps", "-12", "0.1 to 240"), ("--fps", "1e6", "0.1 to 240"),
    ("--fps", "twelve", "0.1 to 240"),
    ("--orbit", "nan", "-180 to 180"), ("--orbit", "inf", "-180 to 180"),
    ("--orbit", "-inf", "-180 to 180"), ("--orbit", "181", "-180 to 180"),
    ("--orbit", "-1e9", "-180 to 180"),
])
def test_bad_value_exit_2_before_taichi(option, value, allowed, tmp_path, capsys, no_backend):
    # OPTION=VALUE: argparse takes a lone "-inf" for an option, not for --orbit's value
    argv = ["record", "quick-2d", "--recordings", str(tmp_path / "rec"), f"{option}={value}"]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"crowndemo: error: argument {option}: ") and allowed in err
    assert "Traceback" not in err and len(err.strip().splitlines()) == 1
    assert not (tmp_path / "rec").exists()


@pytest.mark.parametrize("option, value", [("--orbit", "-inf"), ("--fps", "-1e3")])
def test_dash_value_written_with_a_space_says_to_use_equals(option, value, tmp_path, capsys,
                                                             no_backend):
    # argparse reads "-inf" / "-1e3" as an option: --orbit (value optional) leaves it over,
    # --fps (value needed) finds none; either way the line says how to write it
    argv = ["record", "quick-2d", "--recordings", str(tmp_path / "rec"), option, value]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert f"goes after '=': {option}={value}" in err and len(err.strip().splitlines()) == 1
    assert not (tmp_path / "rec").exists()


def test_unknown_option_gets_no_value_hint(tmp_path, capsys, no_backend):
    assert main(["record", "quick-2d", "--recordings", str(tmp_path / "rec"), "--bogus"]) == 2
    err = capsys.readouterr().err
    assert "unrecognized arguments: --bogus" in err and "'='" not in err


def test_values_in_range_are_taken():
    p = argparse.ArgumentParser()
    add_render_options(p)
    lo, hi = FPS_RANGE
    assert p.parse_args(["--fps", str(lo)]).fps == lo and p.parse_args(["--fps", "240"]).fps == hi
    assert p.parse_args(["--orbit"]).orbit == 1.0 and p.parse_args([]).orbit == 0.0
    assert p.parse_args(["--orbit", "-180"]).orbit == ORBIT_RANGE[0]
    assert p.parse_args(["--orbit", "2.5"]).orbit == 2.5


def test_bounded_refuses_what_is_outside():
    parse = bounded(0.1, 240, "frames per second")
    assert parse("12") == 12.0
    for text in ("0.0999", "240.5", "nan", "inf", "", "1,5"):
        with pytest.raises(argparse.ArgumentTypeError, match="0.1 to 240"):
            parse(text)
