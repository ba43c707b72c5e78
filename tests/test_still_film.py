"""The film at rest drawn flat (render/still_film.py): the same picture as the whole
reconstruction, for a fraction of its triangles; the crown and the spray reconstructed; a
quarter run mirrored like the whole."""
import numpy as np
import pytest

pytest.importorskip("pysplashsurf")

from crowndemo.render import camera, still_film, window  # noqa: E402
from crowndemo.render.colours import MILK_HIGH, MILK_LOW  # noqa: E402
from crowndemo.render.renderer import Renderer  # noqa: E402
from crowndemo.render.surface import SurfaceParams, reconstruct  # noqa: E402

L0 = 1.0e-4
FILM = 3 * L0                 # three particle layers, at z = 0, l0, 2 l0
HALF = 56                     # the film spans -HALF..HALF l0 in x and y
PARAMS = SurfaceParams()
MILK = np.array([MILK_LOW, MILK_HIGH]).mean(axis=0)


def scene():
    """A film with a crown wall (a ring 10-11.5 l0 from the axis, up to 9 l0 high) and five
    spray particles high above the flat film; on a lattice at (k + 1/2) l0 in x and y,
    jittered by up to 0.15 l0 as the runs' lattices are."""
    k = np.arange(-HALF, HALF) + 0.5
    x, y, z = np.meshgrid(k, k, np.arange(3.0), indexing="ij")
    film = np.c_[x.ravel(), y.ravel(), z.ravel()]
    r = np.hypot(film[:, 0], film[:, 1])
    film = film[r > 11.5]                                  # the crown takes the film inside
    x, y, z = np.meshgrid(k, k, np.arange(9.0), indexing="ij")
    wall = np.c_[x.ravel(), y.ravel(), z.ravel()]
    rw = np.hypot(wall[:, 0], wall[:, 1])
    wall = wall[(rw >= 10.0) & (rw <= 11.5)]
    spray = np.array([[35.5, 5.5, 14.0], [-30.5, 32.5, 12.0], [3.5, -40.5, 16.0],
                      [-38.5, -12.5, 13.0], [24.5, 38.5, 15.0]])
    jitter = np.random.default_rng(7).uniform(-0.15, 0.15, (len(film) + len(wall), 3))
    return np.concatenate([np.concatenate([film, wall]) + jitter, spray]) * L0


def still(pos, planes=()):
    cols = still_film.columns(pos, L0, FILM, PARAMS.band(L0), planes)
    mesh = reconstruct(pos[cols.keep], L0, {"speed": np.zeros(int(cols.keep.sum()))}, PARAMS,
                       planes=planes)
    return still_film.join(mesh, cols), cols


def test_the_crown_its_neighbourhood_and_the_spray_are_reconstructed():
    pos = scene()
    _, cols = still(pos)
    assert cols.flat.sum() > 0.4 * cols.flat.size                   # most of the film is flat
    ij, inside = cols.column_of(pos[:, :2])
    assert inside.all()
    raised = pos[:, 2] > FILM                                        # crown and spray
    assert cols.keep[raised].all()
    crown = raised & (pos[:, 2] < FILM + still_film.NEAR * L0)
    # the mesh is kept over every column within KEEP columns of the crown
    grown = np.zeros_like(cols.flat)
    grown[ij[crown, 0], ij[crown, 1]] = True
    assert not (grown & cols.flat).any()
    grown = still_film._grow(grown, still_film.KEEP)
    assert not (grown & cols.cut).any() and (grown & cols.flat).any()
    # quads under the cut film and one column on under the mesh's edge (a low eye looking
    # under that edge meets them: without them the booth frames showed cracks)
    assert (cols.flat >= cols.cut).all() and (cols.flat <= still_film._grow(cols.cut, 1)).all()
    assert (cols.flat & ~cols.cut).any()
    # the edges of the film (a free edge) are not drawn flat either
    assert not cols.flat[0].any() and not cols.flat[-1].any()
    assert not cols.flat[:, 0].any() and not cols.flat[:, -1].any()
    # every particle within the band of a column that is not flat is reconstructed
    reach = still_film.KEEP + int(np.ceil(PARAMS.band(L0) / cols.cell))
    centre = (ij + 0.5) * cols.cell + cols.origin
    dist = np.hypot(centre[:, 0], centre[:, 1])
    assert cols.keep[dist < 11.5 * L0 + reach * cols.cell].all()


def test_the_flat_film_lies_at_the_reconstructed_film_top():
    """The quads lie at the whole reconstruction's film top (within 0.05 l0), and take the
    place of the whole reconstruction's triangles over the flat columns, two a column."""
    pos = scene()
    full = reconstruct(pos, L0, {"speed": np.zeros(len(pos))}, PARAMS)
    joined, cols = still(pos)
    ij, inside = cols.column_of(full.vertices[:, :2])
    top = inside & cols.cut[ij[:, 0], ij[:, 1]] & (full.normals[:, 2] > 0.9)
    quad_z = joined.vertices[-1, 2]                                  # quads come last
    assert abs(np.median(full.vertices[top, 2]) - quad_z) < 0.05 * L0
    over = (inside & cols.cut[ij[:, 0], ij[:, 1]])[full.triangles].all(axis=1).sum()
    assert over > 0.3 * full.n_triangles
    assert joined.n_triangles < full.n_triangles - 0.9 * over + 2 * cols.flat.sum()


