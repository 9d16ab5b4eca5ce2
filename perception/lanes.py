"""Lane finding on the front camera: the ego lane's boundaries, offset, heading and curvature.

The camera pipeline of ICCAS 2020 Fig. 4(a): `LaneDetector` works one frame at a time,
`LaneFilter` filters its output over time. Input: a `CameraFrame`, (H, W, 3) RGB. Output: a
`LaneEstimate` in the vehicle frame at the frame's time (x forward from the car's centre, y
left, origin on the ground), in m, rad and 1/m.

1. **Paint mask**, on the band of image rows the bird's-eye view sees (from beyond the hood),
   in OpenCV's 8-bit HLS (hue 0..179 in 2 deg units, lightness L and saturation S 0..255).
   Paint is white (L >= ``white_min_lightness``, S <= ``white_max_saturation``: bright and
   grey, where asphalt is darker and grass saturated), yellow (hue in ``yellow_hue``, S >=
   ``yellow_min_saturation``, L >= ``yellow_min_lightness``) or a ridge: a grey pixel (S <=
   ``white_max_saturation``, L >= ``ridge_min_lightness``) with a rising edge within
   ``ridge_max_width`` px to its left and a falling one within as far to its right, an edge
   being |Sobel x| / 4 (3 x 3 kernel: the vertically smoothed L(u + 1) - L(u - 1)) >=
   ``ridge_min_gradient``. Ridges keep the distant lines that texture filtering blurs below
   the white test, over their whole width (their two flanks alone, of unequal contrast, would
   bias the position); the border of the shoulder or the grass is one step, not a pair.

2. **Bird's-eye view** (`perception.birdseye`): the mask is warped (bilinear) onto ``grid``
   on the ground plane z = 0; a cell is paint where the warp reaches ``mask_min_coverage``,
   except in runs across the view (along y) at least ``max_paint_width`` wide (`narrow_only`):
   a line is 0.15 m wide and the double centre line 0.45 m, but a vertical face (a truck's
   side, which may pass the colour tests) smears over metres of the ground plane.

3. **Bases**: the view is cut into windows of ``window_length`` along x. In the windows up to
   ``base_reach`` beyond the nearest (dashed lines have 3 m of paint every 12 m), a histogram
   of the paint's y (bins of ``base_bin``) on each side, |y| in [``base_inner``,
   ``base_outer``], gives the side's base in the first window with a bin of
   ``base_min_pixels``: the bin nearest the car (the ego lane's boundaries are the nearest
   lines), its y the mean of the paint within ``base_refine``. A prior with confidence >=
   ``prior_min_confidence`` moves the search to within ``prior_margin`` of its boundary, and
   the bin nearest that boundary is taken.

4. **Sliding windows**: window by window from its base, each side takes the cells within a
   margin of a predicted line; ``window_min_pixels`` of them make a hit, which adds their
   centroid. The prediction is the fit of the side's own centroids (quadratic from a span of
   ``quadratic_min_span``, linear from ``linear_min_span``); while that fit is shorter than
   the other side's and not quadratic, the other side's fit moved through this side's last
   centroid (the boundaries are parallel: a dashed line follows a solid one through its
   gaps); before any fit, the prior's boundary (else a line parallel to the car) through the
   base. The margin is ``window_margin`` plus ``window_margin_growth`` per metre since the
   last hit, at most ``window_margin_max``. A side stops when its prediction leaves the view.

5. **Fits**: each boundary y = c0 + c1 x + c2 x^2 by least squares on its hit cells (degree
   by span as in step 4, else 0), refitted once without the cells farther than
   ``outlier_distance`` from the first fit. A cell's weight (1 / sigma) is
   d^-``weight_power``, d [m] its depth in front of the camera: a pixel's ground footprint
   grows as d across and d^2 along, texture filtering displaces far lines and a quadratic fits
   less well far ahead, so the near lines decide the offset and heading, the far ones the
   curvature. With both boundaries, the centre line y = a0 + a1 x + a2 x^2 is one weighted fit
   of both boundaries' cells as curves concentric with it (own c0 each, a0 their mean, shared
   a1, a2 scaled by 1 / (1 - 2 a2 d) for a boundary d left of the centre): the better-seen
   line carries the shape. At x = 0: offset = -a0 (car left of the centre +), heading_error =
   -atan(a1), curvature = 2 a2 (left turn +), width = (c0_left - c0_right) cos(atan(a1)); the
   pair is trusted if the width is within [``min_width``, ``max_width``] and the pair
   straddles the car (c0_left > 0 > c0_right). Otherwise, or with one boundary, the other is
   searched again (steps 3-4) a lane width (the HD map's at the car when the caller gives
   it, else the prior's, else ``default_width``) across from
   the one first seen nearest the car (of equals, the better-seen): on a tight curve a dashed
   line whose first dash is far may have crossed the car's axis, where step 3 misses it.
   Failing that, the centre is that line shifted half a width across.

6. **Confidence** in [0, 1]: per side min(1, hits / ``full_windows``) min(1, span /
   ``full_span``), span being the fitted length along x; the mean of both sides (a missing
   side scores 0, so one boundary gives at most 0.5).

`LaneFilter` then runs a Kalman filter on (offset, heading_error, curvature, width).

Limits: the ground is taken as the plane z = 0 of the vehicle frame, so the body's pitch and
roll, and a camera height error, scale the lateral metres (as 1 / camera height); one
quadratic cannot follow a curvature step (a straight into an arc) inside the view, so near
such a step the heading at the car is biased (the filter's gate and smoothing damp it).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import cv2
import numpy as np
from numpy.typing import NDArray
from scipy.special import gammaincinv

from perception.birdseye import BevGrid, BirdseyeView
from perception.messages import LaneBoundary, LaneEstimate
from world.frames import CameraFrame, CameraInfo

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.intp]
Coefficients = tuple[float, float, float]  # (c0 [m], c1 [-], c2 [1/m]) of y = c0 + c1 x + c2 x^2

LEFT, RIGHT = 1, -1  # side signs: y of the side's boundary has this sign


@dataclass(frozen=True, slots=True)
class LaneParams:
    """Thresholds of `LaneDetector`, by step of the module docstring."""

    grid: BevGrid = field(default_factory=BevGrid)  # [m] the bird's-eye view, vehicle frame
    # -- mask, OpenCV 8-bit HLS: hue [2 deg units] 0..179, lightness and saturation 0..255
    white_min_lightness: int = 130  # [0..255] above asphalt, shoulder and grass
    white_max_saturation: int = 60  # [0..255] also the ridge pixels' greyness limit
    yellow_hue: tuple[int, int] = (15, 35)  # [2 deg] inclusive band
    yellow_min_saturation: int = 80  # [0..255]
    yellow_min_lightness: int = 60  # [0..255]
    ridge_min_lightness: int = 85  # [0..255] above the asphalt's texture noise
    ridge_min_gradient: float = 5.0  # [lightness] |Sobel x| / 4 at a ridge's two flanks
    ridge_max_width: int = 12  # [px] rising to falling flank, in the image
    mask_min_coverage: int = 128  # [0..255] of the warped 0/255 mask
    max_paint_width: float = 1.0  # [m] wider runs across the view are not paint (car sides)
    # -- base search
    base_reach: float = 16.0  # [m] windows searched beyond the nearest (> a dash's gap)
    base_bin: float = 0.1  # [m] histogram bin
    base_min_pixels: int = 12  # [cells] in a bin
    base_inner: float = 0.3  # [m] nearest |y| of a base (no prior)
    base_outer: float = 3.2  # [m] farthest |y| of a base (no prior)
    base_refine: float = 0.3  # [m] half width around the bin the base y is averaged over
    prior_margin: float = 0.7  # [m] half width of the search around the prior's boundary
    prior_min_confidence: float = 0.3  # [-] a prior less confident than this is ignored
    # -- sliding windows
    window_length: float = 2.0  # [m] along x
    window_margin: float = 0.35  # [m] half width around the prediction after a hit
    window_margin_growth: float = 0.06  # [m/m] per metre since the last hit
    window_margin_max: float = 1.0  # [m] well short of the next line, a lane width away
    window_min_pixels: int = 20  # [cells] for a hit
    # -- fits
    quadratic_min_span: float = 8.0  # [m] x range for a quadratic (fits and predictions)
    linear_min_span: float = 1.0  # [m] x range for a linear fit
    outlier_distance: float = 0.25  # [m] cells farther from the first fit are dropped
    weight_power: float = 3.0  # [-] a cell's lateral sigma grows as (its depth)^weight_power
    # -- estimate and confidence
    default_width: float = 3.5  # [m] lane width with one boundary and no prior
    min_width: float = 2.5  # [m] plausible lane width
    max_width: float = 4.5  # [m]
    full_windows: int = 4  # [-] windows with paint for a side's full score
    full_span: float = 15.0  # [m] fitted length for a side's full score


# ---- mask -----------------------------------------------------------------------------------


def lane_mask(rgb: NDArray[np.uint8], p: LaneParams) -> NDArray[np.uint8]:
    """(H, W) 0/255 paint mask of an RGB image (band): white | yellow | light ridge."""
    hls = cv2.cvtColor(rgb, cv2.COLOR_RGB2HLS)
    white = cv2.inRange(hls, (0, p.white_min_lightness, 0), (180, 255, p.white_max_saturation))
    yellow = cv2.inRange(hls, (p.yellow_hue[0], p.yellow_min_lightness, p.yellow_min_saturation),
                         (p.yellow_hue[1], 255, 255))
    grey = cv2.inRange(hls, (0, p.ridge_min_lightness, 0), (180, 255, p.white_max_saturation))
    sobel = cv2.Sobel(hls[:, :, 1], cv2.CV_16S, 1, 0, ksize=3)  # 4 x lightness per pixel
    step = round(4.0 * p.ridge_min_gradient)
    rising = cv2.inRange(sobel, step, 32767)
    falling = cv2.inRange(sobel, -32768, -step)
    reach = np.ones((1, p.ridge_max_width + 1), np.uint8)
    rise_left = cv2.dilate(rising, reach, anchor=(p.ridge_max_width, 0))  # rise at u-w .. u
    fall_right = cv2.dilate(falling, reach, anchor=(0, 0))  # fall at u .. u+w
    ridge = cv2.bitwise_and(cv2.bitwise_and(rise_left, fall_right), grey)
    paint = cv2.bitwise_or(white, yellow)
    return np.asarray(cv2.bitwise_or(paint, ridge), dtype=np.uint8)


def narrow_only(bev_mask: NDArray[np.uint8], min_coverage: int,
                max_cells: int) -> NDArray[np.uint8]:
    """The paint cells of a warped mask without the runs across the view (along y) at least
    `max_cells` wide, and a cell either side of them: painted lines are 0.15 m wide (a double
    centre line 0.45 m), but a vehicle's or a wall's side, a vertical face, smears across the
    ground plane of a bird's-eye view far wider (a yellow truck passes the colour test)."""
    paint = np.where(bev_mask >= min_coverage, 255, 0).astype(np.uint8)
    wide = cv2.morphologyEx(paint, cv2.MORPH_OPEN, np.ones((1, max_cells), np.uint8))
    wide = cv2.dilate(wide, np.ones((1, 3), np.uint8))
    return np.asarray(cv2.bitwise_and(paint, cv2.bitwise_not(wide)), dtype=np.uint8)


