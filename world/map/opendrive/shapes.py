"""Exact evaluation of one planView record in its local frame (u along the record's start
heading, v to its left), as functions of the station `ds` past the record's start.

- line, arc: closed form (the arc via `sinc`, exact also at curvature 0);
- spiral: the clothoid closed form with `scipy.special.fresnel` (curvature k0 + c ds, any
  signs, k0 != 0 by completing the square). Where that form is ill-conditioned (|k0/c| large:
  Cephes' Fresnel integrals lose the phase) it is integrated by composite Gauss-Legendre
  quadrature of exp(i heading) instead (panels of at most 0.5 rad heading change, 16 nodes
  each, their sums tabulated once per record). Both are exact to rounding (checked against
  DOP853 integration: < 1e-11 m over hundreds of metres). A curvature rate whose effect on the
  heading is below 1e-12 rad over the record is an arc (a line at curvature 0);
- poly3 and paramPoly3: the station is the arc length along the curve. It is tabulated with
  16-node Gauss-Legendre quadrature on 64 panels of the parameter and inverted by Newton's
  method from the tabulated guess (to ~1e-12 relative, for curves whose speed |dr/dp| stays
  clear of 0: a cusp is not resolved). poly3's u runs from 0 to where the arc length reaches
  the record's length; paramPoly3's p runs over [0, 1] ("normalized") or [0, length]
  ("arcLength": the parameter domain as in esmini) and the station is its arc length scaled
  so that the record's end is the curve's end, as esmini does (the scale is 1 when the file's
  length is the curve's; otherwise stations are not exactly arc lengths).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray
from scipy.special import fresnel

from world.map.opendrive.model import Arc, Geometry, Line, Poly3Shape, Spiral

FloatArray = NDArray[np.float64]
Local = tuple[FloatArray, FloatArray, FloatArray]  # u [m], v [m], local heading [rad]

GL_X, GL_W = np.polynomial.legendre.leggauss(16)
PANELS = 64  # arc-length table panels of a polynomial curve
RATE_IS_ZERO = 1e-12  # [rad] heading effect of a spiral's curvature rate below which it is an arc
FRESNEL_CONDITION = 1e5  # [m] |k0/c| above which the spiral is integrated numerically
PANEL_TURN = 0.5  # [rad] heading change per quadrature panel of an ill-conditioned spiral
CURVATURE_SAMPLES = 1025  # [-] parameters where a polynomial curve's curvature is checked


class LocalCurve:
    """A record's shape, evaluated at stations ds in [0, length] [m]."""

    def local(self, ds: FloatArray) -> Local:
        """u, v [m] and heading [rad, unwrapped] relative to the record's start frame."""
        return ds.copy(), np.zeros_like(ds), np.zeros_like(ds)

    def curvature(self, ds: FloatArray) -> FloatArray:
        """[1/m] + turns left."""
        return np.zeros_like(ds)


def _arc_local(k: float, ds: FloatArray) -> tuple[FloatArray, FloatArray]:
    th = k * ds
    return ds * np.sinc(th / np.pi), ds * np.sin(th / 2) * np.sinc(th / (2 * np.pi))


class ArcCurve(LocalCurve):
    def __init__(self, k: float) -> None:
        self.k = k

    def local(self, ds: FloatArray) -> Local:
        u, v = _arc_local(self.k, ds)
        return u, v, self.k * ds

    def curvature(self, ds: FloatArray) -> FloatArray:
        return np.full_like(ds, self.k)


