"""ParaView files with numpy and the standard library only: one XML PolyData file (``.vtp``,
one vertex cell per particle, raw binary appended data) per frame and a ``.pvd`` collection
that lists every frame with its time. ``read`` and ``read_pvd`` parse them back.

Point data: ``velocity`` (vector), ``pressure``, ``number_density``, ``kind``, ``id``; 2D
positions and velocities get a zero third component. Floats keep the snapshot's precision.
Field data: ``TimeValue``; for a half or quarter run ``SymmetryPlanes``, the axes of its mirror
planes through 0 (0: x = 0, 1: y = 0; core/symmetry.py): the points are that part only
(ParaView's Reflect filter, once per plane, shows the whole).
"""
from __future__ import annotations

import os
import shutil
import tempfile
import xml.etree.ElementTree as ET
from pathlib import Path
from typing import Callable, Dict, List, Sequence, Tuple
from xml.sax.saxutils import quoteattr

import numpy as np

from .files import PathLike, atomic_write, atomic_write_text

VTK_TYPES = {np.dtype("float32"): "Float32", np.dtype("float64"): "Float64",
             np.dtype("int32"): "Int32", np.dtype("int64"): "Int64",
             np.dtype("uint8"): "UInt8"}
NUMPY_TYPES = {v: k for k, v in VTK_TYPES.items()}
POINT_DATA = (("velocity", "vel"), ("pressure", "pressure"),
              ("number_density", "number_density"), ("kind", "kind"), ("id", "id"))


def _xyz(a: np.ndarray) -> np.ndarray:
    """N x d -> N x 3 (zero z in 2D)."""
    a = np.asarray(a)
    if a.shape[1] == 3:
        return a
    return np.concatenate([a, np.zeros((len(a), 3 - a.shape[1]), dtype=a.dtype)], axis=1)


def write(path: PathLike, snap: Dict[str, np.ndarray], time: float = None) -> None:
    """One frame as a .vtp file (atomically). ``snap``: pos, vel, pressure, number_density,
    kind, id (a snapshot, see crowndemo.record.snapshots)."""
    n = len(snap["pos"])
    blocks: List[Tuple[str, str, int, np.ndarray]] = []    # (section, name, comps, data)
    for name, key in POINT_DATA:
        a = np.ascontiguousarray(_xyz(snap[key]) if key == "vel" else snap[key])
        blocks.append(("PointData", name, 3 if a.ndim == 2 else 1, a))
    blocks.append(("Points", "Points", 3, np.ascontiguousarray(_xyz(snap["pos"]))))
    blocks.append(("Verts", "connectivity", 1, np.arange(n, dtype=np.int64)))
    blocks.append(("Verts", "offsets", 1, np.arange(1, n + 1, dtype=np.int64)))

    arrays, payload = appended(blocks)
    fields = [] if time is None else [
        '      <DataArray type="Float64" Name="TimeValue" NumberOfTuples="1" '
        f'format="ascii">{float(time)!r}</DataArray>']
    planes = tuple(snap.get("symmetry_planes", ()))
    if planes:      # a half or quarter run (core/symmetry.py): the points are that part only
        fields.append(f'      <DataArray type="Int32" Name="SymmetryPlanes" NumberOfTuples='
                      f'"{len(planes)}" format="ascii">{" ".join(map(str, planes))}</DataArray>')
    field = ("" if not fields else
             "    <FieldData>\n" + "\n".join(fields) + "\n    </FieldData>\n")
    head = ('<?xml version="1.0"?>\n'
            '<VTKFile type="PolyData" version="1.0" byte_order="LittleEndian" '
            'header_type="UInt64">\n  <PolyData>\n' + field +
            f'    <Piece NumberOfPoints="{n}" NumberOfVerts="{n}" NumberOfLines="0" '
            'NumberOfStrips="0" NumberOfPolys="0">\n'
            '      <PointData Scalars="pressure" Vectors="velocity">\n'
            + "\n".join(arrays["PointData"]) + "\n      </PointData>\n      <Points>\n"
            + "\n".join(arrays["Points"]) + "\n      </Points>\n      <Verts>\n"
            + "\n".join(arrays["Verts"]) + "\n      </Verts>\n    </Piece>\n  </PolyData>\n"
            '  <AppendedData encoding="raw">\n   _')
    write_appended(path, head, payload)


def appended(blocks: Sequence[Tuple[str, str, int, np.ndarray]]
             ) -> Tuple[Dict[str, List[str]], List[bytes]]:
    """Blocks (section, name, components, data) as raw appended data: the DataArray lines of
    each section and the payload (UInt64 byte count, then the little-endian bytes, each)."""
    offset, payload, arrays = 0, [], {}
    for section, name, comps, a in blocks:
        a = np.ascontiguousarray(a)
        raw = a.astype(a.dtype.newbyteorder("<"), copy=False).tobytes()
        arrays.setdefault(section, []).append(
            f'        <DataArray type="{VTK_TYPES[a.dtype]}" Name={quoteattr(name)} '
            f'NumberOfComponents="{comps}" format="appended" offset="{offset}"/>')
        payload += [np.uint64(len(raw)).tobytes(), raw]
        offset += 8 + len(raw)
    return arrays, payload


