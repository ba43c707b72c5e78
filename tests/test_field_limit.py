"""Taichi 1.7.4 indexes a field's entries with 32-bit integers, and a field of 2^31 entries or
more crashed it (core/step.py, FIELD_ENTRIES_MAX). A simulator refuses a capacity that would
need one, and a preset whose scene would be that large is refused on its l0 key, both before
any kernel runs."""
import json

import numpy as np
import pytest
import taichi as ti

from crowndemo import config
from crowndemo.config import PresetError
from crowndemo.core import ParameterError, Simulator
from crowndemo.core.step import (CELLS_PER_PARTICLE_MIN, FIELD_ENTRIES_MAX, Model,
                                 default_max_cells, entries_per_particle, max_particles)


def _fields(root):
    """Every Taichi field reachable from ``root`` through crowndemo objects' attributes."""
    seen, found, todo = set(), {}, [root]
    while todo:
        obj = todo.pop()
        if id(obj) in seen:
            continue
        seen.add(id(obj))
        if isinstance(obj, ti.Field):
            found[id(obj)] = obj
        elif isinstance(obj, dict):
            todo.extend(obj.values())
        elif isinstance(obj, (list, tuple)):
            todo.extend(obj)
        elif type(obj).__module__.startswith("crowndemo") and hasattr(obj, "__dict__"):
            todo.extend(vars(obj).values())
    return list(found.values())


@pytest.mark.parametrize("preset", ["quick", "quick-2d"])
def test_no_field_holds_more_entries_per_particle_than_the_limit_allows(preset):
    scene = config.load(preset, "draft").build_scene()
    sim = Simulator(scene.physics, scene.numerics, len(scene.pos))
    cap, m = sim.state.capacity, entries_per_particle(sim.model)
    cells = {id(sim.grid.cell_count), id(sim.grid.cell_start)}
    fields = _fields(sim)
    entries = [int(np.prod(f.shape)) for f in fields if id(f) not in cells]
    assert len(entries) > 30                            # the walk found the simulator's fields
    assert max(entries) <= m * cap + 1                  # so at max_particles: < 2^31 entries
    assert max(entries) >= m * cap                      # and the bound is the tight one
    assert (max_particles(sim.model) * m + 1) <= FIELD_ENTRIES_MAX
    # the cells: as many as default_max_cells gives, which is capped at the limit itself and
    # holds CELLS_PER_PARTICLE_MIN (<= m) a particle even at max_particles
    assert sim.grid.max_cells == default_max_cells(cap)
    assert default_max_cells(max_particles(sim.model)) + 1 <= FIELD_ENTRIES_MAX
    assert default_max_cells(max_particles(sim.model)) >= (
        CELLS_PER_PARTICLE_MIN * max_particles(sim.model))


def test_simulator_refuses_a_capacity_past_the_limit_before_allocating():
    scene = config.load("quick", "draft").build_scene()
    limit = max_particles(Model.of(scene.physics, scene.numerics))
    with pytest.raises(ParameterError) as e:
        Simulator(scene.physics, scene.numerics, limit + 1)
    assert e.value.key == "particles" and f"at most {limit:,}" in str(e.value)


def test_preset_too_fine_for_one_simulator_is_refused_on_its_l0_key():
    r = config.load("quick", "draft", ["quality.draft.l0=4e-4"])
    limit = max_particles(r.model)
    r.check_size(limit)                                 # at the limit: fine
    with pytest.raises(PresetError) as e:
        r.check_size(limit + 1000)
    err = e.value
    assert err.source == "--set" and err.key == "quality.draft.l0" and err.value == 4e-4
    # the allowed l0 gives at most the limit: particles scale as l0^-3
    need = float(err.allowed.split(">=")[1].split()[0])
    assert need > 4e-4 and (limit + 1000) * (4e-4 / need) ** 3 <= limit


# the seed rung as the whole scene with the default trim (it simulates a trimmed quarter)
WHOLE = ("quality.seed.symmetry=full", "quality.seed.trim_reach=2")


def test_preset_far_too_fine_is_refused_before_its_scene_is_built():
    # the whole thick layer at l0 = 40 um (the seed rung simulates a quarter; here the whole):
    # ~370 M particles, which numpy would take minutes to build
    r = config.load("thick-layer", "seed", ["quality.seed.l0=4e-5", *WHOLE])
    with pytest.raises(PresetError, match=r"about [\d,]+ particles") as e:
        r.build_scene()
    assert e.value.key == "quality.seed.l0"


def test_info_says_when_a_preset_is_too_large(capsys):
    # the whole thick layer at l0 = 70 um to its seed rung's 3 ms: ~51M particles (info)
    from crowndemo.cli import main
    assert main(["info", "thick-layer", "--quality", "seed", "--set",
                 "quality.seed.l0=7e-5", *(a for w in WHOLE for a in ("--set", w))]) == 0
    out = capsys.readouterr().out
    assert "too many" in out and "a run would be refused" in out
    assert main(["info", "thick-layer", "--quality", "seed", "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert d["particles"]["total"] < d["max_particles"]          # the seed quality fits
