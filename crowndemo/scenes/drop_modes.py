"""A free viscous drop's exact normal modes (method.md §7): the frequency and decay of shape
mode n at any viscosity, of which Rayleigh's frequency and Lamb's decay are the limits as the
viscosity vanishes.

The linearised Navier-Stokes equations in a drop of radius R with a free surface (no outer
fluid), time dependence exp(lambda t): the velocity is a potential part, phi = A r^n Y_n
(pressure p = -rho lambda phi), plus a vortical part that diffuses, its radial function
g(r) = j_n(k r) in 3D (the poloidal field curl curl (r g Y_n)), J_n(k r) in 2D (the stream
function g sin n theta), k^2 = -lambda / nu. A surface displaced by zeta Y_n carries no shear
stress, a normal stress p - 2 mu du_r/dr = sigma's curvature jump, and moves with u_r: three
linear conditions on (A, B, zeta), whose determinant is zero at a mode (in 3D Chandrasekhar,
Proc. London Math. Soc. 9, 1959, and Reid, Q. Appl. Math. 18, 1960; in 2D the same
derivation for a liquid cylinder's planar modes). With nu = 0 the root is lambda = i omega0,
omega0^2 = n (n - 1)(n + 2) sigma / (rho R^3) in 3D and n (n^2 - 1) sigma / (rho R^3) in 2D;
for small nu, Re lambda = -(n - 1)(2 n + 1) nu / R^2 (3D), -2 n (n - 1) nu / R^2 (2D), Lamb's
rates; the next terms go as nu^(3/2). numpy only (a Newton iteration on the complex root
from Lamb's estimate, followed in small steps of nu where the drop is viscous).
"""
from __future__ import annotations

import math
from typing import Tuple

import numpy as np

_QUAD = 256      # points of the trapezoid rule for J_n in 2D (periodic: exponential accuracy)


def rayleigh_omega(dim: int, n: int, radius: float, sigma: float, rho: float) -> float:
    """Rayleigh's angular frequency of mode n, the inviscid limit: omega0^2 = n (n - 1)(n + 2)
    sigma / (rho R^3) in 3D, n (n^2 - 1) sigma / (rho R^3) in 2D."""
    restoring = (n - 1) * (n + 2) if dim == 3 else n * n - 1
    return math.sqrt(n * restoring * sigma / (rho * radius ** 3))


def lamb_decay(dim: int, n: int, radius: float, nu: float) -> float:
    """Lamb's decay rate of mode n's amplitude, the small-viscosity limit: (n - 1)(2 n + 1)
    nu / R^2 in 3D, 2 n (n - 1) nu / R^2 in 2D."""
    return ((n - 1) * (2 * n + 1) if dim == 3 else 2 * n * (n - 1)) * nu / radius ** 2


def _radial(dim: int, n: int, z: complex) -> Tuple[complex, complex]:
    """(g, dg/dz) of the vortical part's radial function, both times exp(-|Im z|) (the same
    factor, which the determinant's B column drops; unscaled they overflow where nu is
    small): the spherical Bessel j_n(z) in 3D, the Bessel J_n(z) in 2D (Bessel's integral)."""
    def cos_sin(w):      # cos w, sin w times exp(-|Im z|), |Im w| <= |Im z|
        a, b = np.exp(1j * w - abs(z.imag)), np.exp(-1j * w - abs(z.imag))
        return (a + b) / 2, (a - b) / 2j
    if dim == 3:
        # j_n by upward recurrence from j_0, j_1: stable while n < |z| = R (omega / nu)^(1/2),
        # the drop's radius over the vortical layer's thickness (n <= 80 in the tests)
        c, s = cos_sin(z)
        j = [s / z, s / z ** 2 - c / z]
        for m in range(1, n + 1):
            j.append((2 * m + 1) / z * j[m] - j[m - 1])
        return j[n], j[n - 1] - (n + 1) / z * j[n]
    # the integrand turns |z| times a period: enough points for the trapezoid rule
    tau = np.linspace(0.0, 2.0 * math.pi, max(_QUAD, 8 * int(abs(z))), endpoint=False)

    def bessel(m: int) -> complex:
        return complex(np.mean(cos_sin(m * tau - z * np.sin(tau))[0]))
    return bessel(n), 0.5 * (bessel(n - 1) - bessel(n + 1))


def _determinant(dim: int, n: int, lam: complex, nu: float, gamma: float) -> complex:
    """The three surface conditions' determinant at growth rate lam (R = 1; gamma = the
    curvature's restoring term, so omega0^2 = n gamma)."""
    k = np.sqrt(complex(-lam / nu))
    g, dg = _radial(dim, n, k)
    q = k * dg / g              # g'(R) / g(R): the B column is divided by g (g -> 1 below)
    L = n * (n + 1) if dim == 3 else n             # u_r = n A r^(n-1) + L B g / r
    shear_a = 2 * (n - 1) if dim == 3 else 2 * n * (n - 1)
    shear_g = 2 * L - 2 if dim == 3 else 2 * n * n
    rows = np.array([
        [shear_a, -2 * q - k * k + shear_g, 0.0],                                # no shear
        [-lam - 2 * nu * n * (n - 1), -2 * nu * L * (q - 1), -gamma],             # normal stress
        [n, L, -lam]], dtype=complex)                                             # kinematic
    return complex(np.linalg.det(rows))


def viscous_mode(dim: int, n: int, radius: float, sigma: float, rho: float,
                 nu: float) -> Tuple[float, float]:
    """(omega, decay) of a free drop's shape mode n [rad/s, 1/s]: the oscillation's angular
    frequency and its amplitude's decay rate, exp(-decay t) cos(omega t). Beyond the viscosity
    where the mode stops oscillating (3D mode 2: nu ~ 0.27 omega0 R^2) omega = 0 and decay is
    the root followed there; ArithmeticError where the root is lost (far beyond it)."""
    if dim not in (2, 3) or n < 2:
        raise ValueError(f"viscous_mode: dim 2 or 3 and n >= 2, got dim={dim}, n={n}")
    omega0 = rayleigh_omega(dim, n, radius, sigma, rho)
    if nu <= 0.0:
        return omega0, 0.0
    gamma = 1.0 / n                                # units: R = 1, omega0 = 1
    nu_hat = nu / (omega0 * radius ** 2)
    steps = max(1, int(math.ceil(nu_hat / 1e-3)))   # follow the root from small nu
    lam = complex(-lamb_decay(dim, n, 1.0, nu_hat / steps), 1.0)   # Lamb's, at the first step
    for s in range(1, steps + 1):
        nu_s = nu_hat * s / steps
        for _ in range(60):
            f = _determinant(dim, n, lam, nu_s, gamma)
            h = 1e-7 * max(1.0, abs(lam))
            step = f / ((_determinant(dim, n, lam + h, nu_s, gamma) - f) / h)
            lam -= step
            if abs(step) < 1e-12 * max(1.0, abs(lam)):
                break
        else:
            raise ArithmeticError(f"viscous_mode: no root at nu R^-2 omega0^-1 = {nu_s:.3g}")
    return abs(lam.imag) * omega0, -lam.real * omega0
