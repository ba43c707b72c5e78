"""Surface export (record/surface_vtk.py, ``crowndemo export --surface``), read back by VTK's
own reader where the ``vtk`` package is installed (the test extra)."""
import json
import math

import numpy as np
import pytest

pytest.importorskip("pysplashsurf")
vtk = pytest.importorskip("vtk", reason="vtk (the test extra) is not installed: VTK's own "
                                        "reader cannot check the exported files")

from vtk.util.numpy_support import vtk_to_numpy  # noqa: E402

from crowndemo.cli import main  # noqa: E402
from crowndemo.record import surface_vtk  # noqa: E402
from crowndemo.record.vtk import read_pvd  # noqa: E402
from crowndemo.render import meshmeasure as mm  # noqa: E402
from crowndemo.render.surface import reconstruct  # noqa: E402

L0 = 1.0e-4


def read_vtp(path):
    r = vtk.vtkXMLPolyDataReader()
    r.SetFileName(str(path))
    r.Update()
    assert r.GetErrorCode() == 0
    return r.GetOutput()


def test_vtk_reads_the_mesh_with_normals_and_fields(tmp_path):
    """A ball of R = 10 l0: VTK reads back every point, triangle and array, and VTK's own
    vtkMassProperties finds the sphere's volume (within 5 %) and area (within 10 %)."""
    n = 11
    g = np.stack(np.meshgrid(*[np.arange(-n, n) + 0.5] * 3, indexing="ij"), -1).reshape(-1, 3)
    p = g[np.linalg.norm(g, axis=1) <= 10] * L0
    mesh = reconstruct(p, L0, {"speed": np.linalg.norm(p, axis=1), "pressure": p[:, 2]})
    surface_vtk.write(tmp_path / "ball.vtp", mesh, 1.5e-3)
    out = read_vtp(tmp_path / "ball.vtp")
    assert out.GetNumberOfPoints() == mesh.n_vertices
    assert out.GetNumberOfPolys() == mesh.n_triangles
    assert np.allclose(vtk_to_numpy(out.GetPoints().GetData()), mesh.vertices)
    pd = out.GetPointData()
    assert np.allclose(vtk_to_numpy(pd.GetNormals()), mesh.normals, atol=1e-6)
    for name in ("speed", "pressure"):
        assert np.allclose(vtk_to_numpy(pd.GetArray(name)), mesh.fields[name], rtol=1e-6)
    assert np.allclose(vtk_to_numpy(pd.GetArray("height")), mesh.vertices[:, 2], atol=1e-9)
    cells = vtk_to_numpy(out.GetPolys().GetConnectivityArray()).reshape(-1, 3)
    assert np.array_equal(cells, mesh.triangles)
    t = out.GetFieldData().GetArray("TimeValue")
    assert t.GetValue(0) == 1.5e-3
    props = vtk.vtkMassProperties()
    props.SetInputData(out)
    props.Update()
    R = 10 * L0
    assert props.GetVolume() == pytest.approx(4 / 3 * math.pi * R ** 3, rel=0.05)
    assert props.GetSurfaceArea() == pytest.approx(4 * math.pi * R ** 2, rel=0.10)
    assert props.GetVolume() == pytest.approx(mm.volume(mesh.vertices, mesh.triangles),
                                              rel=1e-6)


def test_symmetry_planes_come_from_the_metadata():
    assert surface_vtk.planes_of({}) == []
    assert surface_vtk.planes_of({"symmetry_planes": ["x", "y"]}) == ["x", "y"]
    assert surface_vtk.planes_of({"scene_info": {"symmetry_planes": ["x"]}}) == ["x"]
    assert surface_vtk.planes_of({"symmetry_planes": [], "scene_info": {}}) == []


def test_export_surface_of_a_recording(tmp_path):
    """quick-2d recorded (no rendering), exported with --surface: one surface file per frame,
    each read by VTK, the .pvd's times those of metadata.json, the particle files beside."""
    root = tmp_path / "rec"
    assert main(["record", "quick-2d", "--recordings", str(root), "--no-render", "--quiet",
                 "--set", "scene.t_end=2e-4", "--set", "scene.frame_interval=1e-4"]) == 0
    assert main(["export", "quick-2d", "--recordings", str(root), "--surface",
                 "--quiet"]) == 0
    folder = root / "quick-2d"
    meta = json.loads((folder / "metadata.json").read_text())
    out = folder / "vtk"
    entries = read_pvd(out / "quick-2d-surface.pvd")
    assert [t for t, _ in entries] == [f["time_s"] for f in meta["frames"]]
    assert len(list(out.glob("frame_*.vtp"))) == len(entries)
    for _, name in entries:
        poly = read_vtp(out / name)
        assert poly.GetNumberOfPolys() > 0
        assert poly.GetPointData().GetNormals() is not None
        assert poly.GetPointData().GetArray("speed") is not None
        z = vtk_to_numpy(poly.GetPoints().GetData())[:, 2]
        assert np.allclose(vtk_to_numpy(poly.GetPointData().GetArray("height")), z, atol=1e-9)


def test_export_surface_of_a_quarter_run_is_the_whole(tmp_path):
    """quick as a quarter (symmetry planes x = 0, y = 0; metadata.json says so): the exported
    surface covers all four quadrants, mirror-symmetric, and is closed (no seam at the
    planes)."""
    root = tmp_path / "rec"
    assert main(["record", "quick", "--recordings", str(root), "--no-render", "--quiet",
                 "--set", "scene.symmetry=quarter", "--set", "scene.t_end=2.5e-4",
                 "--fast-compile"]) == 0
    meta = json.loads((root / "quick" / "metadata.json").read_text())
    assert surface_vtk.planes_of(meta) == ["x", "y"]
    assert main(["export", "quick", "--recordings", str(root), "--surface", "--quiet"]) == 0
    out = root / "quick" / "vtk"
    for _, name in read_pvd(out / "quick-surface.pvd"):
        poly = read_vtp(out / name)
        v = vtk_to_numpy(poly.GetPoints().GetData())
        tris = vtk_to_numpy(poly.GetPolys().GetConnectivityArray()).reshape(-1, 3)
        assert v[:, 0].min() == pytest.approx(-v[:, 0].max())
        assert v[:, 1].min() == pytest.approx(-v[:, 1].max())
        assert mm.open_edges(tris) == 0
