"""Object detection in one LiDAR scan: oriented, class-completed boxes in the vehicle frame.

Input: a `LidarScan`, (N, 3) points [m] in the sensor frame. Output: `Detection` boxes in the
vehicle frame (x forward, y left, z up, origin on the ground below the car's centre), sorted
by horizontal range from the sensor. Lengths in metres, angles in radians; the thresholds
named below are fields of `DetectorParams`.

1. **Vehicle frame and region of interest**: ``mount.to_vehicle``; keep |x| <= ``roi_x`` and
   |y| <= ``roi_y``.
2. **Ground plane**: the ground is flat, but the body pitches and rolls, so in the vehicle
   frame it is a plane z = a x + b y + c near z = 0, fitted by RANSAC: ``ground_hypotheses``
   planes through three of ``ground_sample`` ROI points (an even stride), drawn by a generator
   seeded with ``ground_seed`` at every call (a scan always gives the same plane). A plane is
   admissible if its normal is within ``ground_max_tilt`` of vertical and it passes within
   ``ground_max_offset`` of the vehicle origin, so that walls and car roofs cannot win; the
   one with the most sample points within ``ground_threshold`` is refined twice by least
   squares on its inliers among all ROI points. No admissible plane: z = 0. A point's height
   is z - (a x + b y + c); points below ``ground_clearance`` are ground, points above
   ``roi_height`` are dropped (it lies well above ``max_height``: a wall cropped lower would
   look like a row of posts).
3. **Clustering** on the horizontal coordinates, as objects stand on the ground and do not
   stack (a 16-channel LiDAR's rings are metres apart at range and would split a car in 3D):
   the points are averaged per ``voxel`` x ``voxel`` grid cell (each point's cell kept), the
   centroids clustered by Open3D's ``cluster_dbscan`` (eps ``cluster_eps``, ``min_points =
   1``: single-linkage Euclidean clustering), and the labels go back to the points.
4. **Cluster gate**: clusters with fewer than `fewest_points` returns, whose highest point is
   below ``min_top`` or above ``max_height`` (buildings), or whose axis-aligned extent exceeds
   ``max_length`` sqrt(2) are dropped before fitting. The fewest returns is what one ring
   leaves across the narrowest side of the smallest object to be found, a pedestrian seen
   side-on (its trunk ``pedestrian_depth`` deep), at the scan's column step: a 16-channel
   LiDAR's rings are 0.5 - 1 m apart at 15 - 30 m, so one ring may be all that crosses a
   walker's body (the ring below meets its feet under ``ground_clearance``); at most
   ``min_points``, at least ``min_points_far``, and a cluster under ``min_points`` must
   span two columns (a 0.25 m deep trunk at 0.2 deg leaves 4 returns up to 17.9 m, 3 up to
   23.9 m, then 2: a 16-channel LiDAR's single ring crosses a walker at 50 m on two
   columns). The tracker's M-of-N confirmation over consecutive scans is what rejects lone
   returns.
5. **Oriented rectangle (L-shape fitting)**: the heading in [0, pi/2) that maximises the
   closeness criterion of Zhang et al. 2017 ("Efficient L-shape fitting for vehicle detection
   using laser scanners"): the points are projected on the two rectangle axes, each axis
   keeps the edge its points are closer to (norm of the distance vector), and the score is
   sum 1 / max(min(d1, d2), ``closeness_d0``). It is searched every ``coarse_step``, then
   every ``fine_step`` within one coarse step of the best, on at most ``fit_max_points``
   points (an even stride). The heading is fitted to the lower body's returns, those at
   most ``footprint_top`` high, when there are ``min_points`` of them and at least a
   ``footprint_share`` of the cluster: a vehicle's footprint is its lower body's outline
   (bumpers, sides), while its cabin, bonnet and boot deck are set back from the ends and
   its glass sides lean in, so that they and the bumpers fit no one rectangle (a car in the
   next lane was tilted 5 - 10 deg). Else the points within ``roof_band`` of the cluster's
   highest point are left out of the heading fit (unless fewer than ``min_points`` would
   remain): a roof seen from above, close by, fills the rectangle's interior and tilts the
   refit below.
   The criterion chases the extreme (noisiest) points, so the
   heading is then refitted ``refine_iterations`` times by least squares: each point goes to
   the nearer of the two kept edges, and the two perpendicular lines minimising the summed
   squared distances have the normal n = the eigenvector of the smallest eigenvalue of S_1 -
   S_2 (the scatter matrices of the two point sets; closed form).
6. **Candidate classes** from the observed extents a >= b and the highest point h (lower
   bounds: a LiDAR sees only the near faces and, far away, one or two rings) and the height
   the ring above passes over the cluster (`ring_gap_top`: an upper bound): none (not an
   object) if a > ``max_length`` or h > ``max_height``; if a <= ``small_footprint``,
   PEDESTRIAN when a <= ``pedestrian_footprint``, h <= ``pedestrian_max_height`` and h >=
   ``pedestrian_min_height`` or, where only the cluster's top ring could reach it (the ring
   below meets the ground first), the ring above passes over it at ``pedestrian_adult_height``
   or higher (beyond 30 m one ring crosses a walker, at knee height), else MOTORCYCLE if it
   is a two-wheeler seen end-on (`two_wheeler_end_on`: on the line of sight, deeper than
   ``pedestrian_footprint``, no wider than ``motorcycle_max_width`` and
   ``two_wheeler_elongation`` times as deep as wide; as tall as a walker, at most
   ``motorcycle_max_height``: a cyclist from behind, its rider's back, bars and front wheel
   one behind the other), else OTHER (obstacles, poles); TRUCK alone if h > ``car.height``
   + ``height_margin``, a > ``truck_min_length`` or b > ``truck_min_width``; otherwise CAR,
   then MOTORCYCLE if ``car.width`` < a <= ``motorcycle_max_length``, b <=
   ``motorcycle_max_width`` and h <= ``motorcycle_max_height`` (a side longer than a car's
   rear is wide: a car's side or a motorcycle's) or if it is a two-wheeler seen end-on,
   then TRUCK unless the ring above passes over it lower than ``car.height``
   + ``height_margin`` (no truck's rear is that low). Of equal costs (step 7) the first
   wins: a car's rear is no motorcycle's side.
7. **Box completion**: each candidate class's box is grown to its size prior (``car``,
   ``truck``, ``motorcycle``, ``pedestrian``; never shrunk below what was seen; OTHER: a
   square of the longer observed side), with either rectangle axis as the length. A
   pedestrian's rectangle is taken along the line of sight instead of the L-shape fit (see
   `along_sight`), and a two-wheeler's seen end-on along the line of sight and across it
   (`sight_footprint`). Each axis grows away from the sensor, so that the faces seen stay where
   they were seen: if the sensor projects onto the axis outside the observed interval, the
   interval's end nearer the sensor is kept; if inside (a face seen head-on, both its ends
   visible), the interval grows symmetrically. The hypothesis of least cost = silhouette
   growth + ``overshoot_weight`` x overshoot (+ ``truck_bias`` for trucks) wins: the
   silhouette growth [m] is how far the box sticks out sideways beyond the seen points as
   viewed from the sensor (azimuth growth x mean range; a rightly completed box hides behind
   its visible faces), the overshoot [m] how much the seen extents exceed the prior's. This
   decides, e.g., whether a lone face a car wide is a car's rear (grown away: no growth) or
   part of its side (grown sideways). Height: the prior's, or the observed one if larger; z
   is half the height. A car's near end along its length is `Detection.end_seen` when the
   returns within ``end_band`` of it reach down to ``footprint_top``: else the face seen is
   a bonnet's, a boot deck's or a cabin's (beyond about 27 m one ring crosses a car ahead,
   above its boot deck: a saloon's rear screen, 0.9 m before its bumper), the box grown from
   it lies too far away by that set-back, which the scan cannot tell; the tracker can.
8. **Coupled trailers and fragments**: a tractor's cab and its semi-trailer are two solids a
   coupling's clearance apart (the trailer's front swings past the cab's back wall in a
   turn), farther than ``cluster_eps``: two truck boxes whose clusters lie on one line
   (their intervals across the one with more points' axis overlap, within
   ``fragment_margin``) and at most ``coupling_gap`` apart along it are one vehicle, boxed
   again from their joined points (`couple_trailers`). A surface seen at grazing incidence
   breaks into clusters of one azimuth column each (a truck's side seen from just behind
   it). Walking the detections from the most points down, one whose points lie mostly
   (>= 50 %) inside a kept box grown by ``fragment_margin`` is dropped (two objects cannot
   overlap).

The yaw is the length axis's heading, wrapped to (-pi/2, pi/2] (front and back are not told
apart). Limits: a walker shorter than ``pedestrian_adult_height`` hit by one ring only, below
``pedestrian_min_height``, comes out as OTHER (it cannot be told from a bollard), and one
with fewer returns than `fewest_points` is not seen at all.

Open3D is imported lazily, on the first scan, by `world.frames.import_open3d`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np
from numpy.typing import NDArray

from perception.messages import Detection, ObjectClass
from world.frames import LidarInfo, LidarScan, import_open3d

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]
DEG = math.pi / 180.0  # [rad/deg]


@dataclass(frozen=True, slots=True)
class SizePrior:
    """A class's box size [m]."""

    length: float  # [m] along the heading
    width: float  # [m]
    height: float  # [m]


