"""Curvature-based surface tension: the Young-Laplace jump as the pressure boundary condition of
the free surface (Tsujimura, Kubota & Sato, Comput. Part. Mech. 10, 2023),

    P_i = sigma kappa_i  on free-surface particles (n_i < beta n0, M3) instead of P_i = 0,

so the liquid inside a resting drop settles at sigma kappa (sigma/R in 2D, 2 sigma/R in 3D)
through the ordinary pressure gradient (S18), with no delta function to normalise.

kappa_i, two neighbour passes at r* after the number density (S17):
1. the unit normal n_i = -grad n / |grad n|, grad n_i = sum_j w'(r) (r_i - r_j)/r
   = re sum_j r_ij / r^3 over every neighbour (S9 counts every kind), for free-surface i;
2. a weighted least-squares fit, in i's frame (tangents t, normal n_i), of the height
   h = a + b.t + t^T H t / 2 to the fluid neighbours within |h| < l0/2 (the surface layer, i
   itself included); kappa is the mean curvature of the fitted graph (the sum of the principal
   curvatures, positive where convex), moved outward by l0/2 to the liquid's surface (each
   particle stands for a cell of side l0, as in the potential's cut, S23):
   kappa = (H + 2 K s)/(1 + H s + K s^2), s = l0/2, H, K the mean-curvature sum and Gauss
   curvature of the fit. A particle with a fluid or wall neighbour more than l0/2 outward
   along its normal lies under the surface layer (a second layer flagged by n < beta n0): it
   keeps the pressure of S17/M3, as does one whose fit is singular.
The fit measured better than the divergence of the normal (renormalised as in Adami, Hu &
Adams 2010, or by a least-squares gradient): on particles placed on a circle or sphere the
divergence scattered by 40-180 % per particle at R/l0 = 8-16, the fit by under 2 %.

Experimental: the curvature is tested (tests/test_curvature.py), but the model does not yet
hold a free drop; docs/surface_tension_curvature.md has the measurements and what is left.

Dimension-generic: the monomials and the frame are chosen with ti.static (3 unknowns in 2D,
6 in 3D). |kappa| is capped at (d-1)/l0, a drop of radius l0.
"""
import taichi as ti

from ..coefficients import Coefficients
from ..grid import CellGrid
from ..operators import weight
from ..params import Model
from ..state import FLUID, WALL, field_nbytes

LAYER = 0.5      # the surface layer: |h| < LAYER l0 about i's tangent plane
OFFSET = 0.5     # the liquid's surface lies OFFSET l0 outside the outer particles' centres


@ti.func
def frame(n):
    """Rows: orthonormal tangents, then n (unit). 3D tangents after Duff et al. 2017."""
    if ti.static(n.n == 2):
        return ti.Matrix([[-n[1], n[0]], [n[0], n[1]]])
    s = ti.select(n[2] >= 0.0, 1.0, -1.0)
    a = -1.0 / (s + n[2])
    b = n[0] * n[1] * a
    return ti.Matrix([[1.0 + s * n[0] * n[0] * a, s * b, -s * n[0]],
                      [b, s + n[1] * n[1] * a, -n[1]],
                      [n[0], n[1], n[2]]])


@ti.func
def monomials(x):
    """The fit's basis at local coordinates x (tangential first, then the height):
    2D (1, u, u^2/2); 3D (1, u, v, u^2/2, u v, v^2/2)."""
    if ti.static(x.n == 2):
        return ti.Vector([1.0, x[0], 0.5 * x[0] * x[0]])
    return ti.Vector([1.0, x[0], x[1], 0.5 * x[0] * x[0], x[0] * x[1], 0.5 * x[1] * x[1]])


@ti.func
def solve_spd(m, b):
    """m c = b for a symmetric positive (semi)definite m by LDL^T (every index static);
    ok = 0 where a pivot falls below 1e-8 of the largest diagonal term (a singular fit)."""
    k = ti.static(b.n)
    L = ti.Matrix.identity(float, k)
    d = ti.Vector.zero(float, k)
    scale = 0.0
    for a in ti.static(range(k)):
        scale = ti.max(scale, m[a, a])
    ok = 1
    for j in ti.static(range(k)):
        s = m[j, j]
        for p in ti.static(range(j)):
            s -= L[j, p] * L[j, p] * d[p]
        if s <= 1e-8 * scale:
            ok = 0
            s = 1.0
        d[j] = s
        for i in ti.static(range(j + 1, k)):
            t = m[i, j]
            for p in ti.static(range(j)):
                t -= L[i, p] * L[j, p] * d[p]
            L[i, j] = t / s
    y = ti.Vector.zero(float, k)
    for i in ti.static(range(k)):
        t = b[i]
        for p in ti.static(range(i)):
            t -= L[i, p] * y[p]
        y[i] = t
    c = ti.Vector.zero(float, k)
    for ii in ti.static(range(k)):
        i = ti.static(k - 1 - ii)
        t = y[i] / d[i]
        for p in ti.static(range(i + 1, k)):
            t -= L[p, i] * c[p]
        c[i] = t
    return c, ok


