"""2-D regions in the (x, y) plane: boxes, discs and their unions.

Every region answers membership and signed distance for batches of points
(arrays of shape ``(..., 2)``), samples uniformly with a seeded generator, and
round-trips through plain dicts (JSON).  ``is_subset`` is exact for boxes and
discs inside boxes or unions of boxes, and conservative (it may answer False
for a true subset, never True for a false one) when only a mix of the outer set's
discs and boxes together covers a part of the inner set.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass

import numpy as np

from .errors import RegionError


class Region:
    """Base class; subclasses are frozen dataclasses."""

    def contains(self, points) -> np.ndarray:
        return self.signed_distance(points) <= 0.0

    def signed_distance(self, points) -> np.ndarray:  # pragma: no cover - abstract
        raise NotImplementedError

    def bounds(self) -> tuple[float, float, float, float]:  # pragma: no cover
        raise NotImplementedError

    @property
    def area(self) -> float:  # pragma: no cover - abstract
        raise NotImplementedError

    def sample(self, n: int, rng: np.random.Generator) -> np.ndarray:  # pragma: no cover
        raise NotImplementedError

    def centre(self) -> np.ndarray:
        """A representative point inside the region."""
        raise NotImplementedError  # pragma: no cover

    def to_dict(self) -> dict:  # pragma: no cover - abstract
        raise NotImplementedError

    def parts(self) -> tuple[Region, ...]:
        return (self,)


def _set_finite(region, fields) -> None:
    """The region's ``fields`` as floats; a NaN, an infinity or a non-number is a RegionError."""
    for f in fields:
        value = getattr(region, f)
        try:
            number = float(value) if not isinstance(value, (str, bytes, bool)) else None
        except (TypeError, ValueError):
            number = None
        if number is None or not np.isfinite(number):
            raise RegionError(f"a {type(region).__name__.lower()}'s {f} must be a finite number, got {value!r:.40}")
        object.__setattr__(region, f, number)


def _as_points(points) -> np.ndarray:
    pts = np.asarray(points, dtype=float)
    if pts.shape[-1] != 2:
        raise RegionError(f"points must have a trailing dimension of 2, got shape {pts.shape}")
    return pts


@dataclass(frozen=True)
class Box(Region):
    xmin: float
    ymin: float
    xmax: float
    ymax: float

    def __post_init__(self):
        _set_finite(self, ("xmin", "ymin", "xmax", "ymax"))
        if not (self.xmax > self.xmin and self.ymax > self.ymin):
            raise RegionError(f"empty box {self}")

    def signed_distance(self, points) -> np.ndarray:
        p = _as_points(points)
        cx, cy = (self.xmin + self.xmax) / 2, (self.ymin + self.ymax) / 2
        hx, hy = (self.xmax - self.xmin) / 2, (self.ymax - self.ymin) / 2
        dx = np.abs(p[..., 0] - cx) - hx
        dy = np.abs(p[..., 1] - cy) - hy
        outside = np.hypot(np.maximum(dx, 0.0), np.maximum(dy, 0.0))
        inside = np.minimum(np.maximum(dx, dy), 0.0)
        return outside + inside

    def bounds(self):
        return (self.xmin, self.ymin, self.xmax, self.ymax)

    @property
    def area(self) -> float:
        return (self.xmax - self.xmin) * (self.ymax - self.ymin)

    def sample(self, n, rng):
        u = rng.random((n, 2))
        return np.stack(
            [self.xmin + u[:, 0] * (self.xmax - self.xmin), self.ymin + u[:, 1] * (self.ymax - self.ymin)],
            axis=-1,
        )

    def centre(self):
        return np.array([(self.xmin + self.xmax) / 2, (self.ymin + self.ymax) / 2])

    def to_dict(self):
        return {"type": "box", "xmin": self.xmin, "ymin": self.ymin, "xmax": self.xmax, "ymax": self.ymax}