@dataclass(frozen=True, slots=True)
class DetectorParams:
    """Thresholds of the detector, by step of the module docstring."""

    roi_x: float = 100.0  # [m] keep |x| <= roi_x (vehicle frame): the LiDAR's range, so
    #   that a car ahead is found as far as a ring still crosses it above min_top (a
    #   VLP-16-like sensor on the roof: its -1 deg ring, the lowest that still clears the
    #   ground that far, meets a car's rear under min_top beyond about 72 m)
    roi_y: float = 60.0  # [m] keep |y| <= roi_y
    roi_height: float = 8.0  # [m] drop points higher than this above the ground (well above
    #   max_height: a wall stays whole, too tall to be an object)
    ground_hypotheses: int = 40  # [-] RANSAC plane hypotheses
    ground_sample: int = 1500  # [-] ROI points the hypotheses are drawn from and scored on
    ground_threshold: float = 0.10  # [m] RANSAC / refit inlier distance
    ground_max_tilt: float = 6.0 * DEG  # [rad] admissible ground normal tilt from vertical
    ground_max_offset: float = 0.5  # [m] admissible ground distance from the vehicle origin
    ground_clearance: float = 0.2  # [m] points lower than this above the plane are ground
    ground_seed: int = 0  # [-] RANSAC generator seed (fixed: deterministic output)
    voxel: float = 0.15  # [m] horizontal grid cell of the downsampling before clustering
    cluster_eps: float = 0.6  # [m] DBSCAN neighbourhood radius (horizontal): wider than the
    #   column spacing of a 0.4 deg LiDAR at roi range, narrower than two cars a lane apart
    min_points: int = 4  # [-] fewest returns in a detected cluster, at most (step 4) ...
    min_points_far: int = 2  # [-] ... and at least
    pedestrian_depth: float = 0.25  # [m] the narrowest side of a person, its trunk's depth
    #   (an adult's chest depth, about 0.25 m: Pheasant and Haslegrave, "Bodyspace", 3rd ed.,
    #   table 2.1), which sets the fewest returns one ring leaves on a walker (step 4)
    pedestrian_body: float = 0.34  # [m] a person's trunk diameter, the mean of its breadth
    #   across the shoulders (about 0.43 m) and its depth (same table): the returns on a
    #   walker lie on its trunk and limbs, not on the corners of its box (`along_sight`)
    coupling_gap: float = 1.5  # [m] a tractor's cab and its trailer's front stand about
    #   0.5 - 1.2 m apart; two trucks queued nose to tail keep more (step 8)
    min_top: float = 0.3  # [m] a cluster's highest point must be at least this high
    max_length: float = 18.75  # [m] longer clusters are structures, not objects (the EU's
    #   longest vehicle, a road train, Directive 96/53/EC; an articulated one is 16.5 m)
    max_height: float = 4.5  # [m] taller clusters are structures, not objects
    small_footprint: float = 1.3  # [m] longest side up to this: pedestrian or other
    pedestrian_footprint: float = 0.85  # [m] longest side of a pedestrian, at most
    pedestrian_min_height: float = 0.9  # [m] highest point of a pedestrian, at least
    pedestrian_max_height: float = 2.2  # [m] and at most
    pedestrian_adult_height: float = 1.5  # [m] a lower top is a walker's if an adult this
    #   tall would be crossed by no other ring (the 5th-percentile woman's stature, about
    #   1.5 m: Pheasant and Haslegrave, "Bodyspace", 3rd ed., table 2.1)
    height_margin: float = 0.4  # [m] a vehicle higher than the car prior + this is a truck
    truck_min_length: float = 5.6  # [m] a longer one too
    truck_min_width: float = 2.2  # [m] a wider one too
    motorcycle_max_length: float = 2.7  # [m] a motorcycle's longest seen side, at most (the
    #   longest series machines, touring bikes, are about 2.6 m: Honda's Gold Wing 2.575 m)
    motorcycle_max_width: float = 1.2  # [m] its shortest seen side, at most (handlebars and
    #   mirrors about 0.8 - 1.0 m wide; EU category L3e, Regulation (EU) No 168/2013)
    motorcycle_max_height: float = 1.9  # [m] its highest point with a seated rider, at most
    two_wheeler_elongation: float = 1.5  # [-] a two-wheeler seen end-on (from behind or
    #   ahead) is at least this many times as deep along the line of sight as wide across
    #   it: bicycles and motorcycles are 2 - 3 times as long as their bars are wide, and
    #   from behind the rider's back, the bars and the front wheel are seen one behind the
    #   other; a car's rear or an obstacle's face is wider than deep
    overshoot_weight: float = 2.0  # [-] cost per metre seen beyond a prior's size
    truck_bias: float = 0.1  # [m] cost added to truck boxes (a car when equally likely)
    coarse_step: float = 3.0 * DEG  # [rad] L-shape heading search, coarse
    fine_step: float = 0.25 * DEG  # [rad] L-shape heading search, refinement
    fit_max_points: int = 400  # [-] points used in the heading search, at most
    closeness_d0: float = 0.01  # [m] closeness criterion distance floor
    refine_iterations: int = 2  # [-] least-squares refits of the L-shape heading
    roof_band: float = 0.15  # [m] points this close below a cluster's top are left out of
    #   the heading fit (a roof seen from above fills the footprint and tilts the refit)
    footprint_top: float = 0.6  # [m] top of a vehicle's lower body, whose outline is its
    #   footprint: below its bumpers' top (a car's bumper zone is 0.41 - 0.51 m high, 16 - 20
    #   in, US 49 CFR Part 581) the ends are the bumpers' faces; above, bonnets, boot decks
    #   and cabins are set back from them and the sides curve in
    footprint_share: float = 0.25  # [-] the heading is fitted to the lower body's returns
    #   when they are at least this share of a cluster's (and min_points)
    end_band: float = 0.3  # [m] the returns this close to a box's near end are its end face
    fragment_margin: float = 0.2  # [m] a box absorbs smaller clusters within this of it
    # [m] vehicle size priors: generic class sizes, the means of the nuScenes training set's
    #   car and truck boxes (the anchor sizes of mmdetection3d's nuScenes PointPillars), not
    #   any simulated body: a sedan is longer and lower than the car prior, a rigid truck or
    #   a bus much longer than the truck prior
    car: SizePrior = field(default_factory=lambda: SizePrior(4.61, 1.95, 1.72))
    truck: SizePrior = field(default_factory=lambda: SizePrior(6.74, 2.46, 2.73))
    # [m] nuScenes' mean pedestrian box (not the simulated walker's 0.5 x 0.6 x 1.75)
    pedestrian: SizePrior = field(default_factory=lambda: SizePrior(0.73, 0.66, 1.76))

    # [m] nuScenes' mean motorcycle box (the anchor of mmdetection3d's nuScenes SSN config,
    #   configs/ssn: 2.10 x 0.76 x 1.44), its rider included
    motorcycle: SizePrior = field(default_factory=lambda: SizePrior(2.10, 0.76, 1.44))

    def prior(self, cls: ObjectClass) -> SizePrior | None:
        """The size prior of ``cls`` (None for `ObjectClass.OTHER`)."""
        return {ObjectClass.CAR: self.car, ObjectClass.TRUCK: self.truck,
                ObjectClass.MOTORCYCLE: self.motorcycle,
                ObjectClass.PEDESTRIAN: self.pedestrian}.get(cls)