@ti.func
def fit_curvature(c):
    """The curvature (per l0) of the fitted graph h(t), moved OFFSET outward (module
    docstring): from its slope and second derivatives at t = 0."""
    H, K = 0.0, 0.0
    if ti.static(c.n == 3):                       # 2D: (a, h', h'')
        q = 1.0 + c[1] * c[1]
        H = -c[2] / (q * ti.sqrt(q))
    else:                                         # 3D: (a, hx, hy, hxx, hxy, hyy)
        hx, hy, hxx, hxy, hyy = c[1], c[2], c[3], c[4], c[5]
        q = 1.0 + hx * hx + hy * hy
        H = -((1.0 + hy * hy) * hxx - 2.0 * hx * hy * hxy + (1.0 + hx * hx) * hyy) / (
            q * ti.sqrt(q))
        K = (hxx * hyy - hxy * hxy) / (q * q)
    s = OFFSET
    return (H + 2.0 * K * s) / (1.0 + H * s + K * s * s)


@ti.data_oriented
class CurvatureTension:
    name = "curvature"
    pair_term = False

    def __init__(self, model: Model, grid: CellGrid, coef: Coefficients):
        self.grid, self.coef, self.state = grid, coef, grid.state
        self.dim = model.dim
        cap = self.state.capacity
        self.normal = ti.Vector.field(self.dim, float, cap)   # unit outward normal (pass 1)
        self.kappa = ti.field(float, cap)                     # curvature [1/m] (pass 2)
        k = 3 if self.dim == 2 else 6
        self.fit_sums = ti.types.struct(m=ti.types.matrix(k, k, float),
                                        b=ti.types.vector(k, float), f=ti.types.matrix(
                                            self.dim, self.dim, float), count=ti.i32,
                                        out=ti.i32)

    def nbytes(self) -> int:
        return field_nbytes(self.normal) + field_nbytes(self.kappa)

    def boundary_pressure(self, dt: float = 0.0) -> None:
        """kappa at r* (the two passes), then P = sigma kappa on the outer free-surface layer."""
        self._normals()
        self._fit()

    @ti.func
    def _free(self, i):
        return self.state.density[i] < self.coef.beta[None] * self.coef.n0[None]

    @ti.func
    def _normal_pair(self, i, j, rij, r2, acc: ti.template()):
        acc += rij / (r2 * ti.sqrt(r2))            # grad n / re (every kind, as S9)

    @ti.kernel
    def _normals(self):
        """Pass 1: n_i = -grad n / |grad n| for free-surface fluid particles, else 0."""
        for at in range(self.state.n[None]):
            i = self.state.spread(at)
            if self.state.kind[i] == FLUID:
                nv = ti.Vector.zero(float, self.dim)
                if self._free(i):
                    g = ti.Vector.zero(float, self.dim)
                    self.grid.for_each_neighbour(i, self.state.pos[i], self.coef.re2[None],
                                                 self._normal_pair, g)
                    gl = g.norm()
                    if gl > 0.0:
                        nv = -g / gl
                self.normal[i] = nv

    @ti.func
    def _fit_pair(self, i, j, rij, r2, acc: ti.template()):
        kind_j = self.state.kind[j]
        if kind_j == FLUID or kind_j == WALL:
            x = acc.f @ (rij / self.coef.l0[None])   # local coordinates, in l0
            h = x[self.dim - 1]
            if h > LAYER:
                acc.out += 1                          # i lies under the surface layer
            elif h > -LAYER and kind_j == FLUID:
                phi = monomials(x)
                w = weight(ti.sqrt(r2), self.coef.re[None])      # (S10)
                acc.m += w * phi.outer_product(phi)
                acc.b += w * h * phi
                acc.count += 1

    @ti.kernel
    def _fit(self):
        """Pass 2: kappa from the surface fit (module docstring); P = sigma kappa where i is in
        the outer layer and the fit is regular."""
        k = ti.static(3 if self.dim == 2 else 6)
        w_self = weight(self.coef.l0[None], self.coef.re[None])    # w(l0), i itself at t = 0
        for at in range(self.state.n[None]):
            i = self.state.spread(at)
            if self.state.kind[i] == FLUID:
                kap = 0.0
                n = self.normal[i]
                if n.dot(n) > 0.5:
                    acc = self.fit_sums(m=ti.Matrix.zero(float, k, k), b=ti.Vector.zero(float, k),
                                        f=frame(n), count=0, out=0)
                    acc.m[0, 0] += w_self
                    self.grid.for_each_neighbour(i, self.state.pos[i], self.coef.re2[None],
                                                 self._fit_pair, acc)
                    if acc.out == 0 and acc.count + 1 >= k:
                        c, ok = solve_spd(acc.m, acc.b)
                        if ok == 1:
                            cap = ti.static(float(self.dim - 1))
                            kap = ti.min(ti.max(fit_curvature(c), -cap), cap) / self.coef.l0[None]
                            self.state.pressure[i] = self.coef.sigma[None] * kap
                self.kappa[i] = kap
