"""The liquid surface (render/surface.py) against geometry: a ball, a film, a thin sheet,
droplets, and the mirroring of a quarter or half run into the whole."""
import math
import os

import numpy as np
import pytest

pytest.importorskip("pysplashsurf")

from crowndemo.render import meshmeasure as mm  # noqa: E402
from crowndemo.render.surface import SurfaceParams, plane_axes, reconstruct  # noqa: E402

L0 = 1.0e-4                        # particle spacing, m
CUBE = SurfaceParams().cube_size(L0)


def lattice(lo, hi):
    """Particles at the centres of the l0-cubes filling the box [lo, hi] (in l0)."""
    axes = [np.arange(a, b) + 0.5 for a, b in zip(lo, hi)]
    return np.stack(np.meshgrid(*axes, indexing="ij"), -1).reshape(-1, len(lo)) * L0


def ball(radius):
    """Lattice particles within ``radius`` (in l0) of the origin: each stands for l0^3."""
    n = int(radius) + 1
    p = lattice((-n,) * 3, (n,) * 3)
    return p[np.linalg.norm(p, axis=1) <= radius * L0]


def spread_from(a, b):
    """Largest distance from a point of ``a`` to the nearest point of ``b``."""
    bb = (b ** 2).sum(1)
    return max(np.sqrt(max(((c ** 2).sum(1)[:, None] + bb[None] - 2 * c @ b.T).min(1).max(),
                           0.0)) for c in (a[i:i + 1000] for i in range(0, len(a), 1000)))


def test_ball_is_closed_with_the_spheres_volume_and_area():
    r = 10
    mesh = reconstruct(ball(r), L0)
    R = r * L0
    assert mm.open_edges(mesh.triangles) == 0
    assert mm.pieces(mesh.n_vertices, mesh.triangles) == 1
    assert mm.euler(mesh.triangles) == 2                     # a sphere's topology
    assert mm.volume(mesh.vertices, mesh.triangles) == pytest.approx(4 / 3 * math.pi * R ** 3,
                                                                      rel=0.05)
    assert mm.area(mesh.vertices, mesh.triangles) == pytest.approx(4 * math.pi * R ** 2,
                                                                    rel=0.10)
    # outward normals of unit length
    n = mesh.normals
    assert np.allclose(np.linalg.norm(n, axis=1), 1.0, atol=1e-6)
    assert (np.einsum("ij,ij->i", n, mesh.vertices) > 0).mean() > 0.99


def test_film_is_a_slab_of_its_thickness():
    layers, half = 3, 15                           # h = 3 l0, 30 l0 square
    mesh = reconstruct(lattice((-half, -half, 0), (half, half, layers)), L0)
    v = mesh.vertices
    centre = np.all(np.abs(v[:, :2]) < 5 * L0, axis=1)        # away from the film's edges
    top, bottom = v[centre, 2].max(), v[centre, 2].min()
    assert top - bottom == pytest.approx(layers * L0, abs=L0)
    assert mm.open_edges(mesh.triangles) == 0


@pytest.mark.parametrize("spacing, jitter", [(1.0, 0.0), (2.0, 0.15)])
def test_thin_sheet_two_particles_thick_stays_one_surface(spacing, jitter):
    """A crown wall two particles thick, also stretched to 2 l0 between neighbours in its plane
    and disordered: one closed sheet without holes (a hole would lower V - E + F below 2)."""
    n = int(30 / spacing)
    p = lattice((0, 0, 0), (n, n, 2))
    p[:, :2] *= spacing
    p += jitter * L0 * np.random.default_rng(22).standard_normal(p.shape)
    mesh = reconstruct(p, L0)
    assert mm.pieces(mesh.n_vertices, mesh.triangles) == 1
    assert mm.euler(mesh.triangles) == 2
    assert mm.open_edges(mesh.triangles) == 0


def test_curved_sheet_stays_one_tube():
    """A cylindrical crown wall (radius 15 l0, two particles thick, open top and bottom): one
    surface with the topology of a tube's skin, a torus (V - E + F = 0)."""
    rings = []
    for layer in range(2):
        r = (15 + layer) * L0
        k = int(2 * math.pi * r / L0)
        a = np.arange(k) * 2 * math.pi / k
        for z in range(20):
            rings.append(np.c_[r * np.cos(a), r * np.sin(a), np.full(k, (z + 0.5) * L0)])
    mesh = reconstruct(np.concatenate(rings), L0)
    assert mm.pieces(mesh.n_vertices, mesh.triangles) == 1
    assert mm.euler(mesh.triangles) == 0