def paint_cells(bev_mask: NDArray[np.uint8], grid: BevGrid,
                min_coverage: int) -> tuple[FloatArray, FloatArray]:
    """(x, y) [m] of the paint cells of a warped mask, sorted by ascending x."""
    rows, cols = np.nonzero(bev_mask >= min_coverage)  # row-major: x descending
    return grid.row_to_x(rows[::-1]), grid.col_to_y(cols[::-1])


# ---- polynomials ----------------------------------------------------------------------------


def poly_y(c: Coefficients, x: FloatArray | float) -> FloatArray:
    """[m] y = c0 + c1 x + c2 x^2 at x [m]."""
    xa = np.asarray(x, dtype=np.float64)
    return np.asarray(c[0] + (c[1] + c[2] * xa) * xa)


def fit_poly(x: FloatArray, y: FloatArray, p: LaneParams,
             w: FloatArray | None = None) -> Coefficients:
    """Least-squares y(x) [m] with residual weights ``w`` (1 / sigma), degree by the x span:
    2 (>= quadratic_min_span), 1 (>= linear_min_span), else 0 (the weighted mean)."""
    span = float(x.max() - x.min()) if len(x) else 0.0
    degree = 2 if span >= p.quadratic_min_span and len(x) >= 3 else 1 if (
        span >= p.linear_min_span and len(x) >= 2) else 0
    if degree == 0:
        return float(np.average(y, weights=None if w is None else w * w)), 0.0, 0.0
    a = np.vander(x, degree + 1, increasing=True)  # columns 1, x[, x^2]
    if w is not None:
        a, y = a * w[:, None], y * w
    c = np.linalg.solve(a.T @ a, a.T @ y)  # normal equations: 2 or 3 unknowns
    return float(c[0]), float(c[1]), float(c[2]) if degree == 2 else 0.0


