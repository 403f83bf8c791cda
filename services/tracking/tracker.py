"""Obstacle tracker: persistent ids, types (new / static / dynamic) and motion, frame by frame.

:class:`Tracker` is fed one obstacle chain per scan (:class:`Clusters` from perception, in
global coordinates) with the scan's stamp and robot pose, and returns the tracks.

Per update:

1. Every track is predicted to the new stamp (constant velocity).
2. Clusters are associated with tracks by optimal assignment
   (``scipy.optimize.linear_sum_assignment``) on the distance between the cluster's measured
   point and the track's prediction, gated at track radius + ``gate``.
3. Split: a cluster left over that is a piece of an associated cluster, cut from it by
   something nearer in front (both facing ends occluded, only nearer clusters between), or
   a chip broken off its end (a grazing surface with range noise), and within the track's
   gate, is joined to it: one obstacle behind a post stays one track.
4. Merge: a confirmed track that was seen in the previous frame, finds no cluster now and is
   predicted inside an associated cluster is taken as merged with it (two obstacles seen as
   one). Both tracks are kept for up to ``merge_hold`` seconds and coast on their
   prediction if the cluster grew (its centre is then neither obstacle's); when the two
   come apart they pick up their own clusters again by prediction.
5. The paper's xi, varsigma and delta (Eqs. 11-14) are computed against the previous chain;
   ``method="paper"`` types each obstacle with the decision tree and moves it with Eq. 15,
   ``method="smoothed"`` runs a constant-velocity Kalman filter and types by filtered speed.
6. Clusters left over start new tracks; tracks unseen for more than ``drop_after`` are
   dropped.

Ego-motion: perception makes every point global with the robot pose at scan time (Eq. 1),
so the robot's own motion and turning cancel out of the track positions. What remains is
that the visible part of an obstacle changes with the viewpoint: slowly for a whole
obstacle (the filter sees it as a few cm/s, below ``static_speed``), suddenly when it comes
out of hiding or leaves the window. Partly hidden clusters get a larger measurement noise,
except a walker's with one end free (``hidden_fit``): that one is measured as the disc of
its last whole view that the free end's beam grazes. A jump of the measured point (beyond
``jump_sigmas``, or when a hidden obstacle comes into full view) resets the position
instead of turning into velocity; when no change of view explains the jump, the velocity
is kept only with a new track's uncertainty (the track may have taken another obstacle for
its own).

Everything is deterministic: no randomness, ties broken by order.
"""

from __future__ import annotations

import math
from collections import deque
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np
import numpy.typing as npt
from scipy.optimize import linear_sum_assignment

from zenav.services.geometry import disc_mean_range, wrap_angle
from zenav.services.perception.clustering import (
    EDGE_FREE,
    EDGE_OCCLUDED,
    Clusters,
    box_area,
    to_global,
)
from zenav.services.tracking import _loops
from zenav.services.tracking.correlation import (
    Box,
    Kind,
    alpha_o_from_heading,
    best_match,
    classify,
    motion,
)
from zenav.services.tracking.params import TrackingParams

Pose = tuple[float, float, float]
FloatArray = npt.NDArray[np.float64]
Point = tuple[float, float]
# One remembered chain: its stamp, Eq. 5 centres and grid boxes.
Chain = tuple[float, list[Point], list[Box]]

# A cluster that covers a second track counts as a union of the two (and its centre as
# neither obstacle's) when its radius exceeds the track's by more than this, metres.
_MERGE_GROWTH = 0.05
_NO_MATCH = 1e9
# A chip of an obstacle starts at most this many beams after it (see _adjacent_piece).
_PIECE_BEAMS = 3
# Stamps are sums of scan periods: 0.3 - 0.1 need not reach 0.2 exactly, so a chain counts
# as compare_dt old within this much, seconds.
_STAMP_SLACK = 1e-6
# hidden_fit: the hidden end's point may lie this far off the fitted disc, metres (the free
# end's beam grazes the walker up to a beam step inside its true silhouette).
_FIT_SLACK = 0.15


