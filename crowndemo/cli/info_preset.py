"""``crowndemo info PRESET``: every resolved value of a preset at one quality, with its
source, derived numbers, particles, memory, steps and run time (host computation only)."""
from __future__ import annotations

import math
import shlex
from typing import Dict

from .. import strictjson
from ..core.params import SOUND_SPEED_FACTOR, VISCOUS_STIFFNESS
from .common import load_preset


SURFACE_TENSION_WHAT = {
    "potential": "the seed's inter-particle potential (S22-S24, Kondo et al. 2007)",
    "stress": "the continuum surface stress, div of sigma (|g| I - g g^T/|g|) (method.md §4c)",
    "curvature": "P = sigma kappa on the free surface (method.md §4b; experimental)",
}


def surface_tension_summary(model: str, lat, sigma: float, pairs: str = "all") -> dict:
    """The preset's surface-tension member and its constants (the lattice's, S23 or C1-C3;
    the neighbourhood's C3 pair support H, C4 factor F and C5's delta and lag where delta is
    not 0; with C3's surface pairs their band B and a's factor, the lattice face's times the
    measured one)."""
    what = SURFACE_TENSION_WHAT[model]
    if model == "potential":
        constants = {"C": lat.C}
    elif model == "stress":
        from ..core.lattice import stress_constants, stress_pairs_scale
        from ..core.params import STRESS_SURFACE_BAND, STRESS_TOLMAN_LAG, stress_pair_support
        ratio = lat.re / lat.l0
        factor, delta = stress_constants(lat.dim, ratio, pairs)
        constants = {"a": lat.stress_a, "K_1_m2": lat.stress_K, "K_d_1_m2": lat.stress_Kd,
                     "H_l0": stress_pair_support(lat.dim, ratio), "F": factor}
        if pairs == "surface":    # C3b (method.md §4c)
            from ..core.params import stress_surface_pairs
            what += ", C3's pairs weighted by the surface band (C3b" + (
                ", torque-free)" if stress_surface_pairs(ratio)["torque_free"][lat.dim]
                else ")")
            constants["band_B"] = STRESS_SURFACE_BAND
            constants["a_factor"] = stress_pairs_scale(lat.dim, ratio, pairs)
        if delta > 0:      # C5's curvature correction (3D; 2D at 3.1 l0)
            constants["delta_l0"] = delta
            constants["lag_capillary_times"] = STRESS_TOLMAN_LAG
    else:
        constants = {}
    return {"model": model, "what": what, "sigma_N_m": sigma, "constants": constants}