@dataclass(frozen=True)
class Disc(Region):
    cx: float
    cy: float
    r: float

    def __post_init__(self):
        _set_finite(self, ("cx", "cy", "r"))
        if not self.r > 0:
            raise RegionError(f"disc radius must be positive, got {self.r}")

    def signed_distance(self, points) -> np.ndarray:
        p = _as_points(points)
        return np.hypot(p[..., 0] - self.cx, p[..., 1] - self.cy) - self.r

    def bounds(self):
        return (self.cx - self.r, self.cy - self.r, self.cx + self.r, self.cy + self.r)

    @property
    def area(self) -> float:
        return float(np.pi * self.r**2)

    def sample(self, n, rng):
        radius = self.r * np.sqrt(rng.random(n))
        angle = rng.random(n) * 2 * np.pi
        return np.stack([self.cx + radius * np.cos(angle), self.cy + radius * np.sin(angle)], axis=-1)

    def centre(self):
        return np.array([self.cx, self.cy])

    def to_dict(self):
        return {"type": "disc", "cx": self.cx, "cy": self.cy, "r": self.r}


@dataclass(frozen=True)
class Union(Region):
    members: tuple[Region, ...]

    def __post_init__(self):
        flat: list[Region] = []
        for m in self.members:
            flat.extend(m.parts())
        if not flat:
            raise RegionError("a union needs at least one member")
        object.__setattr__(self, "members", tuple(flat))

    def parts(self):
        return self.members

    def signed_distance(self, points) -> np.ndarray:
        return np.min(np.stack([m.signed_distance(points) for m in self.members]), axis=0)

    def bounds(self):
        b = np.array([m.bounds() for m in self.members])
        return (b[:, 0].min(), b[:, 1].min(), b[:, 2].max(), b[:, 3].max())

    @property
    def area(self) -> float:
        """Area of the union (exact for boxes; Monte Carlo estimate if discs are present)."""
        if all(isinstance(m, Box) for m in self.members):
            xs, ys, covered = _elementary_cells(self.members, [])
            widths = np.diff(xs)[:, None] * np.diff(ys)[None, :]
            return float((widths * covered).sum())
        rng = np.random.default_rng(0)
        pts = Box(*self.bounds()).sample(20000, rng)
        return Box(*self.bounds()).area * float(self.contains(pts).mean())

    def sample(self, n, rng):
        """Uniform over the union: rejection from the members, weighted by area."""
        areas = np.array([m.area for m in self.members])
        chunks, total = [], 0
        while total < n:
            counts = rng.multinomial(2 * max(n - total, 16), areas / areas.sum())
            for i, count in enumerate(counts):
                pts = self.members[i].sample(count, rng)
                # drop points an earlier member also covers, so overlaps are not sampled twice
                seen = np.zeros(len(pts), dtype=bool)
                for earlier in self.members[:i]:
                    seen |= earlier.contains(pts)
                chunks.append(pts[~seen])
                total += int((~seen).sum())
        out = np.concatenate(chunks)
        out = out[rng.permutation(len(out))]
        return out[:n]

    def centre(self):
        """The member centre closest to the union's centroid (always inside)."""
        centres = np.array([m.centre() for m in self.members])
        areas = np.array([m.area for m in self.members])
        centroid = (centres * areas[:, None]).sum(0) / areas.sum()
        return centres[np.argmin(np.linalg.norm(centres - centroid, axis=1))]

    def to_dict(self):
        return {"type": "union", "members": [m.to_dict() for m in self.members]}


def union(regions: Iterable[Region]) -> Region:
    regions = list(regions)
    return regions[0] if len(regions) == 1 else Union(tuple(regions))


_FIELDS = {"box": (Box, ("xmin", "ymin", "xmax", "ymax")), "disc": (Disc, ("cx", "cy", "r"))}


def from_dict(d: dict) -> Region:
    """The region ``to_dict`` wrote; anything else (a list, a missing or non-finite number) is a RegionError."""
    if not isinstance(d, dict):
        raise RegionError(f"a region is a JSON object with a type, got {type(d).__name__} {d!r:.40}")
    kind = d.get("type")
    if kind == "union":
        if not isinstance(d.get("members"), list):
            raise RegionError("a union's members must be a list of regions")
        return Union(tuple(from_dict(m) for m in d["members"]))  # Union even for one member: lossless
    if kind not in _FIELDS:
        raise RegionError(f"unknown region type {kind!r:.40}")
    cls, fields = _FIELDS[kind]
    missing = [f for f in fields if f not in d]
    if missing:
        raise RegionError(f"a {kind} needs {', '.join(missing)}")
    return cls(*(d[f] for f in fields))