def shifted_through(c: Coefficients, x: float, y: float) -> Coefficients:
    """``c`` moved sideways to pass through (x, y) [m]."""
    return y - float(poly_y((0.0, c[1], c[2]), x)), c[1], c[2]


def prior_boundary(prior: LaneEstimate, side: int) -> Coefficients:
    """The prior's boundary on ``side`` (+1 left, -1 right), half a width from its centre."""
    slope = -math.tan(prior.heading_error)
    half = 0.5 * prior.width / math.cos(math.atan(slope))
    return -prior.offset + side * half, slope, 0.5 * prior.curvature


# ---- base search ----------------------------------------------------------------------------


@dataclass(frozen=True, slots=True)
class _Windows:
    """The view's paint cells cut into windows along x."""

    x: FloatArray  # [m] cell x, ascending
    y: FloatArray  # [m] cell y
    w: FloatArray  # [-] cell fit weight (1 / sigma): (depth in front of the camera)^-power
    bounds: IntArray  # (n + 1,) cell index where each window starts (and the end)
    centres: FloatArray  # (n,) [m] window centre x

    @staticmethod
    def make(x: FloatArray, y: FloatArray, grid: BevGrid, length: float,
             camera_x: float, power: float) -> _Windows:
        """``camera_x`` [m]: the camera's forward position on the car; ``power``: of the
        depth in the weights."""
        n = max(1, round((grid.x_max - grid.x_min) / length))
        edges = grid.x_min + (grid.x_max - grid.x_min) * np.arange(n + 1) / n
        bounds = np.searchsorted(x, edges).astype(np.intp)
        return _Windows(x, y, (x - camera_x) ** -power, bounds, 0.5 * (edges[:-1] + edges[1:]))

    def fit_boundary(self, idx: IntArray, p: LaneParams) -> LaneBoundary:
        return fit_boundary(self.x[idx], self.y[idx], self.w[idx], p)

    def cells(self, k: int) -> slice:
        return slice(int(self.bounds[k]), int(self.bounds[k + 1]))