class SpiralCurve(LocalCurve):
    def __init__(self, k0: float, k1: float, length: float) -> None:
        self.k0 = k0
        self.c = (k1 - k0) / length if length > 0 else 0.0  # [1/m^2]
        self.length = length
        turn = abs(k0) * length + abs(self.c) * length**2 / 2
        self.panels = max(1, int(np.ceil(turn / PANEL_TURN)))
        self._cum: NDArray[np.complex128] | None = None
        self._edges = np.zeros(1)

    def heading(self, ds: FloatArray) -> FloatArray:
        return np.asarray(ds * (self.k0 + 0.5 * self.c * ds), dtype=float)

    def local(self, ds: FloatArray) -> Local:
        h = self.heading(ds)
        if abs(self.c) * self.length**2 < RATE_IS_ZERO:
            u, v = _arc_local(self.k0, ds)
        elif abs(self.k0 / self.c) < FRESNEL_CONDITION:
            u, v = self._fresnel(ds)
        else:
            u, v = self._quadrature(ds)
        return u, v, h

    def _fresnel(self, ds: FloatArray) -> tuple[FloatArray, FloatArray]:
        # heading = c/2 (ds + a)^2 - c/2 a^2 with a = k0/c; t = (ds + a) sqrt(|c|/pi)
        c, a = self.c, self.k0 / self.c
        q = np.sqrt(abs(c) / np.pi)
        s0, c0 = fresnel(a * q)
        s1, c1 = fresnel((ds + a) * q)
        w = np.sqrt(np.pi / abs(c)) * ((c1 - c0) + 1j * np.sign(c) * (s1 - s0))
        w = w * np.exp(-0.5j * c * a * a)
        return np.asarray(w.real, dtype=float), np.asarray(w.imag, dtype=float)

    def _panel(self, a: FloatArray, b: FloatArray) -> NDArray[np.complex128]:
        """The integral of exp(i heading) from `a` to `b` (16-node Gauss-Legendre)."""
        half = (b - a) / 2
        nodes = ((a + b) / 2)[..., None] + half[..., None] * GL_X
        e = np.exp(1j * self.heading(nodes))
        return np.asarray(half * np.sum(GL_W * e, axis=-1), dtype=np.complex128)

    def _quadrature(self, ds: FloatArray) -> tuple[FloatArray, FloatArray]:
        if self._cum is None:  # the integral up to each panel edge, once
            edges = np.linspace(0.0, self.length, self.panels + 1)
            pieces = self._panel(edges[:-1], edges[1:])
            self._edges = edges
            self._cum = np.concatenate([[0.0 + 0.0j], np.cumsum(pieces)])
        j = np.clip((ds / self.length * self.panels).astype(int), 0, self.panels - 1)
        w = self._cum[j] + self._panel(self._edges[j], ds)
        return np.asarray(w.real, dtype=float), np.asarray(w.imag, dtype=float)

    def curvature(self, ds: FloatArray) -> FloatArray:
        return np.asarray(self.k0 + self.c * ds, dtype=float)


