"""A recording's crown metrics measured again from its snapshots with the rule as it now
stands (``validate.crown_metrics.measure``: the mirrored whole of a half or quarter run, the
film's edge from the scene's info), printed as VALIDATION.md's table of a seed-rung run:

    .venv/bin/python tools/crown_table.py recordings/3m-drop

The run's own metadata.json holds the metrics measured while it ran, with the rule of its
start; this is how a table keeps up with a later fix of the rule (no Taichi here)."""
import argparse
import contextlib
import glob
import json
import os
import sys

HEADER = ("| t (ms) | base r (mm) | rim h (mm) | rim thickness (mm) | jets | droplets | "
          "coherence | far film swell (mm) | verdict |\n"
          "|---|---|---|---|---|---|---|---|---|")


def mm(x) -> str:
    return "-" if x is None or x != x else f"{x * 1e3:.3g}"


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("recording", help="a recording's folder (metadata.json, snapshots/)")
    a = p.parse_args()

    with contextlib.redirect_stdout(sys.stderr):      # Taichi's banner: the table alone on stdout
        from crowndemo.core.state import FLUID
        from crowndemo.record import snapshots
        from crowndemo.validate.crown_metrics import measure
        from crowndemo.validate.verdicts import film_limit

    with open(os.path.join(a.recording, "metadata.json")) as f:
        meta = json.load(f)
    crown = meta["parameters"]["crown"]
    edge = film_limit(meta.get("scene_info"), crown["l0"])
    print(HEADER)
    for path in sorted(glob.glob(os.path.join(a.recording, "snapshots", "frame_*.npz"))):
        snap = snapshots.read(path)
        m = measure(snap["pos"][snap["kind"] == FLUID], float(snap["time"]), crown["film"],
                    crown["drop"], crown["l0"], edge=edge,
                    planes=snap["symmetry_planes"])
        print(f"| {m.time * 1e3:.2f} | {mm(m.base_radius)} | {mm(m.rim_height)} | "
              f"{mm(m.rim_thickness)} | {m.jets} | {m.droplets:,} | {m.sheet_coherence:.3f} | "
              f"{m.film_swell * 1e3:.2f} | {'crown' if m.crown else 'no crown'} |")


if __name__ == "__main__":
    main()
