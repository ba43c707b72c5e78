"""The liquid surface per frame as ParaView/Blender files (numpy only): one XML PolyData file
(``surface_NNNNN.vtp``: triangles, raw binary appended data) per snapshot and a ``.pvd`` that
lists them with their times, beside the particle files of ``vtk.py``.

Point data: ``Normals`` (unit, outward), ``speed`` (m/s), ``pressure`` (Pa), ``height`` (m,
the vertex's z). A run with symmetry planes (metadata.json's ``symmetry_planes``) is mirrored
into the whole scene.
"""
from __future__ import annotations

from pathlib import Path
from typing import Dict, List, Optional, Sequence, Tuple

import numpy as np

from .files import PathLike
from .vtk import all_or_nothing, appended, write_appended, write_pvd

PREFIX = "surface_"


def planes_of(meta: dict) -> List[str]:
    """A recording's symmetry planes (axis names): metadata.json's ``symmetry_planes``, or its
    scene_info's; none when it has neither (a recording from before symmetry planes)."""
    planes = meta.get("symmetry_planes")
    if planes is None:
        planes = (meta.get("scene_info") or {}).get("symmetry_planes")
    return list(planes or [])


def write(path: PathLike, mesh, time: Optional[float] = None) -> None:
    """One SurfaceMesh (render/surface.py) as a .vtp of triangles, written atomically."""
    nv, nt = mesh.n_vertices, mesh.n_triangles
    point_data = [("Normals", mesh.normals.astype(np.float32))]
    point_data += [(k, np.asarray(v, np.float32)) for k, v in sorted(mesh.fields.items())]
    point_data.append(("height", mesh.vertices[:, 2].astype(np.float32)))
    blocks: List[Tuple[str, str, int, np.ndarray]] = [
        ("PointData", name, 3 if a.ndim == 2 else 1, a) for name, a in point_data]
    blocks.append(("Points", "Points", 3, mesh.vertices.astype(np.float64)))
    blocks.append(("Polys", "connectivity", 1, mesh.triangles.astype(np.int64).reshape(-1)))
    blocks.append(("Polys", "offsets", 1, 3 * np.arange(1, nt + 1, dtype=np.int64)))
    arrays, payload = appended(blocks)
    field = ("" if time is None else
             '    <FieldData>\n      <DataArray type="Float64" Name="TimeValue" '
             f'NumberOfTuples="1" format="ascii">{float(time)!r}</DataArray>\n    </FieldData>\n')
    scalars = "speed" if "speed" in mesh.fields else "height"
    head = ('<?xml version="1.0"?>\n'
            '<VTKFile type="PolyData" version="1.0" byte_order="LittleEndian" '
            'header_type="UInt64">\n  <PolyData>\n' + field +
            f'    <Piece NumberOfPoints="{nv}" NumberOfVerts="0" NumberOfLines="0" '
            f'NumberOfStrips="0" NumberOfPolys="{nt}">\n'
            f'      <PointData Scalars="{scalars}" Normals="Normals">\n'
            + "\n".join(arrays["PointData"]) + "\n      </PointData>\n      <Points>\n"
            + "\n".join(arrays["Points"]) + "\n      </Points>\n      <Polys>\n"
            + "\n".join(arrays["Polys"]) + "\n      </Polys>\n    </Piece>\n  </PolyData>\n"
            '  <AppendedData encoding="raw">\n   _')
    write_appended(path, head, payload)


def surface_of(snap: Dict[str, np.ndarray], l0: float, planes: Sequence[str] = ()):
    """The surface of a snapshot's fluid particles, with speed and pressure on its vertices."""
    from ..core.state import FLUID
    from ..render.surface import reconstruct

    fluid = np.asarray(snap["kind"]) == FLUID
    fields = {"speed": np.linalg.norm(np.asarray(snap["vel"])[fluid], axis=1),
              "pressure": np.asarray(snap["pressure"])[fluid]}
    return reconstruct(np.asarray(snap["pos"])[fluid], l0, fields, planes=planes)


def export(snapshot_files: Sequence[PathLike], out_dir: PathLike, name: str, l0: float,
           planes: Sequence[str] = ()) -> Tuple[Path, float]:
    """Each snapshot -> out_dir/surface_NNNNN.vtp and out_dir/NAME-surface.pvd, all or nothing
    (as vtk.export); returns the .pvd and the reconstruction's wall seconds per frame."""
    import time as _time

    from .snapshots import read as read_snapshot

    out = Path(out_dir)
    seconds = 0.0
    entries: List[Tuple[float, str]] = []

    def write_into(tmp: Path) -> List[str]:
        nonlocal seconds
        for f in snapshot_files:
            snap = read_snapshot(f)
            start = _time.perf_counter()
            mesh = surface_of(snap, l0, planes)
            seconds += _time.perf_counter() - start
            vtp = PREFIX + Path(f).stem.replace("frame_", "") + ".vtp"
            write(tmp / vtp, mesh, snap["time"])
            entries.append((snap["time"], vtp))
        write_pvd(tmp / f"{name}-surface.pvd", entries)
        return [n for _, n in entries] + [f"{name}-surface.pvd"]

    pvd = all_or_nothing(out, write_into)[-1]
    keep = {n for _, n in entries}
    for old in out.glob(PREFIX + "*.vtp"):
        if old.name not in keep:
            old.unlink()
    return out / pvd, seconds / max(len(entries), 1)


__all__ = ["write", "export", "surface_of", "planes_of", "PREFIX"]