def test_spray_droplets_stay_droplets():
    """Five single particles 3 l0 apart (centre to centre): five closed droplets."""
    p = np.array([[3.0 * i * L0, 0.0, 0.0] for i in range(5)])
    mesh = reconstruct(p, L0)
    assert mm.pieces(mesh.n_vertices, mesh.triangles) == 5
    assert mm.euler(mesh.triangles) == 2 * 5
    assert mm.open_edges(mesh.triangles) == 0


def crown_like():
    """A film (3 layers), a wall on it (2 particles thick, 12 high) and spray above: single
    particles and clusters of 2-8, jittered by 0.15 l0: every kind of vertex a crown has."""
    rng = np.random.default_rng(3)
    film = lattice((-20, -20, 0), (20, 20, 3))
    wall = lattice((-10, -1, 3), (10, 1, 15))
    spray = [np.array([[x, y, 22.0]]) + lattice((0, 0, 0), (k, 1, 1)) / L0
             for x, y, k in zip(range(-18, 18, 4), (0, 6) * 5, (1, 2, 4, 8, 1, 2, 4, 8, 1))]
    p = np.concatenate([film, wall, np.concatenate(spray) * L0])
    return p + rng.uniform(-0.15, 0.15, p.shape) * L0


def on_film_top(v):
    """Vertices of crown_like's film top, away from the wall, the spray and the film's edges."""
    x, y, z = (np.abs(v[:, a]) / L0 for a in range(3))
    return (x > 13) & (x < 17) & (y < 15) & (z > 2.5) & (z < 4)


def test_grid_weights_follow_splashsurfs():
    """The smoothing weights from the grid (smoothing_weights.py) against splashsurf's own on
    the same vertices: within the fit's error on the booth crown (mean |difference| 0.049,
    bound 0.1); single spray particles unsmoothed (below 0.1) and the film's top fully
    smoothed, in both."""
    import pysplashsurf
    from crowndemo.render.smoothing_weights import grid_weights

    p = crown_like()
    P = SurfaceParams()
    out, _ = pysplashsurf.reconstruction_pipeline(
        p, particle_radius=0.5 * L0, smoothing_length=P.smoothing, cube_size=P.cube,
        iso_surface_threshold=P.iso, mesh_smoothing_weights=True,
        output_mesh_smoothing_weights=True)
    v = np.asarray(out.mesh.vertices)
    theirs = np.asarray(out.point_attributes["sw"])
    ours = grid_weights(p, v, L0)
    assert np.abs(ours - theirs).mean() < 0.1
    single = np.linalg.norm(v - np.array([-18, 0, 22.5]) * L0, axis=1) < 2 * L0
    film_top = on_film_top(v)
    for w in (ours, theirs):
        assert single.any() and (w[single] < 0.1).all()
        assert film_top.any() and (w[film_top] > 0.99).mean() > 0.95


@pytest.mark.parametrize("weights", ["grid", "splashsurf"])
def test_droplets_keep_their_size_and_the_wall_is_smoothed(weights):
    """With either weights a single spray particle's droplet keeps its unsmoothed radius
    (within 5 %), while the film's top is smoothed flatter. Unweighted, the 5 iterations
    shrink that droplet by 34 % (1.07 -> 0.70 l0): that is what the weights are for."""
    p = crown_like()
    raw = reconstruct(p, L0, params=SurfaceParams(smoothing_iters=0, weights=weights))
    mesh = reconstruct(p, L0, params=SurfaceParams(weights=weights))
    centre = np.array([-18, 0, 22.5]) * L0

    def size(m):
        d = np.linalg.norm(m.vertices - centre, axis=1)
        return d[d < 2 * L0].mean()
    assert size(mesh) == pytest.approx(size(raw), rel=0.05)
    assert mesh.vertices[on_film_top(mesh.vertices), 2].std() < raw.vertices[
        on_film_top(raw.vertices), 2].std()