@pytest.fixture
def renderer():
    window.check_available()
    r = Renderer((320, 180))
    yield r
    r.close()


def test_the_picture_is_the_whole_reconstructions(renderer):
    """Seen low, as the surface frames are, the frame with the flat film differs from the
    frame of the whole reconstruction in under 0.2 % of its pixels (by more than 8 of 255)."""
    pos = scene()
    full = reconstruct(pos, L0, {"speed": np.zeros(len(pos))}, PARAMS)
    joined, _ = still(pos)
    pose = camera.spherical((0.0, 0.0, 2 * L0), 150 * L0, -60.0, 18.0, 40.0)
    images = [renderer.render_surface(m, np.tile(np.float32(MILK), (m.n_vertices, 1)), pose)
              for m in (full, joined)]
    assert renderer.blank_frames == 0
    lit = (images[0].astype(int).sum(axis=2) > 60).mean()
    assert lit > 0.2                                                   # the film fills it
    diff = np.abs(images[0].astype(int) - images[1].astype(int)).max(axis=2)
    assert (diff > 8).mean() < 0.002
    # no crack: no pixel of the lit film comes out dark (the film's inside, or the floor)
    bright, dark = (im.astype(int).sum(axis=2) for im in images)
    assert not ((bright > 300) & (dark < 150)).any()


def flat_triangles(mesh):
    """The columns (x, y indices) under the triangles of the flat film (facing exactly up),
    each with its triangle count, and their heights."""
    up = np.all(mesh.normals[mesh.triangles] == [0.0, 0.0, 1.0], axis=(1, 2))
    centres = mesh.vertices[mesh.triangles[up]].mean(axis=1) / L0
    cells, count = np.unique(np.floor(centres[:, :2] / still_film.CELL).astype(int), axis=0,
                             return_counts=True)
    return {(i, j, c) for (i, j), c in zip(cells.tolist(), count.tolist())}, \
        np.unique(centres[:, 2])


def test_a_quarter_is_mirrored_into_the_wholes_flat_film():
    """A quarter (x, y > 0) with its symmetry planes gets the whole scene's flat film."""
    pos = scene()
    whole, cols = still(pos)
    quarter = pos[(pos[:, 0] > 0) & (pos[:, 1] > 0)]
    part, qcols = still(quarter, ("x", "y"))
    assert int(qcols.flat.sum()) * 4 == int(cols.flat.sum())
    flat, z = flat_triangles(whole)
    assert len(flat) == int(cols.flat.sum()) and {c for *_, c in flat} == {2} and len(z) == 1
    flat_part, z_part = flat_triangles(part)
    assert flat_part == flat
    assert len(z_part) == 1 and abs(z_part[0] - z[0]) < 0.01       # l0: each its own median


def test_a_trimmed_films_left_out_part_lies_flat_out_to_the_floors_edge():
    """A film trimmed to a disc (scene.trim): the film left out is drawn as one flat ring at
    the quads' height, from EDGE l0 inside the disc's edge out to the square floor's edge;
    its area is the floor's less the inner polygon's, to rounding."""
    pos = scene()
    extent, floor = 45 * L0, 2 * HALF * L0
    film = pos[:, 2] < FILM
    pos = pos[~film | (np.hypot(pos[:, 0], pos[:, 1]) <= extent)]
    cols = still_film.columns(pos, L0, FILM, PARAMS.band(L0), (), floor, extent)
    mesh = reconstruct(pos[cols.keep], L0, {"speed": np.zeros(int(cols.keep.sum()))}, PARAMS)
    joined = still_film.join(mesh, cols)
    k = still_film.ANNULUS
    ring = joined.vertices[joined.triangles[-2 * k:]]                # the ring comes last
    r_in = extent - still_film.EDGE * L0
    assert np.hypot(ring[..., 0], ring[..., 1]).min() == pytest.approx(r_in, rel=1e-12)
    e1, e2 = ring[:, 1] - ring[:, 0], ring[:, 2] - ring[:, 0]
    assert (np.cross(e1, e2)[:, 2] > 0).all()                       # facing up
    area = 0.5 * np.cross(e1, e2)[:, 2].sum()
    assert area == pytest.approx(floor ** 2 - 0.5 * k * r_in ** 2 * np.sin(2 * np.pi / k),
                                 rel=1e-9)
    up = np.all(joined.normals[joined.triangles] == [0.0, 0.0, 1.0], axis=(1, 2))
    flat = joined.vertices[joined.triangles[up]]
    assert len(flat) > 2 * k and np.ptp(flat[..., 2]) < 1e-12       # ring and quads: one height


@pytest.mark.parametrize("preset, quality", [("quick", "draft"), ("3m-drop", "booth")])
def test_the_view_knows_where_the_scene_trimmed_its_film(preset, quality):
    """Geometry.film_extent is the radius the scene kept its film to, or None untrimmed."""
    from crowndemo import config
    from crowndemo.render.camera import Geometry
    resolved = config.load(preset, quality)
    info = resolved.build_scene().info
    expect = info["extent_m"] if info["trimmed"] else None
    assert Geometry.from_resolved(resolved).film_extent == expect