# ---- Open3D ----------------------------------------------------------------------------------


_open3d = import_open3d


# ---- ground ----------------------------------------------------------------------------------


@dataclass(frozen=True, slots=True)
class GroundPlane:
    """The ground in the vehicle frame: ``z = a x + b y + c``."""

    a: float  # [-] slope along x
    b: float  # [-] slope along y
    c: float  # [m] height at the vehicle origin

    def height(self, points: FloatArray) -> FloatArray:
        """(N,) [m] height of (N, 3) vehicle-frame points above the plane (vertical)."""
        out: FloatArray = points[:, 2] - (self.a * points[:, 0] + self.b * points[:, 1] + self.c)
        return out


def _plane_hypotheses(sample: FloatArray, rng: np.random.Generator,
                      p: DetectorParams) -> FloatArray:
    """(K, 4) admissible planes ``n . x + d = 0`` (unit n, n_z > 0) through random triplets."""
    idx = rng.integers(0, len(sample), size=(p.ground_hypotheses, 3))
    p0, p1, p2 = sample[idx[:, 0]], sample[idx[:, 1]], sample[idx[:, 2]]
    normal = np.cross(p1 - p0, p2 - p0)
    norm = np.linalg.norm(normal, axis=1)
    ok = norm > 1e-9
    normal = normal[ok] / norm[ok, None]
    normal *= np.where(normal[:, 2] < 0.0, -1.0, 1.0)[:, None]
    d = -np.einsum("ij,ij->i", normal, p0[ok])
    keep = (normal[:, 2] >= math.cos(p.ground_max_tilt)) & (np.abs(d) <= p.ground_max_offset)
    return np.column_stack([normal[keep], d[keep]])