def _base_in_window(y: FloatArray, lo: float, hi: float, target: float,
                    p: LaneParams) -> float | None:
    """[m] the paint line in y (cells of one window) within [lo, hi] nearest ``target``."""
    inside = y[(y >= lo) & (y <= hi)]
    if len(inside) < p.base_min_pixels:
        return None
    n_bins = max(1, math.ceil((hi - lo) / p.base_bin))
    counts, edges = np.histogram(inside, bins=n_bins, range=(lo, hi))
    strong = np.flatnonzero(counts >= p.base_min_pixels)
    if len(strong) == 0:
        return None
    centres = 0.5 * (edges[strong] + edges[strong + 1])
    best = float(centres[np.argmin(np.abs(centres - target))])
    return float(np.mean(inside[np.abs(inside - best) <= p.base_refine]))


def _find_base(win: _Windows, side: int, guide: Coefficients | None,
              p: LaneParams) -> tuple[int, float] | None:
    """(window index, y [m]) where the boundary on ``side`` is first seen, or None.

    Without a guide (prior boundary) the line nearest the car within |y| in [base_inner,
    base_outer] on that side; with one, the line nearest the guide within prior_margin."""
    reach = win.centres[0] + p.base_reach
    for k in range(len(win.centres)):
        if win.centres[k] > reach:
            break
        if guide is None:
            lo, hi = sorted((side * p.base_inner, side * p.base_outer))
            target = 0.0
        else:
            target = float(poly_y(guide, float(win.centres[k])))
            lo, hi = target - p.prior_margin, target + p.prior_margin
        y = _base_in_window(win.y[win.cells(k)], lo, hi, target, p)
        if y is not None:
            return k, y
    return None


# ---- sliding windows ------------------------------------------------------------------------


@dataclass
class _Side:
    """One boundary's search state (mutable while the windows run)."""

    sign: int  # [-] LEFT or RIGHT
    start: int  # [-] first window index
    guide: Coefficients  # shape before own hits: the prior's boundary or a line through the base
    anchor: tuple[float, float]  # [m] (x, y) the borrowed shapes are moved through
    centroids_x: list[float] = field(default_factory=list)  # [m] hit window centroids
    centroids_y: list[float] = field(default_factory=list)  # [m]
    chunks: list[IntArray] = field(default_factory=list)  # [-] cell indices of hit windows
    last_x: float = 0.0  # [m] centre of the last hit window (or the base window)
    hits: int = 0  # [-] windows with paint
    active: bool = True
    fit: tuple[Coefficients, float] | None = None  # centroid fit and its x span [m]

    def add_hit(self, idx: IntArray, win: _Windows, xc: float, p: LaneParams) -> None:
        """Record window cells ``idx`` as a hit of the window centred at ``xc`` [m]."""
        self.chunks.append(idx)
        self.centroids_x.append(float(np.mean(win.x[idx])))
        self.centroids_y.append(float(np.mean(win.y[idx])))
        self.anchor = (self.centroids_x[-1], self.centroids_y[-1])
        self.last_x = xc
        self.hits += 1
        span = self.centroids_x[-1] - self.centroids_x[0]
        if span >= p.linear_min_span:
            self.fit = fit_poly(np.array(self.centroids_x), np.array(self.centroids_y), p), span

    def cell_indices(self) -> IntArray:
        return np.concatenate(self.chunks) if self.chunks else np.zeros(0, dtype=np.intp)


def _prediction(side: _Side, other: _Side | None, p: LaneParams) -> Coefficients:
    """The line the next window of ``side`` searches around (see module doc, step 4)."""
    own = side.fit
    theirs = other.fit if other is not None else None
    if own is not None and (theirs is None or own[1] >= min(theirs[1], p.quadratic_min_span)):
        return own[0]
    shape = theirs[0] if theirs is not None else own[0] if own is not None else side.guide
    return shifted_through(shape, *side.anchor)


def _step(side: _Side, other: _Side | None, k: int, win: _Windows, grid: BevGrid,
          p: LaneParams) -> None:
    """Search window k for ``side``'s boundary; record a hit."""
    line = _prediction(side, other, p)
    xc = float(win.centres[k])
    yc = float(poly_y(line, xc))
    if not grid.y_min < yc < grid.y_max:
        side.active = False
        return
    cells = win.cells(k)
    margin = min(p.window_margin_max,
                 p.window_margin + p.window_margin_growth * max(0.0, xc - side.last_x))
    near = np.abs(win.y[cells] - poly_y(line, win.x[cells])) < margin
    if np.count_nonzero(near) < p.window_min_pixels:
        return
    side.add_hit(cells.start + np.flatnonzero(near), win, xc, p)


def _start_side(win: _Windows, sign: int, guide: Coefficients | None,
                p: LaneParams) -> _Side | None:
    base = _find_base(win, sign, guide, p)
    if base is None:
        return None
    k, y = base
    x = float(win.centres[k])
    shape = guide if guide is not None else (y, 0.0, 0.0)
    return _Side(sign, k, shape, (x, y), last_x=x)


