"""A booth frame's cost, the surface as it was (every colour field interpolated, splashsurf's
smoothing weights) against as it is (only the colour scale's field, the grid's weights):
surface + render + caption + PNG at 1920x1080, on a booth 3m-drop recording's snapshots,
alternating, in one process:

    .venv/bin/python tools/surface_frame_time.py RECORDING FRAMES REPEATS
    (e.g. recordings/3m-drop 8,12,16 2, after crowndemo record 3m-drop --quality booth)"""
import os
import sys
import tempfile
import time

import numpy as np

from crowndemo import config
from crowndemo.render.renderer import Renderer
from crowndemo.render.view import PresetView, RenderSettings
from crowndemo.render.surface import SurfaceParams
from crowndemo.render.captions import draw_caption
from crowndemo.render.video import write_png
rec, frames, reps = sys.argv[1], [int(f) for f in sys.argv[2].split(',')], int(sys.argv[3])
res = (1920, 1080)
r = config.load("3m-drop", "booth")
ren = Renderer(res)
view = PresetView.from_resolved(r, RenderSettings(resolution=res))
variants = {"before": (SurfaceParams(weights="splashsurf"), True), "after": (SurfaceParams(), False)}
res_t = {}
out = tempfile.mkdtemp()
for fr in frames:
    z = np.load(f"{rec}/snapshots/frame_{fr:05d}.npz")
    pos = z["pos"].astype(np.float64); t = float(z["time"])
    fields = {"speed": np.linalg.norm(z["vel"], axis=1), "pressure": z["pressure"].astype(float)}
    for rep in range(reps):
        for name, (params, all_fields) in variants.items():
            view.surface_params = params
            t0 = time.perf_counter()
            if all_fields:     # what the view did before: every field to the reconstruction
                mesh = view.surface(pos, fields)
                from crowndemo.render.colours import vertex_colours
                img = ren.render_surface(mesh, vertex_colours(view.scale, mesh.vertices[:, 2], mesh.fields), view.pose(fr), view.floor)
            else:
                img = view.surface_image(ren, pos, fields, view.pose(fr))
            img = draw_caption(img, view.caption, t, "en", None, view.scale)
            write_png(img, os.path.join(out, f"{fr}-{name}.png"))     # the PNG's cost counts
            dt = time.perf_counter() - t0
            res_t.setdefault((fr, name), []).append((dt, view.surface_seconds))
            print(fr, name, f"frame {dt:.2f}s surface {view.surface_seconds:.2f}s tris {view.triangles}", flush=True)
ren.close()
for k, v in sorted(res_t.items()):
    a = np.array(v)
    print(k, "median frame %.2f surface %.2f" % tuple(np.median(a, axis=0)))