def test_fields_are_interpolated_to_the_vertices():
    """A field equal to the height z reads, at each vertex, the height of the particles near
    it: within the kernel's reach (one support radius) of the vertex's own height."""
    p = ball(8)
    mesh = reconstruct(p, L0, {"height": p[:, 2], "one": np.ones(len(p))})
    assert set(mesh.fields) == {"height", "one"}
    assert np.allclose(mesh.fields["one"], 1.0, atol=1e-6)
    err = np.abs(mesh.fields["height"] - mesh.vertices[:, 2])
    assert err.max() < SurfaceParams().support(L0)
    # the field follows the height: top vertices read high, bottom ones low
    assert np.corrcoef(mesh.fields["height"], mesh.vertices[:, 2])[0, 1] > 0.99


@pytest.mark.parametrize("planes", [["x"], ["x", "y"]])
def test_mirrored_part_equals_the_whole(planes):
    """The mesh of a quarter (or half) ball mirrored into the whole is the full ball's mesh
    within one cube size, closed, one piece, no seam."""
    p = ball(10)
    full = reconstruct(p, L0, {"z": p[:, 2]})
    part = np.all(p[:, list(plane_axes(planes))] > 0, axis=1)
    whole = reconstruct(p[part], L0, {"z": p[part, 2]}, planes=planes)
    assert mm.open_edges(whole.triangles) == 0                 # seamless
    assert mm.pieces(whole.n_vertices, whole.triangles) == 1
    assert mm.euler(whole.triangles) == 2
    assert spread_from(whole.vertices, full.vertices) < CUBE
    assert spread_from(full.vertices, whole.vertices) < CUBE
    assert mm.volume(whole.vertices, whole.triangles) == pytest.approx(
        mm.volume(full.vertices, full.triangles), rel=0.01)
    # no seam in the shading: near the planes the normals are as close to the sphere's exact
    # (radial) normals as the full ball's own are anywhere (cut before smoothing, they were
    # off by up to 3.0 degrees there against 1.7)
    def error(mesh):
        radial = mesh.vertices / np.linalg.norm(mesh.vertices, axis=1, keepdims=True)
        return np.degrees(np.arccos(np.clip((mesh.normals * radial).sum(1), -1, 1)))
    near = np.abs(whole.vertices[:, list(plane_axes(planes))]).min(axis=1) < L0
    assert error(whole)[near].max() <= error(full).max()
    assert error(whole)[near].mean() <= error(full).mean()
    # the part alone, cut at the planes, is open exactly there
    cut = reconstruct(p[part], L0, planes=planes, whole=False)
    assert cut.vertices[:, list(plane_axes(planes))].min() == 0.0
    assert mm.open_edges(cut.triangles) > 0


def test_grid_weights_are_mirror_symmetric():
    """Particles and vertices mirrored across x = 0 and y = 0 get the same weights as their
    images (to rounding): the weight grid's faces lie on the planes, so a vertex on a plane
    stays on it through the smoothing."""
    from crowndemo.render.smoothing_weights import grid_weights

    rng = np.random.default_rng(3)
    # a sparse spray (0.17 particles per l0^3), so that the weights are not all saturated
    quarter = rng.uniform([0.0, 0.0, 0.0], [20.0, 20.0, 6.0], (400, 3)) * L0
    both = lambda a: np.concatenate([a * s for s in ([1, 1, 1], [-1, 1, 1], [1, -1, 1],
                                                     [-1, -1, 1])])
    particles = both(quarter) + np.array([0.0, 0.0, 1.0e-3])   # not at the origin in z
    v = rng.uniform([0.0, 0.0, 0.0], [20.0, 20.0, 6.0], (500, 3)) * L0 + [0.0, 0.0, 1.0e-3]
    w = grid_weights(particles, both(v), L0).reshape(4, -1)
    assert ((w[0] > 0.05) & (w[0] < 0.95)).mean() > 0.5         # between none and full
    assert np.abs(w - w[0]).max() < 1e-9