def _search_sides(win: _Windows, grid: BevGrid, prior: LaneEstimate | None,
                 p: LaneParams) -> tuple[_Side | None, _Side | None]:
    """(left, right) boundary searches run window by window, both sides in step; ``prior``
    guides both bases."""
    left = _start_side(win, LEFT, None if prior is None else prior_boundary(prior, LEFT), p)
    right = _start_side(win, RIGHT, None if prior is None else prior_boundary(prior, RIGHT), p)
    for k in range(len(win.centres)):
        for side, other in ((left, right), (right, left)):
            if side is not None and side.active and k >= side.start:
                _step(side, other, k, win, grid, p)
    return left, right


def _search_beside(win: _Windows, grid: BevGrid, found: _Side, boundary: LaneBoundary,
                  width: float, p: LaneParams) -> _Side | None:
    """The boundary on the other side of ``found`` (its fit ``boundary``), searched around
    ``boundary`` shifted a lane ``width`` [m] across."""
    c0, c1, c2 = boundary.coefficients
    sign = -found.sign
    side = _start_side(win, sign, (c0 + sign * width / math.cos(math.atan(c1)), c1, c2), p)
    if side is None:
        return None
    for k in range(side.start, len(win.centres)):
        if side.active:
            _step(side, found, k, win, grid, p)
    return side


# ---- fits and the estimate ------------------------------------------------------------------


def fit_boundary(x: FloatArray, y: FloatArray, w: FloatArray, p: LaneParams) -> LaneBoundary:
    """The boundary's weighted fit on its cells, refitted once without outliers (module doc,
    step 5)."""
    c = fit_poly(x, y, p, w)
    keep = np.abs(y - poly_y(c, x)) <= p.outlier_distance
    if np.count_nonzero(keep) >= max(3, len(x) // 2):
        x, y, w = x[keep], y[keep], w[keep]
        c = fit_poly(x, y, p, w)
    return LaneBoundary(c, float(x.min()), float(x.max()), len(x))


def _wlstsq(a: FloatArray, y: FloatArray, w: FloatArray) -> FloatArray:
    """Weighted linear least squares: x minimising |w (a x - y)|."""
    return np.asarray(np.linalg.lstsq(a * w[:, None], y * w, rcond=None)[0], dtype=np.float64)


def _fit_parallel(win: _Windows, left: IntArray, right: IntArray,
                 p: LaneParams) -> tuple[float, float, Coefficients]:
    """(c0_left, c0_right, (a0, a1, a2) centre) of the weighted joint fit of both
    boundaries' cells as curves concentric with the centre line y = a0 + a1 x + a2 x^2:
    y = c0_side + a1 x + g_side a2 x^2 with a0 = (c0_left + c0_right) / 2 and g_side = 1 /
    (1 - 2 a2 (c0_side - a0)) (a boundary d to the left of an arc of curvature k has
    curvature k / (1 - k d)). A first fit with g = 1 gives g and the outliers (farther than
    outlier_distance) the second fit leaves out. Linear (a2 = 0) unless a side spans
    quadratic_min_span."""
    idx = np.concatenate([left, right])
    x, y, w = win.x[idx], win.y[idx], win.w[idx]
    is_left = np.concatenate([np.ones(len(left)), np.zeros(len(right))])
    quadratic = max(float(np.ptp(win.x[left])), float(np.ptp(win.x[right]))) >= (
        p.quadratic_min_span)
    columns = [is_left, 1.0 - is_left, x] + ([x * x] if quadratic else [])
    a = np.column_stack(columns)
    sol = _wlstsq(a, y, w)
    keep = np.abs(y - a @ sol) <= p.outlier_distance
    if np.count_nonzero(keep) < len(y) // 2 or not (
            keep[is_left > 0].any() and keep[is_left == 0].any()):
        keep = np.ones(len(y), dtype=bool)
    if quadratic:
        a0, a2 = 0.5 * (sol[0] + sol[1]), sol[3]
        g = 1.0 / (1.0 - 2.0 * a2 * np.where(is_left > 0, sol[0] - a0, sol[1] - a0))
        a[:, 3] = x * x * g
    sol = _wlstsq(a[keep], y[keep], w[keep])
    c0l, c0r, a1 = float(sol[0]), float(sol[1]), float(sol[2])
    return c0l, c0r, (0.5 * (c0l + c0r), a1, float(sol[3]) if quadratic else 0.0)


def _side_score(side: _Side, boundary: LaneBoundary, p: LaneParams) -> float:
    """[0, 1] how well one boundary was seen (module doc, step 6)."""
    span = boundary.x_max - boundary.x_min
    return min(1.0, side.hits / p.full_windows) * min(1.0, span / p.full_span)


def _estimate(t: float, centre: Coefficients, width: float, confidence: float,
              left: LaneBoundary | None, right: LaneBoundary | None) -> LaneEstimate:
    a0, a1, a2 = centre
    return LaneEstimate(t=t, offset=-a0, heading_error=-math.atan(a1), curvature=2.0 * a2,
                        width=width, confidence=confidence, left=left, right=right,
                        lines=(left is not None) + (right is not None))