class Track(NamedTuple):
    """One tracked obstacle as output by :meth:`Tracker.update` (an immutable record; a
    named tuple, which costs a fraction of a frozen dataclass to build, once per track and
    scan).

    Attributes:
        id: persistent id, unique over the tracker's life (1, 2, ...).
        kind: "new" | "static" | "dynamic".
        x: position, metres, global (Eq. 5 centre in "paper", filtered point in "smoothed").
        y: position, metres, global.
        vx: velocity estimate, m/s (given whatever the kind; the paper's V_k = 0 rule is for
            the consumer: treat a kind other than "dynamic" as standing still).
        vy: velocity estimate, m/s.
        speed: |v|, m/s (Eq. 15 v_o in "paper").
        heading: direction of motion, radians from +x counter-clockwise (REP 103), in
            (-pi, pi]; 0 when the speed is 0.
        alpha_o_deg: the paper's alpha_o, degrees clockwise from +y, in [0, 360).
        distance: d_o, metres moved over the last period (Eq. 15).
        xi: coincidence with the best-matching previous obstacle (Eq. 11), [0, 1].
        varsigma: varsigma_max over the previous chain (Eq. 14), 0 if there was none.
        delta: centre distance to that previous obstacle (Eq. 13), grid cells (inf if none).
        radius: footprint radius of the visible part, metres (of the last whole view for a
            walker fitted by ``hidden_fit``).
        age: frames in which the track was seen.
        last_seen: stamp of the last frame that saw it, seconds.
        box: grid box (ix_min, ix_max, iy_min, iy_max) when last seen.
        area: S_k, cells, when last seen.
        visible: seen in this frame (False: coasting on its prediction).
    """

    id: int
    kind: Kind
    x: float
    y: float
    vx: float
    vy: float
    speed: float
    heading: float
    alpha_o_deg: float
    distance: float
    xi: float
    varsigma: float
    delta: float
    radius: float
    age: int
    last_seen: float
    box: tuple[int, int, int, int]
    area: int
    visible: bool


@dataclass(slots=True)
class _State:
    """Mutable state of one track."""

    id: int
    kind: Kind
    # Kalman filter, per axis state (position, velocity); x and y share one covariance
    # [[p00, p01], [p01, p11]] because their noise and updates are the same.
    x: float
    y: float
    vx: float
    vy: float
    p00: float
    p01: float
    p11: float
    # last measurement
    centre: tuple[float, float]
    radius: float
    box: tuple[int, int, int, int]
    area: int
    partial: bool
    n_parts: int
    # paper quantities of the last frame that saw it
    xi: float
    varsigma: float
    delta: float
    paper_vx: float
    paper_vy: float
    paper_d: float
    age: int
    last_seen: float
    merged_since: float | None
    last_moved: float | None = None  # stamp of the last frame the motion cue fired
    born: float = 0.0  # stamp of the first frame
    whole_radius: float = 0.0  # radius of the last view with both ends free (0: none yet)


@dataclass(slots=True)
class _Measurement:
    """One obstacle of this frame: a cluster, or several pieces of one (split)."""

    centre: tuple[float, float]  # Eq. 5, global
    point: tuple[float, float]  # the point the filter measures
    radius: float
    box: tuple[int, int, int, int]
    area: int
    partial: bool
    n_parts: int
    fitted: bool = False  # measured as the disc of the last whole view (hidden_fit)


@dataclass(slots=True)
class _Rows:
    """The per-cluster values of a chain the tracker reads one by one, as Python numbers
    (``tolist``: the same values; a numpy scalar costs more to index and convert than
    the arithmetic done with it on a chain of a few obstacles). Built once per scan and
    only read (not frozen: a frozen dataclass sets each field through a call)."""

    centre: list[tuple[float, float]]
    chord_centre: list[tuple[float, float]]
    radius: list[float]
    box: list[tuple[int, int, int, int]]
    area: list[int]
    edge_start: list[int]
    edge_end: list[int]
    mean_rho: list[float]
    beams: list[list[int]]
    first_point: list[list[float]]
    last_point: list[list[float]]
    moved: list[float] | None
    moved_each: list[list[float]] | None
    moved_refs: list[tuple[int, float]] | None
    """(column of ``moved_each``, stamp) of each earlier scan compared with, those that
    were remembered (a finite stamp)."""

    @staticmethod
    def of(clusters: Clusters) -> _Rows:
        each, refs = clusters.moved_each, clusters.moved_refs
        return _Rows(
            centre=[(x, y) for x, y in clusters.centre.tolist()],
            chord_centre=[(x, y) for x, y in clusters.chord_centre.tolist()],
            radius=clusters.radius.tolist(),
            box=[(a, b, c, d) for a, b, c, d in clusters.box.tolist()],
            area=clusters.area.tolist(),
            edge_start=clusters.edge_start.tolist(),
            edge_end=clusters.edge_end.tolist(),
            mean_rho=clusters.mean_rho.tolist(),
            beams=clusters.beams.tolist(),
            first_point=clusters.first_point.tolist(),
            last_point=clusters.last_point.tolist(),
            moved=clusters.moved.tolist() if clusters.moved is not None else None,
            moved_each=each.tolist() if each is not None and refs is not None else None,
            moved_refs=([(k, ref) for k, ref in enumerate(refs.tolist()) if math.isfinite(ref)]
                        if each is not None and refs is not None else None),
        )  # fmt: skip