def write_appended(path: PathLike, head: str, payload: Sequence[bytes]) -> None:
    """A VTK XML file (atomically): ``head`` up to the appended data's '_', the payload."""
    def emit(f):
        f.write(head.encode())
        for b in payload:
            f.write(b)
        f.write("\n  </AppendedData>\n</VTKFile>\n".encode())
    atomic_write(path, emit)


def read(path: PathLike) -> Dict[str, np.ndarray]:
    """A .vtp written by ``write``: ``points`` (N x 3), every point-data array by name,
    ``connectivity``, ``offsets`` and ``time`` (None if absent)."""
    data = Path(path).read_bytes()
    mark = data.find(b"<AppendedData")
    if mark < 0:
        raise ValueError(f"{path}: no appended data (not written by crowndemo.record.vtk)")
    start = data.index(b"_", data.index(b">", mark)) + 1
    root = ET.fromstring(data[:mark] + b"</VTKFile>")
    if root.get("type") != "PolyData" or root.get("header_type") != "UInt64":
        raise ValueError(f"{path}: expected PolyData with UInt64 headers")
    out: Dict[str, object] = {"time": None}
    for arr in root.iter("DataArray"):
        name = arr.get("Name")
        if arr.get("format") == "ascii":
            if name == "SymmetryPlanes":
                out["symmetry_planes"] = tuple(int(v) for v in arr.text.split())
            else:
                out["time" if name == "TimeValue" else name] = float(arr.text.split()[0])
            continue
        at = start + int(arr.get("offset"))
        size = int(np.frombuffer(data, "<u8", 1, at)[0])
        dtype = NUMPY_TYPES[arr.get("type")].newbyteorder("<")
        a = np.frombuffer(data, dtype, size // dtype.itemsize, at + 8)
        comps = int(arr.get("NumberOfComponents", "1"))
        out["points" if name == "Points" else name] = a.reshape(-1, comps) if comps > 1 else a
    return out


def write_pvd(path: PathLike, entries: Sequence[Tuple[float, str]]) -> None:
    """A .pvd collection: (time in s, file relative to the .pvd) per frame."""
    rows = "\n".join(f'    <DataSet timestep="{float(t)!r}" group="" part="0" '
                     f'file={quoteattr(str(f))}/>' for t, f in entries)
    atomic_write_text(path, '<?xml version="1.0"?>\n<VTKFile type="Collection" version="0.1" '
                            'byte_order="LittleEndian">\n  <Collection>\n' + rows +
                      "\n  </Collection>\n</VTKFile>\n")


def read_pvd(path: PathLike) -> List[Tuple[float, str]]:
    root = ET.parse(path).getroot()
    return [(float(d.get("timestep")), d.get("file")) for d in root.iter("DataSet")]


def export(snapshot_files: Sequence[PathLike], out_dir: PathLike, name: str) -> Path:
    """Each snapshot .npz -> out_dir/frame_NNNNN.vtp, and out_dir/NAME.pvd; returns the .pvd.
    All or nothing: the files are written into a temporary folder inside ``out_dir`` and moved
    into place (the .pvd last) once every frame is written, so a damaged snapshot
    (snapshots.SnapshotError) or a full disk leaves ``out_dir`` as it was, or absent."""
    out = Path(out_dir)
    names = all_or_nothing(out, lambda tmp: _write_all(snapshot_files, tmp, name))
    return out / names[-1]


def all_or_nothing(out: Path, write_into: Callable[[Path], List[str]]) -> List[str]:
    """``write_into(folder)`` writes files into a temporary folder inside ``out`` and returns
    their names; they are moved into ``out`` in that order once all are written. On any
    failure ``out`` is left as it was (or removed, if this call made it). Returns the names."""
    made = _first_missing(out)
    out.mkdir(parents=True, exist_ok=True)
    tmp = Path(tempfile.mkdtemp(prefix=".export.", dir=out))
    try:
        names = write_into(tmp)
        for n in names:
            os.replace(tmp / n, out / n)
    except BaseException:
        if made is not None:
            shutil.rmtree(made, ignore_errors=True)
        raise
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    return names


def _write_all(snapshot_files: Sequence[PathLike], folder: Path, name: str) -> List[str]:
    """Every frame's .vtp and the .pvd into ``folder``; their names, the .pvd last."""
    from .snapshots import read as read_snapshot

    entries = []
    for f in snapshot_files:
        snap = read_snapshot(f)
        vtp = f"{Path(f).stem}.vtp"
        write(folder / vtp, snap, snap["time"])
        entries.append((snap["time"], vtp))
    write_pvd(folder / f"{name}.pvd", entries)
    return [vtp for _, vtp in entries] + [f"{name}.pvd"]


def _first_missing(folder: Path):
    """The outermost of ``folder`` and its parents that does not exist yet (None: it exists),
    to remove again when an export fails."""
    missing = None
    while not folder.exists() and folder != folder.parent:
        missing, folder = folder, folder.parent
    return missing


__all__ = ["write", "read", "write_pvd", "read_pvd", "export"]