def _preset_facts(r, tp) -> Dict:
    """Every resolved value and derived quantity of a preset at one quality (no kernels)."""
    from dataclasses import asdict

    from ..config import estimate
    from ..core.lattice import LatticeConstants
    from ..core.params import Model
    from ..core.step import max_particles
    from ..record.recorder import frame_times
    from ..scenes.crown import crown_base_radius
    from ..validate.verdicts import cossali

    ph, s, liq = r.physics, r.scene, r.liquid
    lat = LatticeConstants.compute(ph.dim, ph.l0, ph.re_ratio, ph.rho, ph.sigma)
    est = estimate.summary(r, tp)
    lim, dt = est["limits_s"], est["dt_s"]
    ties = [k for k, v in lim.items() if v <= dt * (1 + 1e-9)]
    U, D, h = s["speed"], s["drop"], s["film"]
    splash = cossali(U, D, h, liq["rho"], liq["nu"], liq["sigma"])
    re_num = U * D / liq["nu"] if liq["nu"] > 0 else math.inf
    impact = s["gap"] / U
    numerics = {key: (None if isinstance(v, float) and math.isinf(v) else v)
                for key, v in asdict(r.numerics).items() if key != "allow_unsafe_dt"}
    return {
        "preset": r.name, "file": r.label, "extends_chain": r.doc.files,
        "quality": r.quality,
        "title": r.title, "description": r.description, "dim": r.dim,
        "scene": {"floor_m": s["floor"], "film_m": h, "drop_m": D, "speed_m_s": U,
                  "height_m": s.get("height"), "gap_m": s["gap"],
                  "gravity_m_s2": s["gravity"], "t_end_s": s["t_end"],
                  "frame_interval_s": s.get("frame_interval"), "frames": len(frame_times(r)),
                  "trim": s["trim"], "impact_at_s": impact},
        "sources": {k: {"key": key, "file": src} for k, (key, src) in sorted(r.where.items())},
        "liquid": {"name": liq["name"], "rho_kg_m3": liq["rho"], "nu_m2_s": liq["nu"],
                   "sigma_N_m": liq["sigma"]},
        "l0_m": ph.l0, "re_ratio": ph.re_ratio, "re_m": lat.re, "drop_over_l0": D / ph.l0,
        "film_over_l0": h / ph.l0, "n0": lat.n0, "lambda0": lat.lambda0,
        "lambda0_over_l0_sq": lat.lambda0 / lat.l0 ** 2, "C": lat.C, "mass": lat.mass,
        "mass_unit": "kg" if ph.dim == 3 else "kg/m (per unit depth)",
        "surface_tension": surface_tension_summary(r.numerics.surface_tension, lat, ph.sigma,
                                                  r.numerics.stress_pairs),
        "sound_speed_m_s": ph.c,
        "sound_speed_source": s.get("sound_speed_source") or (
            "given" if s.get("sound_speed") is not None else f"{SOUND_SPEED_FACTOR:g} x speed"),
        "numerics": numerics, "model": Model.describe(r.model),
        "limits_s": {key: lim.get(key) for key in ("courant", "approach", "acoustic",
                                                    "viscous", "capillary", "dt_max")
                     if key not in ("dt_max", "approach") or key in lim},
        "dt_s": dt, "binding": est["binding"], "binding_ties": ties,
        "particles": est["particles"], "memory_bytes": est["memory_bytes"],
        "max_particles": max_particles(r.model),
        "steps": est["steps"], "steps_at_U": est["steps_at_U"],
        "splash_speed_m_s": est["splash_speed_m_s"],
        "relative_speed_m_s": est["relative_speed_m_s"],
        "dt_after_contact_s": est["dt_after_contact_s"],
        "binding_after_contact": est["binding_after_contact"],
        "run_seconds_estimate": est["run_seconds"],
        "run_seconds_at_U": est["run_seconds_at_U"],
        "compile_seconds": est["compile_seconds"],
        "crown_cost": {"before_contact": est["crown_cost_calm"],
                       "after_contact": est["crown_cost_splash"],
                       "wall_or_dummy": estimate.WALL_COST,
                       "surface_tension_model": est["surface_tension_cost"]},
        "throughput": {"fluid_particle_steps_per_s": tp.rate,
                       "all_particle_steps_per_s": tp.rate_total,
                       "bytes_per_particle": tp.bytes_per_particle, "source": tp.source},
        "dimensionless": {"weber": splash["We"], "reynolds": re_num, "ohnesorge": splash["Oh"],
                          "cossali_K": splash["K"], "cossali_K_splash": splash["K_threshold"],
                          "splash_predicted": splash["splash"],
                          "crown_base_radius_at_t_end_m":
                              crown_base_radius(s["t_end"] - impact, U, D, h)},
        "left_out": est["particles"]["left_out"],
    }


def _model_cost(r, cost: dict) -> str:
    """', the stress model's passes included (3.11 x the potential's)' where the member
    costs other than the seed's potential (estimate.SURFACE_TENSION_COST), else ''."""
    if cost["surface_tension_model"] == 1.0:
        return ""
    return (f", the {r.model.surface_tension_model} model's passes included "
            f"({cost['surface_tension_model']:g} x the potential's)")


def _neighbourhood_cost(r) -> str:
    """'; ...' where re is not the seed's 2.1 l0, at which every cost of the estimate was
    measured: a wider neighbourhood walks more pairs (the lattice's count within re)."""
    from ..core.lattice import lattice_offsets
    from ..core.params import Physics
    re_ratio, seed_ratio = r.physics.re_ratio, Physics.re_ratio
    if abs(re_ratio - seed_ratio) < 1e-9:
        return ""
    seed, own = (len(lattice_offsets(r.dim, 1.0, x)) for x in (seed_ratio, re_ratio))
    return (f"; the costs are measured at re = {seed_ratio:g} l0, where a particle has {seed} "
            f"lattice neighbours against {own} at {re_ratio:g} l0, so this run takes "
            f"{'longer' if own > seed else 'less'}")


def _speed_in_c(v: float, c: float, U: float) -> str:
    """'32 m/s = 4 U = 0.4 c': a speed and its ratios to the impact speed U and to the sound
    speed c."""
    return f"{v:.3g} m/s = {v / U:.2g} U = {v / c:.2g} c"


def _mm(x: float) -> str:
    return f"{x * 1e3:.4g} mm"