def test_mirrored_quarter_crown_is_closed():
    """quick's quarter scene (a film and a drop on the planes' corner) mirrored into the whole
    with the default weights: closed, no seam. With a weight grid placed from the particles'
    extent a vertex on the axis ended 1e-11 l0 off a plane and left 4 open edges."""
    from crowndemo import config
    from crowndemo.core import FLUID

    r = config.load("quick", "draft", ["scene.symmetry=quarter"])
    scene = r.build_scene()
    mesh = reconstruct(scene.pos[scene.kind == FLUID], r.l0, planes=["x", "y"])
    assert mesh.n_triangles > 0
    assert mm.open_edges(mesh.triangles) == 0


def test_slice_is_extruded_and_mirrored():
    """A 2D disc (x, z) of radius 10 l0 becomes a slab whose outline at y = 0 lies on the
    circle within one l0; its half run (plane x) mirrors into the same."""
    r = 10
    n = r + 1
    p = lattice((-n, -n), (n, n))
    p = p[np.linalg.norm(p, axis=1) <= r * L0]
    full = reconstruct(p, L0)
    mid = np.abs(full.vertices[:, 1]) < 0.5 * L0
    rim = np.hypot(full.vertices[mid, 0], full.vertices[mid, 2])
    assert np.abs(rim[rim > 5 * L0] - r * L0).max() < L0
    half = reconstruct(p[p[:, 0] > 0], L0, planes=["x"])
    assert mm.open_edges(half.triangles) == 0
    assert spread_from(half.vertices, full.vertices) < CUBE


def test_plane_names():
    assert plane_axes(None) == ()
    assert plane_axes([]) == ()
    assert plane_axes(["y", "x"]) == (0, 1)
    with pytest.raises(ValueError, match="allowed: x, y"):
        plane_axes(["z"])


def test_no_particles_no_mesh():
    mesh = reconstruct(np.zeros((0, 3)), L0, {"speed": np.zeros(0)})
    assert mesh.n_vertices == 0 and mesh.n_triangles == 0 and "speed" in mesh.fields


def test_splashsurf_threads_follow_taichis(monkeypatch):
    """RAYON_NUM_THREADS (splashsurf's pool) is Taichi's CPU thread count unless set."""
    import taichi as ti

    from crowndemo.render.surface import limit_threads
    monkeypatch.delenv("RAYON_NUM_THREADS", raising=False)
    limit_threads(3)
    assert os.environ["RAYON_NUM_THREADS"] == "3"
    limit_threads(5)                                   # a set value is kept
    assert os.environ["RAYON_NUM_THREADS"] == "3"
    monkeypatch.delenv("RAYON_NUM_THREADS")
    limit_threads()
    if ti.lang.impl.get_runtime().prog is not None:
        expected = ti.lang.impl.current_cfg().cpu_max_num_threads
    else:
        expected = os.cpu_count()
    assert os.environ["RAYON_NUM_THREADS"] == str(expected)


def test_marching_cubes_alone_give_the_pipelines_mesh_and_fields():
    """The grid-weights path calls splashsurf's reconstruct_surface and interpolates the fields
    itself (half the pipeline's time at booth 4 ms); before any smoothing its mesh and an
    interpolated linear field must be the pipeline's own (same vertices, the field within
    1e-9 of its range; the threads may order the vertices differently, so both are sorted)."""
    import pysplashsurf

    p = crown_like()
    q = p[:, 0] / L0 + 2.0 * p[:, 2] / L0
    P = SurfaceParams(smoothing_iters=0, normal_iters=0)
    ours = reconstruct(p, L0, {"q": q}, params=P)
    out, _ = pysplashsurf.reconstruction_pipeline(
        p, attributes_to_interpolate={"q": q}, particle_radius=0.5 * L0,
        smoothing_length=P.smoothing, cube_size=P.cube, iso_surface_threshold=P.iso)
    v, f = np.asarray(out.mesh.vertices), np.asarray(out.point_attributes["q"])
    assert ours.n_vertices == len(v) and ours.n_triangles == len(np.asarray(out.mesh.triangles))

    def order(x):
        return np.lexsort(np.round(x / (1e-6 * L0)).astype(np.int64).T[::-1])
    a, b = order(ours.vertices), order(v)
    assert np.abs(ours.vertices[a] - v[b]).max() < 1e-9 * L0
    assert np.abs(ours.fields["q"][a] - f[b]).max() < 1e-9 * np.ptp(f)