def _moved_since_born(rows: _Rows, c: int, born: float) -> float:
    """Cluster ``c``'s motion score against the earlier scans taken since the track was
    first seen (``born``). An obstacle that appears out of nothing occupies space the
    scans before it saw empty, without having moved: the paper calls it new, and it is
    judged from its own next scans, not from the empty space before. (The largest score
    as numpy's ``max(initial=0.0)`` has it: nan if any is.)
    """
    if rows.moved_each is None or rows.moved_refs is None:
        return rows.moved[c] if rows.moved is not None else 0.0
    limit = born - 1e-9
    best = 0.0
    scores = rows.moved_each[c]
    for k, ref in rows.moved_refs:
        if ref >= limit:
            score = scores[k]
            if math.isnan(score):
                return math.nan
            best = score if score > best else best
    return best


def _union(a: tuple[int, int, int, int], b: tuple[int, int, int, int]) -> tuple[int, int, int, int]:
    """The grid box holding both boxes (ix_min, ix_max, iy_min, iy_max)."""
    return (min(a[0], b[0]), max(a[1], b[1]), min(a[2], b[2]), max(a[3], b[3]))


class Tracker:
    """Frame-to-frame obstacle tracker (see the module notes).

    Example::

        tracker = Tracker(TrackingParams(method="smoothed"))
        for stamp, pose, clusters in frames:
            tracks = tracker.update(stamp, pose, clusters)
    """

    def __init__(self, params: TrackingParams | None = None) -> None:
        self.params = params if params is not None else TrackingParams()
        self._tracks: list[_State] = []
        self._next_id = 1
        self._last_stamp: float | None = None
        self._lost: list[_State] = []  # movers dropped lately, for ``reacquire`` s
        # chains to compare with: (stamp, Eq. 5 centres, grid boxes)
        self._history: deque[Chain] = deque()

    def update(self, stamp: float, pose: Pose, clusters: Clusters) -> list[Track]:
        """Take one scan's obstacle chain and return every live track, sorted by id.

        Args:
            stamp: scan time, seconds; must increase from call to call.
            pose: robot pose (x, y, heading rad) at scan time. The clusters are already
                global; the pose re-derives the Eq. 5 centre when the pieces of a split
                obstacle are joined.
            clusters: the obstacle chain from perception for this scan.

        Returns:
            The tracks seen in this frame (``visible``) and those coasting until dropped.
        """
        p = self.params
        if self._last_stamp is not None and not stamp > self._last_stamp:
            raise ValueError(f"stamp {stamp} does not follow {self._last_stamp}")
        prev_stamp = self._last_stamp
        dt = 0.0 if prev_stamp is None else stamp - prev_stamp
        smoothed = p.method == "smoothed"
        for t in self._tracks:
            self._predict(t, dt)

        use_chord = smoothed and p.position == "chord"
        points = clusters.chord_centre if use_chord else clusters.centre
        rows = _Rows.of(clusters)
        owner = self._associate(points, clusters)
        groups = self._join_pieces(owner, rows, rows.chord_centre if use_chord else rows.centre)
        meas = {ti: self._measure(cl, clusters, pose, smoothed, rows)
                for ti, cl in groups.items()}
        if smoothed and p.hidden_fit:
            for ti, cl in groups.items():
                if len(cl) == 1:
                    fit = self._fit_hidden(self._tracks[ti], meas[ti], rows, cl[0], pose)
                    if fit is not None:
                        meas[ti] = fit
        hold, coast = self._merges(meas, prev_stamp, stamp)

        claimed = {c for cl in groups.values() for c in cl}
        members = dict(groups)
        fresh: set[int] = set()
        for c in range(len(clusters)):
            if c not in claimed:  # a new obstacle: a new track, ids in scan order
                m = self._measure([c], clusters, pose, smoothed, rows)
                fresh.add(len(self._tracks))
                members[len(self._tracks)] = [c]
                meas[len(self._tracks)] = m
                self._tracks.append(self._reacquired(m, stamp) or self._new_state(m, stamp))

        # Eqs. 11-14 against the chain compared with: xi, varsigma_max, delta (cells).
        order = sorted(meas)
        centres = [meas[i].centre for i in order]
        boxes = [meas[i].box for i in order]
        ref_stamp, ref_centres, ref_boxes = self._reference(stamp)
        best_xi: list[float] = []
        best_varsigma: list[float] = []
        best_delta: list[float] = []
        best_index: list[int] = []
        if order:  # (a frame without obstacles has nothing to compare)
            best = best_match(
                centres, boxes, ref_centres, ref_boxes,
                cell=clusters.cell, y_delta=p.y_delta, y_eta=p.y_eta,
            )  # fmt: skip
            best_xi, best_varsigma = best.xi, best.varsigma_max
            best_delta, best_index = best.delta, best.index

        for row, ti in enumerate(order):
            t = self._tracks[ti]
            m = meas[ti]
            t.xi = best_xi[row]
            t.varsigma = best_varsigma[row]
            t.delta = best_delta[row]
            if ti not in fresh:
                t.age += 1
                if ti not in coast:
                    self._correct(t, m)
            if not m.partial and not m.fitted and m.n_parts == 1 and ti not in coast:
                t.whole_radius = m.radius
            was_static = t.kind == "static"
            if clusters.moved is not None:
                cl = members[ti]
                moved = (_moved_since_born(rows, cl[0], t.born) if len(cl) == 1
                         else max(_moved_since_born(rows, c, t.born) for c in cl))
                if moved >= p.moved_threshold:
                    t.last_moved = stamp
            if smoothed:
                t.kind = self._smoothed_kind(t, stamp, clusters.moved is not None)
            else:
                t.kind = classify(
                    t.varsigma, t.delta, t.xi,
                    theta_varsigma1=p.theta_varsigma1, theta_varsigma2=p.theta_varsigma2,
                    theta_delta=p.theta_delta, theta_xi=p.theta_xi,
                )  # fmt: skip
                j = best_index[row]
                if j >= 0:  # Eq. 15 between this frame and the chain compared with
                    mo = motion(m.centre, ref_centres[j], stamp - ref_stamp)
                    t.paper_vx, t.paper_vy, t.paper_d = mo.vx, mo.vy, mo.d_o
                else:
                    t.paper_vx = t.paper_vy = t.paper_d = 0.0
            t.centre = m.centre
            if ti not in coast and was_static and t.kind == "static":
                # A standing obstacle shows other faces as the robot drives round it: its
                # grid area S_k is everything seen of it so far, not just this scan's part.
                # Only a view with both ends free adds to it; a part cut off by something
                # in front or by the window edge neither grows nor shrinks it.
                if not m.partial:
                    t.box = _union(t.box, m.box)
                    t.area = box_area(t.box)  # Eq. 6
                    t.radius = max(t.radius, m.radius)
            elif ti not in coast:  # a coasting track keeps its own footprint
                t.radius, t.box, t.area = m.radius, m.box, m.area
            t.partial, t.n_parts = m.partial, m.n_parts
            t.last_seen = stamp
        for ti in hold:
            self._tracks[ti].last_seen = stamp  # hidden in another's cluster: keep alive
        for t in self._tracks:
            if t.kind == "static" and t.last_seen != stamp:
                # Unseen (out of view, say): a standing obstacle stays where it was seen.
                t.x, t.y = t.centre
                t.vx = t.vy = 0.0
        for ti, t in enumerate(self._tracks):
            if ti not in hold:
                t.merged_since = None  # only a held track counts its merge time

        self._remember(stamp, centres, boxes)
        self._last_stamp = stamp
        visible = set(order)
        # Drop tracks unseen for longer than drop_after, and tentative ones (still "new")
        # at their first miss: a one-frame speck must not linger as an obstacle.
        live = [
            ti
            for ti, t in enumerate(self._tracks)
            if t.last_seen == stamp
            or (t.age > p.new_frames and stamp - t.last_seen <= p.drop_after)
            or (t.age >= p.memory_min_age and t.kind == "static"
                and stamp - t.last_seen <= p.memory and not self._in_view(t, pose))
        ]
        out = [self._output(self._tracks[ti], dt, ti in visible and ti not in hold) for ti in live]
        if p.reacquire > 0.0:
            kept = set(live)
            self._lost = [t for t in self._lost if stamp - t.last_seen <= p.reacquire]
            # Only a mover dropped beside or behind the laser's field of view: one lost
            # in view (hidden by another, merged with it, or walked out of range) is not
            # looked for, so a walker of a crowd is not taken for another that vanished
            # near it (at 360 degrees nothing is looked for).
            self._lost += [t for ti, t in enumerate(self._tracks)
                           if ti not in kept and t.kind == "dynamic"
                           and math.hypot(t.vx, t.vy) >= p.static_speed
                           and not self._in_field(t, pose)]
        self._tracks = [self._tracks[ti] for ti in live]
        out.sort(key=lambda tr: tr.id)
        return out

    def _in_field(self, t: _State, pose: Pose) -> bool:
        """Whether the track's bearing from ``pose`` lies in the scanner's field of view."""
        bearing = wrap_angle(math.atan2(t.y - pose[1], t.x - pose[0]) - pose[2])
        return abs(bearing) <= math.radians(self.params.fov_deg) / 2

    def _in_view(self, t: _State, pose: Pose) -> bool:
        """Whether the scanner at ``pose`` could see the track's obstacle (ignoring
        occlusion): inside the field of view and the view range."""
        if math.hypot(t.x - pose[0], t.y - pose[1]) - t.radius > self.params.window_radius:
            return False
        return self._in_field(t, pose)

    # --- association -------------------------------------------------------------------

    def _associate(self, points: FloatArray, clusters: Clusters) -> list[int]:
        """Optimal cluster -> track assignment on predicted distance, gated; -1 = none."""
        n, k = len(clusters), len(self._tracks)
        owner = [-1] * n
        if n == 0 or k == 0:
            return owner
        # distance to each prediction within the track's gate (radius + gate), compiled
        cost = _loops.gated_distances(np.ascontiguousarray(points, dtype=np.float64),
                                      [(t.x, t.y, t.radius) for t in self._tracks],
                                      self.params.gate, _NO_MATCH)
        lone = _loops.lone_pairs(cost, _NO_MATCH)
        if lone is not None:
            return lone  # no cluster or track with a choice: the assignment is these pairs
        rows, cols = linear_sum_assignment(cost)
        matched = (cost[rows, cols] < _NO_MATCH).tolist()
        for r, c, ok in zip(rows.tolist(), cols.tolist(), matched, strict=True):
            if ok:
                owner[r] = c
        return owner

    def _join_pieces(
        self, owner: list[int], rows: _Rows, points: list[tuple[float, float]]
    ) -> dict[int, list[int]]:
        """Track -> its clusters: the assigned one plus the pieces of the same obstacle.

        A left-over cluster c joins the cluster a of track T, if c is within T's gate, when

        * c is a chip of a (see ``_adjacent_piece``), or
        * an occluder cut them apart: walking along the scan from c, every cluster passed is
          nearer than both, a is the first one that is not, and the ends of c and a facing
          each other are both occluded.
        """
        groups: dict[int, list[int]] = {ti: [c] for c, ti in enumerate(owner) if ti >= 0}
        n = len(owner)
        if all(ti >= 0 for ti in owner):
            return groups  # nothing left over to join
        rho = rows.mean_rho
        for c in range(n):
            if owner[c] >= 0:
                continue
            j = self._adjacent_piece(c, owner, rows)
            if j >= 0 and self._in_gate(points[c], owner[j]):
                groups[owner[j]].append(c)
                continue
            for step in (-1, 1):
                own_end = rows.edge_start if step < 0 else rows.edge_end
                far_end = rows.edge_end if step < 0 else rows.edge_start
                if own_end[c] != EDGE_OCCLUDED:
                    continue
                j = c + step
                nearest_between = math.inf
                while 0 <= j < n and rho[j] < rho[c]:
                    nearest_between = min(nearest_between, rho[j])
                    j += step
                if not (0 <= j < n) or j == c + step or owner[j] < 0:
                    continue
                if far_end[j] != EDGE_OCCLUDED or rho[j] <= nearest_between:
                    continue
                if not self._in_gate(points[c], owner[j]):
                    continue
                groups[owner[j]].append(c)
                break
        for cl in groups.values():
            cl.sort()
        return groups

    def _in_gate(self, point: tuple[float, float], ti: int) -> bool:
        t = self._tracks[ti]
        return math.hypot(point[0] - t.x, point[1] - t.y) <= t.radius + self.params.gate

    def _adjacent_piece(self, c: int, owner: list[int], rows: _Rows) -> int:
        """The associated cluster that c is a chip of (next in the scan, ends close), or -1.

        A surface seen at a grazing angle, with range noise, breaks off a few beams at its
        end; such a chip, at most ``_PIECE_BEAMS`` beams and ``piece_gap`` metres from the
        end of an associated cluster, belongs to that obstacle.
        """
        gap = self.params.piece_gap
        for j in (c - 1, c + 1):
            if not 0 <= j < len(owner) or owner[j] < 0:
                continue
            a, b = (j, c) if j < c else (c, j)  # a before b in the scan
            if rows.beams[b][0] - rows.beams[a][1] > _PIECE_BEAMS:
                continue
            end, start = rows.last_point[a], rows.first_point[b]
            if math.hypot(end[0] - start[0], end[1] - start[1]) <= gap:
                return j
        return -1

    def _merges(
        self, meas: dict[int, _Measurement], prev_stamp: float | None, stamp: float
    ) -> tuple[set[int], set[int]]:
        """Find tracks merged into another's cluster.

        Returns ``hold``: tracks with no cluster kept alive inside another's, and ``coast``:
        tracks whose cluster is the union of two obstacles (their update is skipped; only in
        "smoothed", the paper's estimate takes the cluster as it is).
        """
        p = self.params
        hold: set[int] = set()
        coast: set[int] = set()
        if not meas:
            return hold, coast
        for bi, b in enumerate(self._tracks):
            if bi in meas or b.age <= p.new_frames:
                continue
            if b.last_seen != prev_stamp and b.merged_since is None:
                continue  # only a track seen until just now can have merged
            best_ai, best_d = -1, math.inf
            for ai, m in meas.items():
                d = math.hypot(b.x - m.point[0], b.y - m.point[1])
                if d <= m.radius + p.gate and d < best_d:
                    best_ai, best_d = ai, d
            if best_ai < 0:
                continue
            if b.merged_since is None:
                b.merged_since = stamp
            if stamp - b.merged_since > p.merge_hold:
                continue  # merged too long: let it age out, the cluster is the other's
            hold.add(bi)
            grown = meas[best_ai].radius > self._tracks[best_ai].radius + _MERGE_GROWTH
            if p.method == "smoothed" and grown:
                coast.add(best_ai)
        return hold, coast

    # --- measurements and the chain history -------------------------------------------

    def _measure(
        self, cl: list[int], clusters: Clusters, pose: Pose, smoothed: bool,
        rows: _Rows | None = None,
    ) -> _Measurement:
        """The measurement of one obstacle from its cluster(s), pieces joined in scan order
        (``rows``: the chain's, when the caller has them already)."""
        use_chord = smoothed and self.params.position == "chord"
        if len(cl) == 1:
            c = cl[0]
            r = rows if rows is not None else _Rows.of(clusters)
            centre = r.centre[c]
            return _Measurement(
                centre=centre,
                point=r.chord_centre[c] if use_chord else centre,
                radius=r.radius[c],
                box=r.box[c],
                area=r.area[c],
                partial=r.edge_start[c] != EDGE_FREE or r.edge_end[c] != EDGE_FREE,
                n_parts=1,
            )
        idx = np.asarray(cl, dtype=np.int64)
        w = clusters.n_beams[idx].astype(np.float64)
        # Eq. 5 over all beams of the pieces (beam-weighted means), then Eq. 1.
        rho = float(np.dot(w, clusters.mean_rho[idx]) / w.sum())
        alpha = float(np.dot(w, clusters.mean_alpha[idx]) / w.sum())
        gx, gy = to_global(pose, rho, alpha)
        centre = (float(gx), float(gy))
        first, last = cl[0], cl[-1]
        cx = 0.5 * float(clusters.first_point[first, 0] + clusters.last_point[last, 0])
        cy = 0.5 * float(clusters.first_point[first, 1] + clusters.last_point[last, 1])
        ch = clusters.chord_centre[idx]
        radius = float(np.max(np.hypot(ch[:, 0] - cx, ch[:, 1] - cy) + clusters.radius[idx]))
        bx = clusters.box[idx]
        box = (int(bx[:, 0].min()), int(bx[:, 1].max()), int(bx[:, 2].min()), int(bx[:, 3].max()))
        return _Measurement(
            centre=centre,
            point=(cx, cy) if use_chord else centre,
            radius=radius,
            box=box,
            area=box_area(box),  # Eq. 6
            partial=bool(
                clusters.edge_start[first] != EDGE_FREE or clusters.edge_end[last] != EDGE_FREE
            ),
            n_parts=len(cl),
        )

    def _fit_hidden(
        self, t: _State, m: _Measurement, rows: _Rows, c: int, pose: Pose
    ) -> _Measurement | None:
        """A walker's partial view measured as the disc of its last whole view.

        One end of the cluster is free: its beam grazes the walker's silhouette, so the
        walker's centre lies ``whole_radius`` off that beam, square to it, on the side of
        the hidden end. The point measured is where the Eq. 5 centre of that disc seen
        whole would be, so the filter sees no jump between whole and partial views. None
        when the track is no walker with a whole view, both or neither end is free, or the
        hidden end's point does not lie on that disc.
        """
        if t.kind != "dynamic" or t.whole_radius <= 0.0 or not m.partial:
            return None
        start_free = rows.edge_start[c] == EDGE_FREE
        if start_free == (rows.edge_end[c] == EDGE_FREE):
            return None
        r = t.whole_radius
        # Beams go counter-clockwise: a free first beam has the walker on its left.
        if start_free:
            (tx, ty), (hx, hy), side = rows.first_point[c], rows.last_point[c], 1.0
        else:
            (tx, ty), (hx, hy), side = rows.last_point[c], rows.first_point[c], -1.0
        dx, dy = tx - pose[0], ty - pose[1]
        reach = math.hypot(dx, dy)
        if reach <= r:
            return None
        ux, uy = dx / reach, dy / reach
        cx, cy = tx - side * r * uy, ty + side * r * ux
        if abs(math.hypot(hx - cx, hy - cy) - r) > _FIT_SLACK:
            return None
        d = math.hypot(cx - pose[0], cy - pose[1])
        k = disc_mean_range(d, r) / d
        return _Measurement(
            centre=m.centre,
            point=(pose[0] + (cx - pose[0]) * k, pose[1] + (cy - pose[1]) * k),
            # Not partial: the filter takes it as a whole view (no reset when the walker
            # comes into full view again), with its own noise (fitted_meas_std).
            radius=max(r, m.radius), box=m.box, area=m.area, partial=False, n_parts=1,
            fitted=True,
        )  # fmt: skip

    def _reference(self, stamp: float) -> Chain:
        """The chain to compare with: the newest at least ``compare_dt`` old, else the oldest."""
        limit = stamp - self.params.compare_dt + _STAMP_SLACK
        chosen: Chain | None = None
        for entry in self._history:
            if entry[0] <= limit:
                chosen = entry
        if chosen is None and self._history:
            chosen = self._history[0]
        if chosen is None:
            return stamp, [], []
        return chosen

    def _remember(self, stamp: float, centres: list[Point], boxes: list[Box]) -> None:
        """Store this chain, dropping the ones no later frame can compare with."""
        self._history.append((stamp, centres, boxes))
        limit = stamp - self.params.compare_dt + _STAMP_SLACK
        # Keep the newest entry at or before the limit (the next frame's limit is later).
        while len(self._history) > 1 and self._history[1][0] <= limit:
            self._history.popleft()

    # --- Kalman filter and types ---------------------------------------------------------

    def _new_state(self, m: _Measurement, stamp: float) -> _State:
        p = self.params
        r = p.partial_meas_std if m.partial else p.meas_std
        t = _State(
            id=self._next_id, kind="new",
            x=m.point[0], y=m.point[1], vx=0.0, vy=0.0,
            p00=r * r, p01=0.0, p11=p.init_speed_std**2,
            centre=m.centre, radius=m.radius, box=m.box, area=m.area,
            partial=m.partial, n_parts=m.n_parts,
            xi=0.0, varsigma=0.0, delta=math.inf,
            paper_vx=0.0, paper_vy=0.0, paper_d=0.0,
            age=1, last_seen=stamp, merged_since=None, born=stamp,
        )  # fmt: skip
        self._next_id += 1
        return t

    def _reacquired(self, m: _Measurement, stamp: float) -> _State | None:
        """The lost mover that ``m`` is seen again, if any: the nearest whose prediction
        from where it was last seen, at its velocity then, lies within both radii plus
        half the way it walked meanwhile (slack for a turn or a change of pace). It comes
        back where it is measured, with its id, velocity and type, and counts as moving
        now: it was found where its motion took it."""
        best: tuple[float, int] | None = None
        for i, t in enumerate(self._lost):
            age = stamp - t.last_seen
            px, py = t.x + t.vx * age, t.y + t.vy * age
            gap = math.hypot(m.point[0] - px, m.point[1] - py)
            if (gap <= t.radius + m.radius + 0.5 * math.hypot(t.vx, t.vy) * age
                    and (best is None or gap < best[0])):
                best = (gap, i)
        if best is None:
            return None
        t = self._lost.pop(best[1])
        r = self.params.partial_meas_std if m.partial else self.params.meas_std
        t.x, t.y = m.point
        t.p00, t.p01 = r * r, 0.0
        t.centre, t.radius, t.box, t.area = m.centre, m.radius, m.box, m.area
        t.partial, t.n_parts = m.partial, m.n_parts
        t.last_seen = t.last_moved = t.born = stamp
        t.merged_since = None
        return t

    def _predict(self, t: _State, dt: float) -> None:
        """Constant-velocity prediction over dt with white-acceleration noise."""
        if dt <= 0.0:
            return
        q = self.params.accel_std**2
        t.x += t.vx * dt
        t.y += t.vy * dt
        p00, p01, p11 = t.p00, t.p01, t.p11
        t.p00 = p00 + 2.0 * dt * p01 + dt * dt * p11 + q * dt**3 / 3.0
        t.p01 = p01 + dt * p11 + q * dt * dt / 2.0
        t.p11 = p11 + q * dt

    def _correct(self, t: _State, m: _Measurement) -> None:
        """Kalman update with the measured point, or a position reset on a jump."""
        p = self.params
        r = p.partial_meas_std if m.partial else p.fitted_meas_std if m.fitted else p.meas_std
        r2 = r * r
        ix = m.point[0] - t.x
        iy = m.point[1] - t.y
        s = t.p00 + r2
        view_changed = (t.partial and not m.partial) or m.n_parts != t.n_parts
        innovation2 = ix * ix + iy * iy
        jumped = innovation2 > p.jump_sigmas**2 * s
        if view_changed or jumped:
            # What is visible changed (or the point jumped): the old point is not comparable,
            # so restart the position from the measurement and keep the velocity.
            t.x, t.y = m.point
            t.p00, t.p01 = r2, 0.0
            if jumped and (not view_changed or innovation2 > (2.0 * m.radius) ** 2):
                # A jump that no change of view explains: perhaps another obstacle taken
                # for this one (two walkers crossing). Its velocity is then as unknown as
                # a new track's; kept as the mean, it is learnt again from the next scans.
                t.p11 = max(t.p11, p.init_speed_std**2)
            return
        k0 = t.p00 / s
        k1 = t.p01 / s
        t.x += k0 * ix
        t.y += k0 * iy
        t.vx += k1 * ix
        t.vy += k1 * iy
        p00, p01, p11 = t.p00, t.p01, t.p11
        t.p00 = (1.0 - k0) * p00
        t.p01 = (1.0 - k0) * p01
        t.p11 = p11 - k1 * p01

    def _smoothed_kind(self, t: _State, stamp: float, cue: bool) -> Kind:
        """Type from the free-space motion cue when perception measures it, else from the
        filtered speed alone; with hysteresis; "new" for the first frames.

        With the cue, a track is dynamic while the cue fired within ``moved_hold`` s (or,
        in its first ``cue_warmup`` s, while the filter is sure of a high speed). The
        filtered speed alone cannot tell a slow walker from the drift of a box's visible
        part as the robot drives past (at 0.5 m/s that drift exceeds 0.2 m/s); the cue
        can. A fast mover just come into view is caught by the cue's shortest (0.2 s) baseline."""
        p = self.params
        if t.age <= p.new_frames:
            return "new"
        speed = math.hypot(t.vx, t.vy)
        if cue:
            # The cue decides; the filtered speed only keeps a mover dynamic while it is
            # briefly out of the cue's sight (passing beside the robot, say).
            moving = t.last_moved is not None and stamp - t.last_moved <= p.moved_hold
            still_going = (t.kind == "dynamic" and speed >= p.static_speed
                           and t.last_moved is not None
                           and stamp - t.last_moved <= p.moved_hold + p.drop_after)
            # Before the cue has an earlier scan to compare with, a confident filter speed
            # well above walking pace decides (a fast mover that just came into view).
            significant = speed > p.speed_sigmas * math.sqrt(max(t.p11, 0.0))
            warming_up = stamp - t.born < p.cue_warmup
            fast = warming_up and speed > p.dynamic_speed and significant
            return "dynamic" if moving or still_going or fast else "static"
        if t.kind == "dynamic":
            return "dynamic" if speed >= p.static_speed else "static"
        significant = speed > p.speed_sigmas * math.sqrt(max(t.p11, 0.0))
        return "dynamic" if speed > p.dynamic_speed and significant else "static"

    def _output(self, t: _State, dt: float, visible: bool) -> Track:
        if self.params.method == "smoothed":
            x, y, vx, vy = t.x, t.y, t.vx, t.vy
            speed = math.hypot(vx, vy)
            distance = speed * dt
        else:
            x, y = t.centre if visible else (t.x, t.y)
            vx, vy = t.paper_vx, t.paper_vy
            speed = math.hypot(vx, vy)
            distance = t.paper_d
        heading = math.atan2(vy, vx) if speed > 0.0 else 0.0
        alpha_o_deg = alpha_o_from_heading(heading) if speed > 0.0 else 0.0
        # Positional, in the order of Track's fields (a named tuple built by keyword costs
        # about three times as much; tests/tracking/test_tracker_rows.py pins the order).
        return Track(t.id, t.kind, x, y, vx, vy, speed, heading, alpha_o_deg, distance,
                     t.xi, t.varsigma, t.delta, t.radius, t.age, t.last_seen, t.box, t.area,
                     visible)