class PolyCurve(LocalCurve):
    """u(p), v(p) cubics (coefficients ascending) on p in [0, p_end], station = arc length
    times `scale`."""

    def __init__(self, cu: FloatArray, cv: FloatArray, p_end: float | None, length: float):
        self.cu, self.cv = cu, cv
        self.du = np.array([cu[1], 2 * cu[2], 3 * cu[3]])
        self.dv = np.array([cv[1], 2 * cv[2], 3 * cv[3]])
        top = length if p_end is None else p_end  # poly3: u_end <= length (arc >= chord)
        self.p_nodes = np.linspace(0.0, top, PANELS + 1)
        pieces = self._integral(self.p_nodes[:-1], self.p_nodes[1:])
        self.cum = np.concatenate([[0.0], np.cumsum(pieces)])
        self.scale = 1.0
        if p_end is None:  # poly3: the curve ends where its arc length is the record's
            p_end = float(self._invert(np.array([min(length, self.cum[-1])]))[0])
        elif length > 0:  # 0 for a curve of no length: no station reaches its end
            self.scale = self.cum[-1] / length
        self.p_end = p_end
        self.h0 = float(np.arctan2(self.dv[0], self.du[0]))  # [rad] the start tangent's
        self.c0, self.s0 = np.cos(self.h0), np.sin(self.h0)

    def max_curvature(self, samples: int = CURVATURE_SAMPLES) -> float:
        """[1/m] the largest |curvature| at `samples` parameters evenly over [0, p_end] (inf
        where the curve stops: a cusp, or no curve at all)."""
        p = np.linspace(0.0, self.p_end, samples)
        pv = np.polynomial.polynomial.polyval
        du, dv = pv(p, self.du), pv(p, self.dv)
        ddu = pv(p, np.polynomial.polynomial.polyder(self.du))
        ddv = pv(p, np.polynomial.polynomial.polyder(self.dv))
        cross, speed = np.abs(du * ddv - dv * ddu), np.hypot(du, dv)
        with np.errstate(divide="ignore", invalid="ignore"):
            k = np.where(speed > 0.0, cross / np.maximum(speed, 1e-300) ** 3, np.inf)
        return float(np.max(k))

    def _speed(self, p: FloatArray) -> FloatArray:
        du = np.polynomial.polynomial.polyval(p, self.du)
        dv = np.polynomial.polynomial.polyval(p, self.dv)
        return np.asarray(np.hypot(du, dv), dtype=float)

    def _integral(self, p0: FloatArray, p1: FloatArray) -> FloatArray:
        half = (p1 - p0) / 2
        nodes = ((p1 + p0) / 2)[..., None] + half[..., None] * GL_X
        return np.asarray(half * np.sum(GL_W * self._speed(nodes), axis=-1), dtype=float)

    def _invert(self, target: FloatArray) -> FloatArray:
        """p with arc length `target` [m] from p = 0 (within the table)."""
        target = np.clip(target, 0.0, self.cum[-1])
        i = np.clip(np.searchsorted(self.cum, target, side="right") - 1, 0, PANELS - 1)
        lo, hi = self.p_nodes[i], self.p_nodes[i + 1]
        span = self.cum[i + 1] - self.cum[i]
        frac = np.where(span > 0, (target - self.cum[i]) / np.where(span > 0, span, 1.0), 0.0)
        p = lo + frac * (hi - lo)
        for _ in range(8):
            err = self.cum[i] + self._integral(lo, p) - target
            p = np.clip(p - err / np.maximum(self._speed(p), 1e-300), lo, hi)
        return np.asarray(p, dtype=float)

    def param(self, ds: FloatArray) -> FloatArray:
        return self._invert(ds * self.scale)

    def local(self, ds: FloatArray) -> Local:
        p = self.param(ds)
        pv = np.polynomial.polynomial.polyval
        u, v = pv(p, self.cu), pv(p, self.cv)
        du, dv = pv(p, self.du), pv(p, self.dv)
        # relative to the start tangent: continuous unless the curve turns half a turn
        h = self.h0 + np.arctan2(dv * self.c0 - du * self.s0, du * self.c0 + dv * self.s0)
        return np.asarray(u, dtype=float), np.asarray(v, dtype=float), np.asarray(h, dtype=float)

    def curvature(self, ds: FloatArray) -> FloatArray:
        p = self.param(ds)
        pv = np.polynomial.polynomial.polyval
        du, dv = pv(p, self.du), pv(p, self.dv)
        ddu, ddv = (
            pv(p, np.polynomial.polynomial.polyder(self.du)),
            pv(p, np.polynomial.polynomial.polyder(self.dv)),
        )
        sp = np.maximum(np.hypot(du, dv), 1e-300)
        return np.asarray((du * ddv - dv * ddu) / sp**3, dtype=float)


def local_curve(geom: Geometry) -> LocalCurve:
    """The evaluator of one record."""
    sh, length = geom.shape, geom.length
    if isinstance(sh, Line):
        return LocalCurve()
    if isinstance(sh, Arc):
        return ArcCurve(sh.curvature)
    if isinstance(sh, Spiral):
        return SpiralCurve(sh.curv_start, sh.curv_end, length)
    if isinstance(sh, Poly3Shape):
        return PolyCurve(
            np.array([0.0, 1.0, 0.0, 0.0]), np.array([sh.a, sh.b, sh.c, sh.d]), None, length
        )
    p_end = 1.0 if sh.p_range == "normalized" else length
    return PolyCurve(
        np.array([sh.au, sh.bu, sh.cu, sh.du]),
        np.array([sh.av, sh.bv, sh.cv, sh.dv]),
        p_end,
        length,
    )