def info_preset(args) -> int:
    """``crowndemo info PRESET``: every resolved value of a preset at one quality."""
    import textwrap

    from ..config import estimate

    r = load_preset(args.preset, args)
    tp = estimate.throughput()
    f = _preset_facts(r, tp)
    f["overrides"] = list(args.sets)
    if args.json:
        print(strictjson.dumps(f))
        return 0
    s, liq, p = f["scene"], f["liquid"], f["particles"]
    src = {k: v["key"] for k, v in f["sources"].items()}
    lang = "en"
    print(f"preset {r.name}, quality {r.quality} ({r.label}): {r.dim}D")
    if len(f["extends_chain"]) > 1:
        print(f"  extends     {' <- '.join(reversed(f['extends_chain']))}")
    if f["overrides"]:
        print("  overrides   " + " ".join("--set " + shlex.quote(o) for o in f["overrides"]))
    print(f"  title       {f['title'].get(lang, '')}")
    if f["description"].get(lang):
        for i, line in enumerate(textwrap.wrap(f["description"][lang], 82)):
            print(f"  {'about' if i == 0 else '':<11} {line}")
    speed = (f"U = {s['speed_m_s']:.4g} m/s = sqrt(2 g H), H = {s['height_m']:g} m"
             if s["height_m"] is not None else f"U = {s['speed_m_s']:.4g} m/s")
    floor = "square floor" if r.dim == 3 else "wide slice"
    print(f"  scene       {_mm(s['floor_m'])} {floor}, film h = {_mm(s['film_m'])}, drop D = "
          f"{_mm(s['drop_m'])}, gap {_mm(s['gap_m'])}")
    print(f"              {speed} ({src['speed']}); contact at t = {s['impact_at_s'] * 1e3:.4g} ms")
    # as `record` writes them: t = 0 and every frame interval to t_end (record/recorder.py)
    frames = (f"; {s['frames']} frames, every {s['frame_interval_s'] * 1e3:g} ms from t = 0"
              if s["frame_interval_s"] else "; 1 frame (t = 0; no frame_interval)")
    print(f"              t_end = {s['t_end_s'] * 1e3:g} ms ({src['t_end']}){frames}")
    print(f"  liquid      {liq['name']}: rho {liq['rho_kg_m3']:g} kg/m^3, nu {liq['nu_m2_s']:g} "
          f"m^2/s, sigma {liq['sigma_N_m']:g} N/m; gravity {s['gravity_m_s2']:g} m/s^2")
    dl = f["dimensionless"]
    verdict = "a splash" if dl["splash_predicted"] else "no splash"
    print(f"  numbers     We = {dl['weber']:,.0f}, Re = {dl['reynolds']:,.0f}, Oh = "
          f"{dl['ohnesorge']:.3g}; Cossali K = We Oh^-0.4 = {dl['cossali_K']:.3g} against "
          f"{dl['cossali_K_splash']:.4g}: {verdict} predicted")
    print(f"              crown base radius at t_end (Yarin & Weiss): "
          f"{_mm(dl['crown_base_radius_at_t_end_m'])}")
    print(f"  resolution  l0 = {_mm(f['l0_m'])} ({src['l0']}): D/l0 = {f['drop_over_l0']:.3g}, "
          f"h/l0 = {f['film_over_l0']:.3g}; re = {f['re_ratio']:g} l0 = {_mm(f['re_m'])}")
    c_unit = "J/m^3" if r.dim == 3 else "N/m^3 (per unit depth)"
    print(f"  constants   n0 {f['n0']:.6g}, lambda0 {f['lambda0']:.6g} m^2 (= "
          f"{f['lambda0_over_l0_sq']:.6g} l0^2), C {f['C']:.6g} {c_unit}, mass {f['mass']:.6g} "
          f"{f['mass_unit']}")
    st = f["surface_tension"]
    units = {"C": " " + c_unit, "K_1_m2": " 1/m^2", "K_d_1_m2": " 1/m^2", "H_l0": " l0",
             "delta_l0": " l0", "lag_capillary_times": " capillary times"}
    print(f"  tension     {st['model']}: {st['what']}" + "".join(
        f"; {k.split('_1_')[0].removesuffix('_l0').removesuffix('_capillary_times').removesuffix('_B')} "
        f"{v:.6g}{units.get(k, '')}"
        for k, v in st["constants"].items()))
    print(f"  sound speed c = {f['sound_speed_m_s']:.4g} m/s ({f['sound_speed_source']})")
    n = f["numerics"]
    beta = n["beta"] if n["beta"] is not None else r.numerics.free_surface_beta(r.dim)
    relative = n["courant_speed"] == "relative"
    print(f"  numerics    gradient {n['pressure_gradient']}; viscosity {n['viscosity']}; "
          f"safety courant {n['courant']:g}"
          + (f" on relative speeds, approach {n['approach']:g}" if relative else "") + ", "
          f"acoustic {n['acoustic']:g}, viscous {n['viscous']:g}, capillary {n['capillary']:g}; "
          f"beta {beta:g}")
    print("              collision model: " + (
        f"approaching pairs closer than {n['collision']:g} l0, restitution "
        f"{n['restitution']:g}" if n["collision"] > 0 else "off"))
    print(f"              abort at density excess {n['max_density_excess']:g}, Mach "
          f"{n['max_mach']:g}, {n['max_out_fraction']:g} of the fluid out; dt_max "
          f"{n['dt_max'] if n['dt_max'] is not None else 'none'}, fixed dt "
          f"{n['fixed_dt'] if n['fixed_dt'] is not None else 'none (adaptive)'}")
    rules = {"courant": f"{n['courant']:g} l0 / U" + (" (relative speed)" if relative else ""),
             "approach": f"{n['approach']:g} l0 / U", "acoustic": f"{n['acoustic']:g} l0 / c",
             "viscous": f"{n['viscous']:g} l0^2 / nu" + (
                 f" / {VISCOUS_STIFFNESS[n['viscosity']]:g} ({n['viscosity']})"
                 if VISCOUS_STIFFNESS[n['viscosity']] != 1.0 else ""),
             "capillary": f"{n['capillary']:g} sqrt(rho l0^3 / (2 pi sigma))",
             "dt_max": "numerics.dt_max"}
    print("  time step   limits at v = U; dt = the smallest:")
    for name, v in f["limits_s"].items():
        if v is None:
            why = "no viscosity (nu = 0)" if name == "viscous" else "no surface tension"
            print(f"    {name:<10} {rules[name]:<34} {'off':>11}    {why}")
        else:
            mark = "  <- binds" if name in f["binding_ties"] else ""
            print(f"    {name:<10} {rules[name]:<34} {v:11.4g} s{mark}")
    approx = "" if p["exact"] else "~"
    how = ("" if p["exact"] else f"; scaled from the scene built at l0 = {_mm(p['built_l0'])}"
           if p["built_l0"] else "; from the sizes alone: resolving the film, even a coarser "
           "build would be too large")
    print(f"  particles   {approx}{p['fluid']:,} fluid (film {p['n_film']:,}, drop "
          f"{p['n_drop']:,}), {approx}{p['wall']:,} wall, {approx}{p['dummy']:,} dummy "
          f"({approx}{p['total']:,} total{how})")
    if p["total"] > f["max_particles"]:
        need = r.l0 * (p["total"] / f["max_particles"]) ** (1.0 / r.dim)
        print(f"  too many    one simulator holds at most {f['max_particles']:,} particles "
              f"(Taichi's 32-bit field indices): a run would be refused; l0 >= ~{_mm(need)}")
    print(f"  memory      ~{estimate.human_bytes(f['memory_bytes'])} ({tp.bytes_per_particle:g} "
          f"bytes per particle with the cell grid, f32)")
    c, U = f["sound_speed_m_s"], r.speed     # the splash's speeds scale with U (estimate.py)
    speeds = f"the splash's ~{_speed_in_c(f['splash_speed_m_s'], c, U)}"
    if relative:
        speeds = (f"a relative speed of ~{_speed_in_c(f['relative_speed_m_s'], c, U)}, "
                  f"{speeds}")
    print(f"  steps       ~{f['steps']:,} to t_end: dt {f['dt_s']:.3g} s until contact, then "
          f"{f['dt_after_contact_s']:.3g} s ({f['binding_after_contact']} at {speeds}); at "
          f"least {f['steps_at_U']:,} (v = U all along)")
    cost = f["crown_cost"]
    print(f"  run time    ~{estimate.human_seconds(f['run_seconds_estimate'])} on the CPU of "
          f"BENCHMARKS.md (at least {estimate.human_seconds(f['run_seconds_at_U'])}): "
          f"{tp.rate:.3g} fluid particle-steps/s (the bench), a crown step costing "
          f"{cost['before_contact']:.3g} of it a fluid particle before contact and "
          f"{cost['after_contact']:.3g} after{_model_cost(r, cost)} (a wall or dummy particle "
          f"{cost['wall_or_dummy']:g} of a fluid one), + {f['compile_seconds']:g} s compiling "
          f"(a first run; 3-9 s with the kernels in Taichi's cache){_neighbourhood_cost(r)}")
    left = f["left_out"] or ["nothing"]
    for i, line in enumerate(left):
        print(f"  {'left out' if i == 0 else '':<11} {'- ' if f['left_out'] else ''}{line}")
    return 0