def _elementary_cells(boxes, extra_bounds):
    """Split the plane along every box edge; return edges and which cells the boxes cover."""
    xs = sorted({v for b in boxes for v in (b.xmin, b.xmax)} | {v for e in extra_bounds for v in (e[0], e[2])})
    ys = sorted({v for b in boxes for v in (b.ymin, b.ymax)} | {v for e in extra_bounds for v in (e[1], e[3])})
    xs, ys = np.array(xs), np.array(ys)
    mx, my = (xs[:-1] + xs[1:]) / 2, (ys[:-1] + ys[1:]) / 2
    centres = np.stack(np.meshgrid(mx, my, indexing="ij"), axis=-1)
    covered = np.zeros(centres.shape[:2], dtype=bool)
    for b in boxes:
        covered |= b.contains(centres)
    return xs, ys, covered


def _part_in_boxes(part: Region, boxes: list[Box]) -> bool:
    """Exact test that a box or disc lies inside a union of boxes (closed sets)."""
    xs, ys, covered = _elementary_cells(boxes, [part.bounds()])
    for i in range(len(xs) - 1):
        for j in range(len(ys) - 1):
            if covered[i, j]:
                continue
            cell = Box(xs[i], ys[j], xs[i + 1], ys[j + 1])
            if _interiors_meet(part, cell):
                return False
    return True


def _interiors_meet(part: Region, cell: Box) -> bool:
    if isinstance(part, Box):
        return part.xmin < cell.xmax and cell.xmin < part.xmax and part.ymin < cell.ymax and cell.ymin < part.ymax
    return float(cell.signed_distance(part.centre())) < part.r  # disc


def _part_in_part(a: Region, b: Region, tol: float) -> bool:
    if isinstance(b, Box):
        ax0, ay0, ax1, ay1 = a.bounds()
        return ax0 >= b.xmin - tol and ay0 >= b.ymin - tol and ax1 <= b.xmax + tol and ay1 <= b.ymax + tol
    if isinstance(a, Disc):
        return np.hypot(a.cx - b.cx, a.cy - b.cy) + a.r <= b.r + tol
    corners = np.array([[a.xmin, a.ymin], [a.xmin, a.ymax], [a.xmax, a.ymin], [a.xmax, a.ymax]])
    return bool(np.all(b.signed_distance(corners) <= tol))


def _shrunk(part: Region, tol: float) -> Region:
    """``part`` shrunk by ``tol`` on every side, so the exact cover test forgives round-off like the others."""
    if isinstance(part, Box) and min(part.xmax - part.xmin, part.ymax - part.ymin) > 2 * tol:
        return Box(part.xmin + tol, part.ymin + tol, part.xmax - tol, part.ymax - tol)
    if isinstance(part, Disc) and part.r > tol:
        return Disc(part.cx, part.cy, part.r - tol)
    return part


def is_subset(inner: Region, outer: Region, tol: float = 1e-9) -> bool:
    """True if every point of ``inner`` lies in ``outer``."""
    outer_parts = outer.parts()
    outer_boxes = [o for o in outer_parts if isinstance(o, Box)]  # inside these boxes => inside outer
    members = set(outer_parts)  # an avoid set of hundreds of wall boxes against itself: no pairwise test
    for part in inner.parts():
        if part in members or any(_part_in_part(part, o, tol) for o in outer_parts):
            continue
        if outer_boxes and _part_in_boxes(_shrunk(part, tol), outer_boxes):
            continue
        return False
    return True


# --- many points at once ------------------------------------------------------------------------
_TINY = float(np.nextafter(0.0, 1.0))  # sd <= 0  <=>  sd < _TINY


