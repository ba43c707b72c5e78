"""The backend choice (crowndemo.backend): ``auto`` never lands on Mesa's software Vulkan;
``--fast-compile`` turns Taichi's advanced IR optimisations off on the CPU arch only
(BENCHMARKS.md, "Compiling" and "The walk's rows in a loop": the 3D crown step compiles in
a fraction of the time)."""
import pytest
import taichi as ti
from taichi.lang.misc import is_arch_supported

from crowndemo import backend
from crowndemo.cli import main


def advanced() -> bool:
    return bool(ti.lang.impl.current_cfg().advanced_optimization)


def test_auto_is_cuda_or_the_cpu():
    try:
        b = backend.init("auto")
        if is_arch_supported(ti.cuda):
            assert b.resolved == "cuda"
        else:        # even where a (software) Vulkan device works, as on the CI machine
            assert b.resolved in ("x64", "arm64")
    finally:
        backend.init("cpu")


def test_fast_compile_on_the_cpu_only(monkeypatch):
    monkeypatch.delenv("CROWNDEMO_FAST_COMPILE", raising=False)
    try:
        assert backend.init("cpu").fast_compile is False and advanced()
        assert not backend.fast_compiling()       # the grid walk unrolls its rows
        assert backend.init("cpu", fast_compile=True).fast_compile and not advanced()
        assert backend.fast_compiling()           # and loops over them (core/grid.py)
        monkeypatch.setenv("CROWNDEMO_FAST_COMPILE", "1")
        assert backend.init("cpu").fast_compile and not advanced()
        try:
            backend.init("vulkan", fast_compile=True)
        except backend.BackendError:
            pass                          # no Vulkan device here
        else:
            assert advanced()             # other archs keep Taichi's optimisations
            assert not backend.fast_compiling()
    finally:
        monkeypatch.delenv("CROWNDEMO_FAST_COMPILE", raising=False)
        backend.init("cpu")


def test_the_bench_says_how_it_compiled(capsys, monkeypatch):
    monkeypatch.delenv("CROWNDEMO_FAST_COMPILE", raising=False)
    try:
        assert main(["bench", "--n", "500", "--steps", "1", "--fast-compile",
                     "--no-stages"]) == 0
        assert "f32 fast-compile" in capsys.readouterr().out
    finally:
        backend.init("cpu")


def test_the_bench_says_where_the_neighbour_list_is_not_stored_as_by_default():
    from crowndemo.bench.tables import _build
    run = {"precision": "f32", "single_thread": False, "fast_compile": False}
    assert _build({**run, "list_layout": "particle"}) == "f32"
    assert _build({**run, "list_layout": None}) == "f32"          # no list
    assert _build({**run, "list_layout": "slot"}) == "f32 slot-list"


def test_a_recorded_slot_list_run_names_the_variable_that_repeats_it():
    from crowndemo.cli.bench import recorded_command
    argv = ["bench", "--n", "12000000", "--record"]
    assert recorded_command(argv, [{"list_layout": "particle"}]) == \
        "crowndemo bench --n 12000000 --record"
    assert recorded_command(argv, [{"list_layout": None}]) == \
        "crowndemo bench --n 12000000 --record"
    assert recorded_command(argv, [{"list_layout": "slot"}]) == \
        "CROWNDEMO_LIST_LAYOUT=slot crowndemo bench --n 12000000 --record"
    assert recorded_command(["bench", "--set", "a b"], [{}]) == "crowndemo bench --set 'a b'"


@pytest.mark.parametrize("value, on", [("1", True), ("yes", True), ("True", True), ("on", True),
                                       ("", False), ("0", False), ("no", False), ("off", False)])
def test_the_fast_compile_variable_reads_the_usual_words(monkeypatch, value, on):
    monkeypatch.setenv("CROWNDEMO_FAST_COMPILE", value)
    assert backend._switch("CROWNDEMO_FAST_COMPILE") is on


def test_another_fast_compile_value_is_an_error_not_off(monkeypatch):
    monkeypatch.setenv("CROWNDEMO_FAST_COMPILE", "maybe")
    with pytest.raises(backend.BackendError, match="CROWNDEMO_FAST_COMPILE = 'maybe'"):
        backend._switch("CROWNDEMO_FAST_COMPILE")