def _one_sided(t: float, boundary: LaneBoundary, sign: int, score: float, width: float
              ) -> LaneEstimate:
    """The estimate from one boundary on ``sign``'s side and a known lane ``width`` [m]."""
    c0, c1, c2 = boundary.coefficients
    a0 = c0 - sign * 0.5 * width / math.cos(math.atan(c1))
    left, right = (boundary, None) if sign == LEFT else (None, boundary)
    return _estimate(t, (a0, c1, c2), width, 0.5 * score, left, right)


_Fits = dict[int, tuple[_Side, LaneBoundary]]  # by side sign: the search and its fit


def _fit_sides(win: _Windows, sides: tuple[_Side | None, _Side | None], p: LaneParams
               ) -> _Fits:
    """The boundary fit of each side that found enough paint, by side sign."""
    fits: _Fits = {}
    for side in sides:
        if side is None:
            continue
        idx = side.cell_indices()
        if len(idx) >= p.window_min_pixels:
            fits[side.sign] = (side, win.fit_boundary(idx, p))
    return fits


# ---- the detector ---------------------------------------------------------------------------


class LaneDetector:
    """One-frame lane finder for one camera (see module doc). No memory between frames."""

    def __init__(self, camera: CameraInfo, params: LaneParams | None = None) -> None:
        self.camera = camera
        self.params = params if params is not None else LaneParams()
        self.view = BirdseyeView(camera, self.params.grid)

    def birdseye_mask(self, frame: CameraFrame) -> NDArray[np.uint8]:
        """(rows, cols) the warped 0/255 paint mask (bilinear) of a frame, for inspection."""
        if frame.rgb.shape != (self.camera.height, self.camera.width, 3):
            raise ValueError(f"frame is {frame.rgb.shape}, the camera "
                             f"{self.camera.height} x {self.camera.width} x 3")
        band = np.ascontiguousarray(self.view.crop(frame.rgb))
        p = self.params
        warped = self.view.warp(lane_mask(band, p))
        return narrow_only(warped, p.mask_min_coverage,
                           max(2, round(p.max_paint_width / p.grid.resolution)))

    def detect(self, frame: CameraFrame, prior: LaneEstimate | None = None,
               map_width: float | None = None) -> LaneEstimate:
        """The ego lane in ``frame``; ``prior`` (e.g. the filter's last output) guides the
        base search; with one boundary seen the lane is ``map_width`` [m] wide (the HD
        map's lane at the car), else the prior's width, else ``default_width``."""
        p = self.params
        if prior is not None and prior.confidence < p.prior_min_confidence:
            prior = None
        x, y = paint_cells(self.birdseye_mask(frame), p.grid, p.mask_min_coverage)
        win = _Windows.make(x, y, p.grid, p.window_length, self.camera.mount.x, p.weight_power)
        fits = _fit_sides(win, _search_sides(win, p.grid, prior, p), p)
        width = map_width if map_width is not None else prior.width if prior is not None \
            else p.default_width
        estimate = self._two_sided(frame.t, win, fits)
        if estimate is None and fits:
            estimate = self._with_the_other_side(frame.t, win, fits, width)
        if estimate is not None:
            return estimate
        guess = (0.0, 0.0, 0.0) if prior is None else (
            -prior.offset, -math.tan(prior.heading_error), 0.5 * prior.curvature)
        return _estimate(frame.t, guess, width, 0.0, None, None)

    def _with_the_other_side(self, t: float, win: _Windows, fits: _Fits,
                             width: float) -> LaneEstimate:
        """The boundary first seen nearest the car (then the better-seen one) with the other
        one searched beside it (a dashed line in a gap on a tight curve, a wrong line taken
        for it); else that boundary alone."""
        p = self.params
        sign = min(fits, key=lambda s: (fits[s][0].start, -_side_score(*fits[s], p)))
        side, boundary = fits[sign]
        other = _search_beside(win, p.grid, side, boundary, width, p)
        if other is not None:
            both = _fit_sides(win, (side, other), p)
            estimate = self._two_sided(t, win, both)
            if estimate is not None:
                return estimate
        return _one_sided(t, boundary, sign, _side_score(side, boundary, p), width)

    def _two_sided(self, t: float, win: _Windows, fits: _Fits) -> LaneEstimate | None:
        """The estimate from both boundaries, or None if one is missing, their width is
        implausible or they do not straddle the car's centre."""
        p = self.params
        if LEFT not in fits or RIGHT not in fits:
            return None
        (left, bl), (right, br) = fits[LEFT], fits[RIGHT]
        c0l, c0r, centre = _fit_parallel(win, left.cell_indices(), right.cell_indices(), p)
        width = (c0l - c0r) * math.cos(math.atan(centre[1]))
        if not (p.min_width <= width <= p.max_width and c0l > 0.0 > c0r):
            return None
        confidence = 0.5 * (_side_score(left, bl, p) + _side_score(right, br, p))
        return _estimate(t, centre, width, confidence, bl, br)


# ---- temporal filter ------------------------------------------------------------------------

DIM = 4
I_OFFSET, I_HEADING, I_CURVATURE, I_WIDTH = range(DIM)


