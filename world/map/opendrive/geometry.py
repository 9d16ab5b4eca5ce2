"""A road's reference line (its planView): exact pose, curvature and projection, vectorised
over stations. Beyond its ends the line carries straight on along its end headings."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.spatial import cKDTree

from world.map.opendrive.model import Geometry
from world.map.opendrive.shapes import LocalCurve, local_curve

FloatArray = NDArray[np.float64]
PROJECT_STEP = 0.5  # [m] the coarse sampling of `project`'s first guess
PROJECT_TOL = 1e-9  # [m] Newton stops when the along-line residual is below this


def wrap(angle: ArrayLike) -> FloatArray:
    """`angle` [rad] in [-pi, pi)."""
    return np.asarray((np.asarray(angle, dtype=float) + np.pi) % (2 * np.pi) - np.pi, dtype=float)


@dataclass(frozen=True, slots=True)
class PlanView:
    """The planView records of a road in ascending `s` (at least one)."""

    geometries: tuple[Geometry, ...]
    _curves: tuple[LocalCurve, ...] = field(init=False, repr=False, compare=False)
    _starts: FloatArray = field(init=False, repr=False, compare=False)
    _tree: list[tuple[cKDTree, FloatArray]] = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        if not self.geometries:
            raise ValueError("a planView needs at least one geometry")
        object.__setattr__(self, "_curves", tuple(local_curve(g) for g in self.geometries))
        object.__setattr__(self, "_starts", np.array([g.s for g in self.geometries]))
        object.__setattr__(self, "_tree", [])

    @property
    def curves(self) -> tuple[LocalCurve, ...]:
        """Each record's evaluator in its local frame (`shapes.local_curve`)."""
        return self._curves

    def record_ends(self) -> tuple[FloatArray, FloatArray, FloatArray]:
        """x, y [m] and heading [rad, not wrapped] where each record ends, evaluated on the
        record itself (whatever the next record's start says)."""
        n = len(self.geometries)
        x, y, h = np.empty(n), np.empty(n), np.empty(n)
        for i, (g, curve) in enumerate(zip(self.geometries, self._curves, strict=True)):
            u, v, lh = curve.local(np.array([g.length]))
            c, sn = np.cos(g.hdg), np.sin(g.hdg)
            x[i] = g.x + c * u[0] - sn * v[0]
            y[i] = g.y + sn * u[0] + c * v[0]
            h[i] = g.hdg + lh[0]
        return x, y, h

    @property
    def start(self) -> float:
        """[m] the station of the first record (normally 0)."""
        return self.geometries[0].s

    @property
    def length(self) -> float:
        """[m] from the first record's start to the last record's end."""
        last = self.geometries[-1]
        return last.s + last.length - self.start

    @property
    def end(self) -> float:
        """[m] the station of the last record's end."""
        return self.start + self.length

    def record_index(self, s: ArrayLike) -> NDArray[np.intp]:
        """The record holding each station (the first/last one beyond the ends)."""
        st = np.asarray(s, dtype=float)
        i = np.searchsorted(self._starts, st, side="right") - 1
        return np.asarray(np.clip(i, 0, len(self.geometries) - 1), dtype=np.intp)

    def pose_unwrapped(self, s: ArrayLike) -> tuple[FloatArray, FloatArray, FloatArray]:
        """x, y [m] and the heading [rad] (record start heading + turn, not wrapped)."""
        st = np.asarray(s, dtype=float)
        flat = st.reshape(-1)
        x, y, h = (np.empty_like(flat) for _ in range(3))
        idx = self.record_index(flat)
        for i in np.unique(idx):
            m = idx == i
            g, curve = self.geometries[i], self._curves[i]
            ds = flat[m] - g.s
            inside = np.clip(ds, 0.0, g.length)
            extra = ds - inside  # beyond the ends only (< 0 before the first record)
            u, v, lh = curve.local(inside)
            c, sn = np.cos(g.hdg), np.sin(g.hdg)
            hh = g.hdg + lh
            x[m] = g.x + c * u - sn * v + extra * np.cos(hh)
            y[m] = g.y + sn * u + c * v + extra * np.sin(hh)
            h[m] = hh
        return x.reshape(st.shape), y.reshape(st.shape), h.reshape(st.shape)

    def pose(self, s: ArrayLike) -> tuple[FloatArray, FloatArray, FloatArray]:
        """x, y [m] and heading [rad, in [-pi, pi)] of the reference line at stations `s`."""
        x, y, h = self.pose_unwrapped(s)
        return x, y, wrap(h)

    def curvature(self, s: ArrayLike) -> FloatArray:
        """[1/m] + turning left; 0 beyond the ends."""
        st = np.asarray(s, dtype=float)
        flat = st.reshape(-1)
        out = np.zeros_like(flat)
        idx = self.record_index(flat)
        for i in np.unique(idx):
            m = idx == i
            g = self.geometries[i]
            ds = flat[m] - g.s
            inside = (ds >= 0) & (ds <= g.length)
            k = self._curves[i].curvature(np.clip(ds, 0.0, g.length))
            out[m] = np.where(inside, k, 0.0)
        return out.reshape(st.shape)

    def _samples(self) -> tuple[cKDTree, FloatArray]:
        if not self._tree:
            n = max(2, int(np.ceil(self.length / PROJECT_STEP)) + 1)
            st = np.unique(np.concatenate([np.linspace(self.start, self.end, n), self._starts]))
            x, y, _ = self.pose_unwrapped(st)
            self._tree.append((cKDTree(np.column_stack([x, y])), st))
        return self._tree[0]

    def project(self, xy: ArrayLike) -> tuple[FloatArray, FloatArray]:
        """Station s [m] and signed lateral offset t [m, left +] of map points `xy` (shape
        (..., 2)): the nearest sample of the line as a first guess, then Newton on the exact
        curve (along-line residual < 1e-9 m). Beyond the ends s runs on along the straight
        extensions."""
        pts = np.asarray(xy, dtype=float)
        flat = pts.reshape(-1, 2)
        tree, st = self._samples()
        _, j = tree.query(flat)
        s = st[j].astype(float)
        t = np.zeros(len(s))
        for _ in range(30):
            x, y, h = self.pose_unwrapped(s)
            dx, dy = flat[:, 0] - x, flat[:, 1] - y
            c, sn = np.cos(h), np.sin(h)
            along = dx * c + dy * sn
            t = -dx * sn + dy * c
            k = self.curvature(s)
            denom = 1.0 - k * t
            step = along / np.where(np.abs(denom) > 0.1, denom, 1.0)
            s = s + np.clip(step, -PROJECT_STEP * 4, PROJECT_STEP * 4)
            if np.all(np.abs(along) < PROJECT_TOL):
                break
        x, y, h = self.pose_unwrapped(s)
        t = -(flat[:, 0] - x) * np.sin(h) + (flat[:, 1] - y) * np.cos(h)
        shape = pts.shape[:-1]
        return s.reshape(shape), t.reshape(shape)