class CompiledRegion:
    """A region's boxes and discs as arrays: signed distances of many points in a few numpy calls.

    ``signed_distance`` gives the same numbers as ``Region.signed_distance`` (the same formula,
    vectorised over parts).  ``below(pts, thr)`` answers ``signed_distance < thr`` exactly but only
    looks at the few boxes near each point (a bucket grid built once per threshold), which keeps the
    wall check of a big maze (hundreds of boxes) cheap in the rollout loop.
    """

    BUCKET_MIN_PARTS = 12  # fewer boxes than this: just compute against all of them

    def __init__(self, region: Region):
        self.region = region
        parts = region.parts()
        boxes = [p for p in parts if isinstance(p, Box)]
        discs = [p for p in parts if isinstance(p, Disc)]
        self.other = [p for p in parts if not isinstance(p, (Box, Disc))]
        self.bc = np.array([[(b.xmin + b.xmax) / 2, (b.ymin + b.ymax) / 2] for b in boxes]).reshape(-1, 2)
        self.bh = np.array([[(b.xmax - b.xmin) / 2, (b.ymax - b.ymin) / 2] for b in boxes]).reshape(-1, 2)
        self.dc = np.array([[d.cx, d.cy] for d in discs]).reshape(-1, 2)
        self.dr = np.array([d.r for d in discs])
        self._grids: dict[float, tuple] = {}

    @staticmethod
    def _box_sd(pts, c, h):
        d = np.abs(pts[:, None, :] - c) - h  # (n, m, 2)
        dx, dy = d[..., 0], d[..., 1]
        return (np.hypot(np.maximum(dx, 0.0), np.maximum(dy, 0.0)) + np.minimum(np.maximum(dx, dy), 0.0)).min(axis=1)

    def _rest_sd(self, pts, out):
        if len(self.dc):
            dd = np.hypot(pts[:, None, 0] - self.dc[None, :, 0], pts[:, None, 1] - self.dc[None, :, 1]) - self.dr
            out = np.minimum(out, dd.min(axis=1))
        for p in self.other:
            out = np.minimum(out, p.signed_distance(pts))
        return out

    def signed_distance(self, pts: np.ndarray) -> np.ndarray:
        pts = np.asarray(pts, dtype=float).reshape(-1, 2)
        out = self._box_sd(pts, self.bc[None], self.bh[None]) if len(self.bc) else np.full(len(pts), np.inf)
        return self._rest_sd(pts, out)

    def contains(self, pts: np.ndarray) -> np.ndarray:
        """``signed_distance(pts) <= 0`` (= below the smallest positive float), exactly."""
        if len(self.bc) < self.BUCKET_MIN_PARTS:
            return self.signed_distance(pts) <= 0.0
        return self.below(pts, _TINY)

    def _grid(self, thr: float):
        """Bucket grid: for every bucket the boxes whose bounding box grown by ``thr`` meets it."""
        g = self._grids.get(thr)
        if g is None:
            lo = (self.bc - self.bh).min(axis=0) - thr - 1e-9
            hi = (self.bc + self.bh).max(axis=0) + thr + 1e-9
            size = float(max(np.median(self.bh.min(axis=1)) * 2, thr, (hi - lo).max() / 256, 1e-6))
            shape = np.maximum(np.ceil((hi - lo) / size).astype(int), 1)
            cells = [[] for _ in range(shape[0] * shape[1])]
            i0 = np.clip(np.floor((self.bc - self.bh - thr - 1e-9 - lo) / size).astype(int), 0, shape - 1)
            i1 = np.clip(np.floor((self.bc + self.bh + thr + 1e-9 - lo) / size).astype(int), 0, shape - 1)
            for j in range(len(self.bc)):
                for ix in range(i0[j, 0], i1[j, 0] + 1):
                    for iy in range(i0[j, 1], i1[j, 1] + 1):
                        cells[ix * shape[1] + iy].append(j)
            k = max(1, max(len(c) for c in cells))
            table = np.full((len(cells), k), len(self.bc))  # padding -> a dummy box far away
            for i, c in enumerate(cells):
                table[i, : len(c)] = c
            c = np.vstack([self.bc, [[1e18, 1e18]]])
            h = np.vstack([self.bh, [[0.0, 0.0]]])
            g = self._grids[thr] = (lo, size, shape, table, c, h)
        return g

    def below(self, pts: np.ndarray, thr: float, grid_thr: float = 0.0) -> np.ndarray:
        """``signed_distance(pts) < thr``, exactly, looking only at nearby boxes.

        The bucket grid is the one for ``max(thr, grid_thr)`` (a grid for a larger threshold answers a
        smaller one too): callers asking about many different thresholds pass their largest, and share one grid.
        """
        pts = np.asarray(pts, dtype=float).reshape(-1, 2)
        if len(self.bc) < self.BUCKET_MIN_PARTS:
            return self.signed_distance(pts) < thr
        lo, size, shape, table, c, h = self._grid(float(max(thr, grid_thr)))
        ij = np.floor((pts - lo) / size).astype(np.int64)
        inside = np.all((ij >= 0) & (ij < shape), axis=1)
        cand = table[np.where(inside, ij[:, 0] * shape[1] + ij[:, 1], 0)]  # (n, k)
        cand[~inside] = len(self.bc)
        out = self._box_sd(pts, c[cand], h[cand])
        return self._rest_sd(pts, out) < thr