def chi_square_quantile(probability: float, dof: int) -> float:
    """The chi-square distribution's quantile [-]: the x with P(X <= x) = `probability` for
    `dof` degrees of freedom, as ``scipy.stats.chi2.ppf`` computes it (2 P^-1(dof/2, p), the
    regularised lower incomplete gamma function's inverse), without importing scipy.stats
    (a quarter of a second on every run's start)."""
    return float(2.0 * gammaincinv(dof / 2, probability))


@dataclass(frozen=True, slots=True)
class LaneFilterParams:
    """Noise (1-sigma), gating and confidence dynamics of `LaneFilter`."""

    offset_sigma: float = 0.05  # [m] measurement noise at confidence 1
    heading_sigma: float = 0.01  # [rad]
    curvature_sigma: float = 0.002  # [1/m]
    width_sigma: float = 0.05  # [m]
    offset_walk: float = 0.3  # [m/sqrt(s)] process random walk
    heading_walk: float = 0.05  # [rad/sqrt(s)]
    curvature_walk: float = 0.01  # [1/m/sqrt(s)]
    width_walk: float = 0.05  # [m/sqrt(s)]
    min_confidence: float = 0.2  # [-] measurements below this are not used (predict only)
    confidence_floor: float = 0.1  # [-] measurement noise is divided by max(this, confidence)
    gate_probability: float = 0.999  # [-] chi-square gate on the innovation
    max_rejections: int = 3  # [-] consecutive gated-out measurements to re-initialise on
    agree_offset: float = 0.3  # [m] ... if those measurements agree this well (offsets)
    agree_heading: float = 0.035  # [rad] ... and headings (2 deg)
    confidence_gain: float = 0.5  # [-] share of the measurement's confidence taken per update
    confidence_tau: float = 0.5  # [s] decay time constant of the confidence while predicting
    init_width_sigma: float = 0.5  # [m] width uncertainty when initialised from one boundary
    reassign_margin: float = 0.2  # [m] past half a width by this: the neighbour is the lane