def _refit(points: FloatArray, plane: GroundPlane, threshold: float) -> GroundPlane:
    """Least-squares ``z = a x + b y + c`` on the points within ``threshold`` of ``plane``."""
    inliers = points[np.abs(plane.height(points)) < threshold]
    if len(inliers) < 3:
        return plane
    design = np.column_stack([inliers[:, 0], inliers[:, 1], np.ones(len(inliers))])
    (a, b, c), *_ = np.linalg.lstsq(design, inliers[:, 2], rcond=None)
    return GroundPlane(float(a), float(b), float(c))


def fit_ground(points: FloatArray, p: DetectorParams) -> GroundPlane:
    """The ground plane under (N, 3) vehicle-frame points [m] (RANSAC + least squares)."""
    flat = GroundPlane(0.0, 0.0, 0.0)
    if len(points) < 3:
        return flat
    rng = np.random.default_rng(p.ground_seed)
    step = max(1, len(points) // p.ground_sample)
    sample = points[::step]
    planes = _plane_hypotheses(sample, rng, p)
    if len(planes) == 0:
        return flat
    inliers = np.abs(sample @ planes[:, :3].T + planes[:, 3]) < p.ground_threshold  # (M, K)
    nx, ny, nz, d = planes[int(np.argmax(inliers.sum(axis=0)))]
    plane = GroundPlane(float(-nx / nz), float(-ny / nz), float(-d / nz))
    return _refit(points, _refit(points, plane, p.ground_threshold), p.ground_threshold)


# ---- clustering ------------------------------------------------------------------------------


def voxel_centroids(xy: FloatArray, size: float) -> tuple[FloatArray, IntArray]:
    """Centroids (M, 2) [m] of the occupied ``size`` grid cells of (N, 2) points, and each
    point's cell index (N,)."""
    cells = np.floor(xy / size).astype(np.int64)
    keys = (cells[:, 0] << 32) + cells[:, 1]
    _, inverse = np.unique(keys, return_inverse=True)
    inverse = inverse.reshape(-1)
    counts = np.bincount(inverse)
    centroids = np.column_stack([np.bincount(inverse, weights=xy[:, 0]) / counts,
                                 np.bincount(inverse, weights=xy[:, 1]) / counts])
    return centroids, inverse


def cluster_labels(xy: FloatArray, p: DetectorParams) -> IntArray:
    """(N,) cluster label of each (N, 2) point [m] (-1: none); see module doc, step 3."""
    if len(xy) == 0:
        return np.zeros(0, dtype=np.int64)
    centroids, inverse = voxel_centroids(xy, p.voxel)
    o3d = _open3d()
    cloud = o3d.geometry.PointCloud(
        o3d.utility.Vector3dVector(np.column_stack([centroids, np.zeros(len(centroids))])))
    labels = np.asarray(cloud.cluster_dbscan(eps=p.cluster_eps, min_points=1), dtype=np.int64)
    out: IntArray = labels[inverse]
    return out


def fewest_points(distance: FloatArray, p: DetectorParams, column_step: float) -> FloatArray:
    """(N,) the fewest returns a cluster needs whose nearest point lies ``distance`` (N,)
    [m] from the car's centre, horizontally, for a LiDAR whose columns are ``column_step``
    [rad] apart: the columns one ring puts on a pedestrian's narrowest side (step 4)."""
    columns = np.floor(p.pedestrian_depth / (np.maximum(distance, 1e-3) * column_step))
    out: FloatArray = np.clip(columns, p.min_points_far, p.min_points)
    return out


def gated_clusters(labels: IntArray, xy: FloatArray, heights: FloatArray,
                   p: DetectorParams, column_step: float,
                   columns: IntArray | None = None) -> list[IntArray]:
    """Point indices of each cluster (label >= 0) that passes the gate of step 4, in label
    order; ``xy`` (N, 2) [m], ``heights`` (N,) [m] and ``columns`` (N,) (the LiDAR's
    azimuth steps; None: not checked) are the labelled points, ``column_step`` [rad] the
    LiDAR's azimuth step."""
    if len(labels) == 0:
        return []
    order = np.argsort(labels, kind="stable")
    sorted_labels = labels[order]
    starts = np.flatnonzero(np.diff(sorted_labels, prepend=-2))
    counts = np.diff(np.append(starts, len(order)))
    top = np.maximum.reduceat(heights[order], starts)
    sxy = xy[order]
    extent = np.max(np.maximum.reduceat(sxy, starts) - np.minimum.reduceat(sxy, starts), axis=1)
    nearest = np.minimum.reduceat(np.hypot(sxy[:, 0], sxy[:, 1]), starts)  # [m]
    ok = ((sorted_labels[starts] >= 0) & (counts >= fewest_points(nearest, p, column_step))
          & (top >= p.min_top)
          & (top <= p.max_height) & (extent <= p.max_length * math.sqrt(2.0)))
    if columns is not None:  # fewer than min_points: across two columns at least
        for i in np.flatnonzero(ok & (counts < p.min_points)):
            ok[i] = len(np.unique(columns[order[starts[i]:starts[i] + counts[i]]])) >= 2
    return [order[i:i + n] for i, n in zip(starts[ok], counts[ok], strict=True)]


# ---- L-shape fitting ---------------------------------------------------------------------------


def _edge_distances(proj: FloatArray) -> FloatArray:
    """(A, N) distance of each projection to the box edge (min or max) its axis keeps."""
    to_max = proj.max(axis=1, keepdims=True) - proj
    to_min = proj - proj.min(axis=1, keepdims=True)
    use_max = np.linalg.norm(to_max, axis=1) <= np.linalg.norm(to_min, axis=1)
    out: FloatArray = np.where(use_max[:, None], to_max, to_min)
    return out


def closeness(xy: FloatArray, angles: FloatArray, d0: float) -> FloatArray:
    """(A,) Zhang et al.'s closeness score of (N, 2) points [m] for each heading [rad]."""
    c, s = np.cos(angles)[:, None], np.sin(angles)[:, None]
    x, y = xy[:, 0][None, :], xy[:, 1][None, :]
    d1 = _edge_distances(c * x + s * y)
    d2 = _edge_distances(-s * x + c * y)
    score: FloatArray = (1.0 / np.maximum(np.minimum(d1, d2), d0)).sum(axis=1)
    return score


def l_shape_heading(xy: FloatArray, p: DetectorParams) -> float:
    """[rad] heading in [0, pi/2) of the box axis best fitting (N, 2) points (module doc 5)."""
    pts = xy[:: max(1, math.ceil(len(xy) / p.fit_max_points))]
    coarse = np.arange(0.0, 0.5 * math.pi, p.coarse_step)
    best = float(coarse[int(np.argmax(closeness(pts, coarse, p.closeness_d0)))])
    fine = best + np.arange(-p.coarse_step, p.coarse_step + 0.5 * p.fine_step, p.fine_step)
    best = float(fine[int(np.argmax(closeness(pts, fine, p.closeness_d0)))])
    for _ in range(p.refine_iterations):
        best = refine_heading(xy, best)
    return best % (0.5 * math.pi)


def _scatter(pts: FloatArray) -> FloatArray:
    """(2, 2) scatter matrix of (N, 2) points about their mean (zeros if N = 0)."""
    if len(pts) == 0:
        return np.zeros((2, 2))
    d = pts - pts.mean(axis=0)
    out: FloatArray = d.T @ d
    return out


def refine_heading(xy: FloatArray, theta: float) -> float:
    """[rad] the heading of two perpendicular lines fitted to (N, 2) points [m] by least
    squares, starting from the L-shape heading ``theta`` [rad] (module doc, step 5)."""
    axes = np.array([[math.cos(theta), math.sin(theta)], [-math.sin(theta), math.cos(theta)]])
    d = _edge_distances((xy @ axes.T).T)  # (2, N): distance to each axis's kept edge
    on_first = d[0] < d[1]  # nearer the edge line whose normal is axis 1
    # sum_A (n.p)^2 + sum_B (n_perp.p)^2 = n^T (S_A - S_B) n + tr(S_B): n is the eigenvector
    # of the smallest eigenvalue of S_A - S_B.
    _, vectors = np.linalg.eigh(_scatter(xy[on_first]) - _scatter(xy[~on_first]))
    n = vectors[:, 0]
    return math.atan2(float(n[1]), float(n[0]))


# ---- class and box completion ------------------------------------------------------------------


def candidate_classes(long_side: float, short_side: float, top: float,
                      p: DetectorParams, gap: RingGap | None = None,
                      end_on: bool = False) -> tuple[ObjectClass, ...]:
    """The classes observed extents [m] and highest point [m] allow (module doc, step 6);
    empty: not an object. ``gap``: how tall the object may be (`ring_gap_top`; None:
    unknown); ``end_on``: the points are a two-wheeler's seen end-on (`two_wheeler_end_on`)."""
    if long_side > p.max_length or top > p.max_height:
        return ()
    if long_side <= p.small_footprint:
        return _small_classes(long_side, top, p, gap, end_on)
    truck_height = p.car.height + p.height_margin
    if top > truck_height or long_side > p.truck_min_length or short_side > p.truck_min_width:
        return (ObjectClass.TRUCK,)
    classes = [ObjectClass.CAR]
    if ((end_on or p.car.width < long_side <= p.motorcycle_max_length)  # longer than a
            and short_side <= p.motorcycle_max_width  # car's rear is wide: a side, of a car
            and top <= p.motorcycle_max_height):  # or of a motorcycle; or one seen end-on
        classes.append(ObjectClass.MOTORCYCLE)
    if gap is None or gap.above >= truck_height:  # the ring above may pass over a truck's
        classes.append(ObjectClass.TRUCK)  # rear only if it is that high
    return tuple(classes)


def _small_classes(long_side: float, top: float, p: DetectorParams, gap: RingGap | None,
                   end_on: bool) -> tuple[ObjectClass, ...]:
    """`candidate_classes` of a footprint up to ``small_footprint`` long: a pedestrian, a
    two-wheeler seen end-on as tall as a rider, or an obstacle."""
    hidden = gap is not None and gap.alone and gap.above >= p.pedestrian_adult_height
    tall = top >= p.pedestrian_min_height or hidden  # as tall as a person may be
    if long_side <= p.pedestrian_footprint and top <= p.pedestrian_max_height and tall:
        return (ObjectClass.PEDESTRIAN,)
    if end_on and tall and top <= p.motorcycle_max_height:
        return (ObjectClass.MOTORCYCLE,)
    return (ObjectClass.OTHER,)


def sight_footprint(fp: Footprint, xy: FloatArray) -> Footprint:
    """``fp`` re-expressed on the line of sight (first axis) and across it: the observed
    intervals of (N, 2) points [m] along the ray from the sensor to them and across it."""
    proj = xy @ fp.view.T
    lo, hi = proj.min(axis=0), proj.max(axis=0)
    return replace(fp, axes=fp.view, lo=(float(lo[0]), float(lo[1])),
                   hi=(float(hi[0]), float(hi[1])))


def two_wheeler_end_on(sight: Footprint, p: DetectorParams) -> bool:
    """Whether a cluster's extents on the line of sight (`sight_footprint`) [m] are a
    two-wheeler's seen from behind or ahead: deeper along the ray than a walker's stride
    (``pedestrian_footprint``), no longer than a motorcycle, no wider than its bars
    (``motorcycle_max_width``), and ``two_wheeler_elongation`` times as deep as wide (the
    rider's back, the bars and the far wheel lie one behind the other, where a car's rear
    or an obstacle's face is wider than deep)."""
    along, across = sight.extents
    return (p.pedestrian_footprint < along <= p.motorcycle_max_length
            and across <= p.motorcycle_max_width and along >= p.two_wheeler_elongation * across)


def grow_interval(lo: float, hi: float, size: float, sensor: float) -> tuple[float, float]:
    """Grow [lo, hi] [m] to ``size`` away from the sensor's projection ``sensor`` [m]."""
    if size <= hi - lo:
        return lo, hi
    if sensor < lo:
        return lo, lo + size
    if sensor > hi:
        return hi - size, hi
    mid = 0.5 * (lo + hi)
    return mid - 0.5 * size, mid + 0.5 * size


@dataclass(frozen=True, slots=True, eq=False)
class Footprint:
    """A cluster's fitted rectangle and how the sensor sees it (vehicle frame)."""

    axes: FloatArray  # (2, 2) [-] rows: the rectangle's unit axes, vehicle frame
    lo: tuple[float, float]  # [m] observed interval of the points along each axis
    hi: tuple[float, float]  # [m]
    sensor: FloatArray  # (2,) [m] the sensor's position (x, y)
    view: FloatArray  # (2, 2) [-] rotation into a frame whose x points from the sensor to them
    azimuth: tuple[float, float]  # [rad] the points' azimuth interval in that frame
    distance: float  # [m] mean horizontal range of the points

    @property
    def extents(self) -> tuple[float, float]:
        """[m] observed extent along each axis."""
        return self.hi[0] - self.lo[0], self.hi[1] - self.lo[1]

    def azimuths(self, xy: FloatArray) -> FloatArray:
        """(N,) [rad] azimuths of (N, 2) points as seen from the sensor, in the view frame."""
        v = (xy - self.sensor) @ self.view.T
        out: FloatArray = np.arctan2(v[:, 1], v[:, 0])
        return out


def footprint(xy: FloatArray, sensor_xy: tuple[float, float], p: DetectorParams,
              fit: FloatArray | None = None) -> Footprint:
    """L-shape fit of (N, 2) vehicle-frame points [m] seen from ``sensor_xy`` [m]; the heading
    is fitted to the points ``fit`` (default: all of them), the extents span all."""
    theta = l_shape_heading(xy if fit is None else fit, p)
    c, s = math.cos(theta), math.sin(theta)
    axes = np.array([[c, s], [-s, c]])
    proj = xy @ axes.T
    lo, hi = proj.min(axis=0), proj.max(axis=0)
    sensor = np.asarray(sensor_xy, dtype=np.float64)
    rel = xy - sensor
    ref = math.atan2(float(rel[:, 1].mean()), float(rel[:, 0].mean()))
    cr, sr = math.cos(ref), math.sin(ref)
    fp = Footprint(axes=axes, lo=(float(lo[0]), float(lo[1])), hi=(float(hi[0]), float(hi[1])),
                   sensor=sensor, view=np.array([[cr, sr], [-sr, cr]]), azimuth=(0.0, 0.0),
                   distance=float(np.hypot(rel[:, 0], rel[:, 1]).mean()))
    az = fp.azimuths(xy)
    return replace(fp, azimuth=(float(az.min()), float(az.max())))


@dataclass(frozen=True, slots=True)
class Hypothesis:
    """One completed box for a cluster: class, which fitted axis is the length, bounds."""

    cost: float  # [m] silhouette growth + overshoot weight x overshoot (+ truck bias)
    cls: ObjectClass  # the candidate class whose size prior the box was grown to
    axis1_length: bool  # the first fitted axis is the box's length axis
    bounds: tuple[tuple[float, float], tuple[float, float]]  # [m] (lo, hi) along each axis
    axes: FloatArray  # (2, 2) [-] the axes of ``bounds`` (the footprint's it was grown from)


def silhouette_growth(fp: Footprint, bounds: tuple[tuple[float, float], ...]) -> float:
    """[m] how far a box of ``bounds`` (along ``fp.axes``) sticks out sideways, as seen from
    the sensor, beyond the points that were seen (angle x mean range)."""
    (lo1, hi1), (lo2, hi2) = bounds
    corners = np.array([[lo1, lo2], [lo1, hi2], [hi1, lo2], [hi1, hi2]]) @ fp.axes
    az = fp.azimuths(corners)
    out = max(0.0, fp.azimuth[0] - float(az.min())) + max(0.0, float(az.max()) - fp.azimuth[1])
    return out * fp.distance


def hypothesis(fp: Footprint, cls: ObjectClass, axis1_length: bool,
               p: DetectorParams) -> Hypothesis:
    """The box of class ``cls`` grown from ``fp`` away from the sensor, and its cost."""
    ext = fp.extents
    prior = p.prior(cls)
    if prior is None:
        dims = (max(ext), max(ext))  # unknown size: a square of the longer observed side
    elif axis1_length:
        dims = (prior.length, prior.width)
    else:
        dims = (prior.width, prior.length)
    sensor = fp.axes @ fp.sensor  # [m] the sensor's projection on each axis
    bounds = (grow_interval(fp.lo[0], fp.hi[0], max(dims[0], ext[0]), float(sensor[0])),
              grow_interval(fp.lo[1], fp.hi[1], max(dims[1], ext[1]), float(sensor[1])))
    overshoot = max(0.0, ext[0] - dims[0]) + max(0.0, ext[1] - dims[1])
    bias = p.truck_bias if cls is ObjectClass.TRUCK else 0.0
    cost = silhouette_growth(fp, bounds) + p.overshoot_weight * overshoot + bias
    return Hypothesis(cost, cls, axis1_length, bounds, fp.axes)


def along_sight(fp: Footprint, xy: FloatArray, prior: SizePrior, body: float) -> Footprint:
    """``fp`` re-expressed on the line of sight and across it: a walker's few returns give
    no heading (an L-shape fit of them turns with every stride), so a pedestrian's box is
    taken along the ray, centred by a cylinder model (as in Autoware's shape estimation): a
    round trunk of diameter ``body`` [m] (a person's, not its box's: the box's prior also
    spans the swing of the arms and of a stride, where few returns land), whose returns
    (evenly spread across it, as a scanning LiDAR spreads them) lie on average pi D / 8 in
    front of its centre. Along the ray the interval is the prior's length about that
    centre (or the returns' span if longer); across it, the returns' own. The returns' mean
    range is used, not the nearest return: range noise on a couple of dozen points moves
    their minimum by centimetres a scan, which a tracker reads as motion."""
    proj = xy @ fp.view.T
    lo, hi = proj.min(axis=0), proj.max(axis=0)
    centre = float(proj[:, 0].mean()) + math.pi / 8.0 * body
    lo[0] = min(float(lo[0]), centre - 0.5 * prior.length)
    hi[0] = max(float(hi[0]), centre + 0.5 * prior.length)
    return replace(fp, axes=fp.view, lo=(float(lo[0]), float(lo[1])),
                   hi=(float(hi[0]), float(hi[1])))


def wrap_half_pi(a: float) -> float:
    """[rad] a box heading wrapped to (-pi/2, pi/2]."""
    w = math.remainder(a, math.pi)
    return math.pi / 2 if w == -math.pi / 2 else w


def box_from_points(xy: FloatArray, top: float, sensor_xy: tuple[float, float],
                    p: DetectorParams, heights: FloatArray | None = None,
                    gap: RingGap | None = None) -> Detection | None:
    """The completed box of one cluster: (N, 2) vehicle-frame points [m], highest point
    ``top`` [m] above the ground, sensor position [m], the points' (N,) heights [m] above
    the ground (given: the heading is fitted below the roof band), how tall it may be
    (`ring_gap_top`; None: unknown); None if it is not an object."""
    fp = footprint(xy, sensor_xy, p, heading_points(xy, top, heights, p))
    ext = fp.extents
    longer_first = ext[0] >= ext[1]
    ray = sight_footprint(fp, xy)
    end_on = two_wheeler_end_on(ray, p)
    classes = candidate_classes(max(ext), min(ext), top, p, gap, end_on)
    base = {ObjectClass.PEDESTRIAN: (along_sight(fp, xy, p.pedestrian, p.pedestrian_body)
                                     if ObjectClass.PEDESTRIAN in classes else fp),
            ObjectClass.MOTORCYCLE: ray if end_on else fp}
    hyps = [hypothesis(base.get(cls, fp), cls, axis1_length, p)
            for cls in classes
            for axis1_length in (longer_first, not longer_first)]
    if not hyps:
        return None
    best = min(hyps, key=lambda h: h.cost)  # the first of equals: deterministic
    (lo1, hi1), (lo2, hi2) = best.bounds
    centre = np.array([0.5 * (lo1 + hi1), 0.5 * (lo2 + hi2)]) @ best.axes
    prior = p.prior(best.cls)
    height = max(top, prior.height) if prior is not None else top
    length, width = (hi1 - lo1, hi2 - lo2) if best.axis1_length else (hi2 - lo2, hi1 - lo1)
    axis = best.axes[0] if best.axis1_length else best.axes[1]
    end_seen = (best.cls is not ObjectClass.CAR or heights is None
                or near_end_low(fp, 0 if best.axis1_length else 1, xy, heights, p))
    return Detection(x=float(centre[0]), y=float(centre[1]), z=0.5 * height, length=length,
                     width=width, height=height,
                     yaw=wrap_half_pi(math.atan2(float(axis[1]), float(axis[0]))),
                     cls=best.cls, points=len(xy), end_seen=end_seen)


def heading_points(xy: FloatArray, top: float, heights: FloatArray | None,
                   p: DetectorParams) -> FloatArray | None:
    """The (M, 2) points [m] the heading is fitted to (module doc, step 5): the lower body's
    (at most ``footprint_top`` high) if there are ``min_points`` of them and at least a
    ``footprint_share`` of the cluster, else those below the roof band; None (all points)
    without heights or with fewer than ``min_points`` below the roof band."""
    if heights is None:
        return None
    lower = heights <= p.footprint_top
    if lower.sum() >= max(p.min_points, p.footprint_share * len(xy)):
        return xy[lower]
    below = heights < top - p.roof_band
    return xy[below] if below.sum() >= p.min_points else None


def near_end_low(fp: Footprint, axis: int, xy: FloatArray, heights: FloatArray,
                 p: DetectorParams) -> bool:
    """Whether the returns within ``end_band`` of the end of ``fp``'s ``axis`` nearer the
    sensor reach down to the lower body (``footprint_top``): True too when the sensor lies
    between the axis's ends (no end faces it). (N, 2) points [m], (N,) heights [m]."""
    proj = xy @ fp.axes[axis]
    sensor = float(fp.axes[axis] @ fp.sensor)
    lo, hi = fp.lo[axis], fp.hi[axis]
    if lo <= sensor <= hi:
        return True
    near = proj <= lo + p.end_band if sensor < lo else proj >= hi - p.end_band
    return bool(heights[near].min() <= p.footprint_top)


# ---- the detector ------------------------------------------------------------------------------


def inside_box(xy: FloatArray, det: Detection, margin: float) -> NDArray[np.bool_]:
    """(N,) whether (N, 2) vehicle-frame points [m] lie in ``det``'s footprint grown by
    ``margin`` [m] on every side."""
    c, s = math.cos(det.yaw), math.sin(det.yaw)
    dx, dy = xy[:, 0] - det.x, xy[:, 1] - det.y
    along, across = c * dx + s * dy, -s * dx + c * dy
    out: NDArray[np.bool_] = ((np.abs(along) <= 0.5 * det.length + margin)
                              & (np.abs(across) <= 0.5 * det.width + margin))
    return out


def suppress_fragments(found: list[tuple[Detection, FloatArray]],
                       margin: float) -> list[Detection]:
    """Drop detections whose points lie mostly inside a box with more points (module doc,
    step 8); ``found`` pairs each detection with its cluster's (N, 2) points [m]."""
    order = sorted(found, key=lambda f: (-f[0].points, f[0].x, f[0].y))
    kept: list[Detection] = []
    for det, xy in order:
        if not any(inside_box(xy, k, margin).mean() >= 0.5 for k in kept):
            kept.append(det)
    return kept


def interval_gap(a: FloatArray, b: FloatArray) -> float:
    """[m] how far apart the (N,) and (M,) projections ``a`` and ``b`` [m] lie (negative:
    they overlap)."""
    return max(float(b.min() - a.max()), float(a.min() - b.max()))


def coupled(big: Detection, xy_big: FloatArray, small: Detection, xy_small: FloatArray,
            p: DetectorParams) -> bool:
    """Whether two truck boxes (each with its cluster's (N, 2) points [m]) are a tractor and
    its trailer (module doc, step 8): on one line along ``big``'s axis, its cluster's
    interval across that axis overlapping the other's (within ``fragment_margin``), and at
    most ``coupling_gap`` apart along it."""
    if big.cls is not ObjectClass.TRUCK or small.cls is not ObjectClass.TRUCK:
        return False
    axis = np.array([math.cos(big.yaw), math.sin(big.yaw)])
    normal = np.array([-axis[1], axis[0]])
    across = interval_gap(xy_big @ normal, xy_small @ normal)
    along = interval_gap(xy_big @ axis, xy_small @ axis)
    return across <= p.fragment_margin and along <= p.coupling_gap


def couple_trailers(found: list[tuple[Detection, IntArray]], xy: FloatArray,
                    p: DetectorParams) -> list[tuple[Detection | None, IntArray]]:
    """The boxes and clusters (point indices into (N, 2) ``xy`` [m]) after joining every
    coupled pair (`coupled`), the one with more points first; a joined cluster's box is
    None (to be boxed again from its points, once no more joins it)."""
    groups = sorted(found, key=lambda f: (-f[0].points, f[0].x, f[0].y))
    merged = [idx for _, idx in groups]
    boxes = [det for det, _ in groups]
    joined = [False] * len(merged)
    i = 0
    while i < len(merged):
        j = next((j for j in range(i + 1, len(merged))
                  if coupled(boxes[i], xy[merged[i]], boxes[j], xy[merged[j]], p)), None)
        if j is None:
            i += 1
            continue
        merged[i] = np.sort(np.concatenate([merged[i], merged.pop(j)]))
        boxes.pop(j)
        joined.pop(j)
        joined[i] = True
    return [(None if j else det, idx) for det, idx, j in zip(boxes, merged, joined, strict=True)]


@dataclass(frozen=True, slots=True)
class RingGap:
    """How tall a cluster may be, from the LiDAR's rings (`ring_gap_top`)."""

    above: float  # [m] the ring above its highest-hit ring passes over it this high (inf:
    #   none above): the object is lower
    alone: bool  # only its highest-hit ring could reach it: the ring below meets the ground
    #   before it, so more of it may be hidden below that ring's hit too


def ring_gap_top(info: LidarInfo, xy: FloatArray, heights: FloatArray, rings: IntArray,
                 p: DetectorParams) -> RingGap:
    """How tall a cluster may be ((N, 2) vehicle-frame points [m], their (N,) heights [m]
    above the ground and ring indices), at its nearest point. A 16-channel LiDAR's rings are
    2 deg apart: beyond 30 m one ring crosses a walker, at knee height, and the next passes
    1 - 2 m higher; the walker's top lies between. Beside the car the ring above passes a
    few centimetres over a motorcycle's top: it is no truck's rear. The rings are taken as
    level cones from the sensor's mount height (the body's pitch is small); the ring below
    reaches the object if it is still ``ground_clearance`` high there."""
    k = int(np.argmax(heights))
    top = float(heights[k])
    elevations = info.elevations
    own = elevations[int(rings[k])]
    sensor = np.array([info.mount.x, info.mount.y])
    d = float(np.min(np.hypot(*(xy - sensor).T)))
    below = [e for e in elevations if e < own]
    alone = not below or info.mount.z + d * math.tan(max(below)) <= p.ground_clearance
    above = [e for e in elevations if e > own]
    bound = top + d * (math.tan(min(above)) - math.tan(own)) if above else math.inf
    return RingGap(bound, alone)


class ObjectDetector:
    """LiDAR object detector; see the module docstring for the method."""

    def __init__(self, params: DetectorParams | None = None) -> None:
        self.params = params if params is not None else DetectorParams()
        self.ground = GroundPlane(0.0, 0.0, 0.0)  # the last scan's fitted ground

    def obstacle_points(self, scan: LidarScan) -> tuple[FloatArray, FloatArray]:
        """(N, 3) vehicle-frame points [m] in the ROI above the ground, and their (N,)
        heights [m] above the fitted ground plane (steps 1-2)."""
        pts, h, _, _ = self._obstacles(scan)
        return pts, h

    def _obstacles(self, scan: LidarScan
                   ) -> tuple[FloatArray, FloatArray, IntArray, IntArray]:
        """`obstacle_points` and each point's (N,) ring and column index."""
        p = self.params
        pts = scan.info.mount.to_vehicle(np.asarray(scan.points, dtype=np.float64))
        roi = (np.abs(pts[:, 0]) <= p.roi_x) & (np.abs(pts[:, 1]) <= p.roi_y)
        pts = pts[roi]
        ring = np.asarray(scan.ring, dtype=np.int64)[roi]
        column = np.asarray(scan.column, dtype=np.int64)[roi]
        self.ground = fit_ground(pts, p)
        h = self.ground.height(pts)
        keep = (h >= p.ground_clearance) & (h <= p.roi_height)
        return pts[keep], h[keep], ring[keep], column[keep]

    def detect(self, scan: LidarScan) -> tuple[Detection, ...]:
        """Boxes of the objects in ``scan``, vehicle frame, nearest first."""
        p = self.params
        pts, heights, rings, columns = self._obstacles(scan)
        xy = pts[:, :2]
        sensor = (scan.info.mount.x, scan.info.mount.y)

        def boxed(idx: IntArray) -> Detection | None:
            top = float(heights[idx].max())
            gap = ring_gap_top(scan.info, xy[idx], heights[idx], rings[idx], p)
            return box_from_points(xy[idx], top, sensor, p, heights[idx], gap)

        step = 2.0 * math.pi / scan.info.azimuth_steps  # [rad] between columns
        first = [(det, idx)
                 for idx in gated_clusters(cluster_labels(xy, p), xy, heights, p, step, columns)
                 if (det := boxed(idx)) is not None]
        found = [(det, xy[idx]) for old, idx in couple_trailers(first, xy, p)
                 if (det := old if old is not None else boxed(idx)) is not None]
        kept = suppress_fragments(found, p.fragment_margin)
        kept.sort(key=lambda d: (math.hypot(d.x - sensor[0], d.y - sensor[1]), d.x, d.y))
        return tuple(kept)