class LaneFilter:
    """Kalman filter on x = (offset [m], heading_error [rad], curvature [1/m], width [m]).

    Per detection (`update`), at its time t [s]:

    1. Initialise on the first detection with confidence >= ``min_confidence`` (the width's
       sigma is ``init_width_sigma`` when one boundary was seen).
    2. Predict over dt [s]: random walks of ``*_walk``; with the car's ``speed`` v [m/s],
       offset += v dt heading_error (sin linearised); with its ``yaw_rate`` r [rad/s],
       heading_error += (r - v curvature) dt.
    3. Correct with offset, heading and curvature, and the width when both boundaries were
       seen; the noise is ``*_sigma`` / max(``confidence_floor``, confidence). A detection
       below ``min_confidence`` only predicts. Gate: an innovation whose squared Mahalanobis
       distance exceeds the chi-square quantile ``gate_probability`` is rejected (predict
       only), unless it is the ``max_rejections``-th in a row and those agree (offsets within
       ``agree_offset``, headings within ``agree_heading``): then the filter re-initialises on
       it (a lane change, a new lane); rejections that scatter (a vehicle's side, glare) only
       predict.
    4. Ego-lane re-assignment, after an accepted detection: when |offset| > width / 2 +
       ``reassign_margin`` (the car's centre past a boundary: a lane change), the state moves
       to the lane beyond that line (offset -+ width, the covariance with it). The detector
       follows, as the filtered estimate is its prior, and the lines it tracked stay in view
       as the new lane's other boundary.
    5. The confidence moves by ``confidence_gain`` towards each accepted detection's and
       decays as exp(-dt / ``confidence_tau``) while predicting.
    6. The output says what it rests on: ``lines``, the boundaries the detection saw (taken
       or not: 1, a line and the lane's width; 0, nothing), and ``age`` [s], the time since
       the last detection taken, over which the lane was dead-reckoned on the car's speed
       and yaw rate (odometry; the consumer decides how long that may last).
    """

    def __init__(self, params: LaneFilterParams | None = None) -> None:
        self.params = params if params is not None else LaneFilterParams()
        p = self.params
        self._r_sigma = np.array([p.offset_sigma, p.heading_sigma, p.curvature_sigma,
                                  p.width_sigma])
        self._walk = np.array([p.offset_walk, p.heading_walk, p.curvature_walk, p.width_walk])
        self._gate = {n: chi_square_quantile(p.gate_probability, n) for n in (3, 4)}
        self.x = np.zeros(DIM)  # (4,) state, see class doc
        self.P = np.eye(DIM)  # (4, 4) covariance
        self.t = 0.0  # [s] time of the state
        self.confidence = 0.0  # [0, 1]
        self.initialised = False
        self.rejections = 0  # [-] consecutive gated-out measurements
        self._rejected: list[LaneEstimate] = []  # the last of them
        self._measured: float | None = None  # [s] time of the last detection taken

    def reset(self) -> None:
        """Forget everything; the next confident measurement initialises again."""
        self.x = np.zeros(DIM)
        self.P = np.eye(DIM)
        self.t = 0.0
        self.confidence = 0.0
        self.initialised = False
        self.rejections = 0
        self._rejected = []
        self._measured = None

    def update(self, estimate: LaneEstimate, speed: float = 0.0,
               yaw_rate: float | None = None) -> LaneEstimate:
        """Filter one detection; return the filtered estimate at ``estimate.t``."""
        p = self.params
        usable = estimate.confidence >= p.min_confidence
        if not self.initialised:
            if not usable:
                return replace(estimate, confidence=0.0, left=None, right=None)
            self._initialise(estimate)
            self.confidence = p.confidence_gain * estimate.confidence
            return self._output(estimate)
        dt = max(0.0, estimate.t - self.t)
        self._predict(dt, speed, yaw_rate)
        self.t = max(self.t, estimate.t)
        if not (usable and self._correct(estimate)):
            self.confidence *= math.exp(-dt / p.confidence_tau)
            return self._output(replace(estimate, left=None, right=None))
        self.confidence += p.confidence_gain * (estimate.confidence - self.confidence)
        self._measured = estimate.t
        if self._reassign():  # this frame's lines belong to the lane left behind
            return self._output(replace(estimate, left=None, right=None))
        return self._output(estimate)

    def _reassign(self) -> bool:
        """Move the state to the neighbouring lane once the car's centre is past its line
        (see the class doc); True if it moved."""
        offset, width = float(self.x[I_OFFSET]), float(self.x[I_WIDTH])
        if abs(offset) <= 0.5 * width + self.params.reassign_margin:
            return False
        j = np.eye(DIM)
        j[I_OFFSET, I_WIDTH] = -math.copysign(1.0, offset)
        self.x = j @ self.x
        self.P = j @ self.P @ j.T
        self.rejections, self._rejected = 0, []
        return True

    def _initialise(self, z: LaneEstimate) -> None:
        p = self.params
        self.x = np.array([z.offset, z.heading_error, z.curvature, z.width])
        sigma = self._r_sigma / max(p.confidence_floor, z.confidence)
        if z.left is None or z.right is None:
            sigma[I_WIDTH] = p.init_width_sigma
        self.P = np.diag(sigma**2)
        self.t = z.t
        self.initialised = True
        self.rejections = 0
        self._rejected = []
        self._measured = z.t

    def _predict(self, dt: float, speed: float, yaw_rate: float | None) -> None:
        if dt <= 0.0:
            return
        f = np.eye(DIM)
        f[I_OFFSET, I_HEADING] = speed * dt
        if yaw_rate is not None:
            f[I_HEADING, I_CURVATURE] = -speed * dt
        self.x = f @ self.x
        if yaw_rate is not None:
            self.x[I_HEADING] += yaw_rate * dt
        self.P = f @ self.P @ f.T + np.diag(self._walk**2 * dt)

    def _correct(self, z: LaneEstimate) -> bool:
        """Kalman update with ``z`` (True), or a rejection by the gate (False); the
        ``max_rejections``-th rejection in a row re-initialises on ``z`` instead (True) when
        the rejected measurements agree with each other."""
        p = self.params
        rows = [I_OFFSET, I_HEADING, I_CURVATURE] + (
            [I_WIDTH] if z.left is not None and z.right is not None else [])
        h = np.eye(DIM)[rows]
        meas = np.array([z.offset, z.heading_error, z.curvature, z.width])[rows]
        r = np.diag((self._r_sigma[rows] / max(p.confidence_floor, z.confidence)) ** 2)
        innovation = meas - h @ self.x
        s = h @ self.P @ h.T + r
        if float(innovation @ np.linalg.solve(s, innovation)) > self._gate[len(rows)]:
            self.rejections += 1
            self._rejected = [*self._rejected, z][-p.max_rejections:]
            if self.rejections < p.max_rejections or not self._rejections_agree():
                return False
            self._initialise(z)
            return True
        self._rejected = []
        gain = self.P @ h.T @ np.linalg.inv(s)
        self.x = self.x + gain @ innovation
        i_kh = np.eye(DIM) - gain @ h
        self.P = i_kh @ self.P @ i_kh.T + gain @ r @ gain.T  # Joseph form
        self.rejections = 0
        return True

    def _rejections_agree(self) -> bool:
        p = self.params
        offsets = [z.offset for z in self._rejected]
        headings = [z.heading_error for z in self._rejected]
        return (max(offsets) - min(offsets) <= p.agree_offset
                and max(headings) - min(headings) <= p.agree_heading)

    def _output(self, z: LaneEstimate) -> LaneEstimate:
        """The state as an estimate at ``z.t`` with ``z``'s boundaries and lines, and the
        age of the last detection taken."""
        m = self._measured
        return LaneEstimate(
            t=z.t, offset=float(self.x[I_OFFSET]), heading_error=float(self.x[I_HEADING]),
            curvature=float(self.x[I_CURVATURE]), width=float(self.x[I_WIDTH]),
            confidence=float(self.confidence), left=z.left, right=z.right,
            lines=z.lines, age=max(0.0, z.t - m) if m is not None else 0.0,
        )
