"""Polygon zones (LANGUAGE.md §13): validation for the checker, inside/distance for the engine."""
from __future__ import annotations

import math
from typing import Optional, Sequence, Tuple

Point = Tuple[float, float]


def _orient(a: Point, b: Point, c: Point) -> float:
    return (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])


def _on_segment(a: Point, b: Point, p: Point) -> bool:
    return min(a[0], b[0]) <= p[0] <= max(a[0], b[0]) and min(a[1], b[1]) <= p[1] <= max(a[1], b[1])


def _cross(a: Point, b: Point, c: Point, d: Point) -> bool:
    """Segments ab and cd meet (touching counts)."""
    o1, o2, o3, o4 = _orient(a, b, c), _orient(a, b, d), _orient(c, d, a), _orient(c, d, b)
    if ((o1 > 0) != (o2 > 0)) and o1 != 0 and o2 != 0 and ((o3 > 0) != (o4 > 0)) and o3 != 0 and o4 != 0:
        return True
    return (o1 == 0 and _on_segment(a, b, c)) or (o2 == 0 and _on_segment(a, b, d)) or \
        (o3 == 0 and _on_segment(c, d, a)) or (o4 == 0 and _on_segment(c, d, b))


def polygon_problem(points: Sequence[Point]) -> Optional[str]:
    """Why these vertices are not a simple polygon, or None when they are."""
    n = len(points)
    if n < 3:
        return f"a polygon needs at least three vertices, not {n}"
    if any(not (math.isfinite(x) and math.isfinite(y)) for x, y in points):
        return "a polygon's vertices must be finite"
    for i in range(n):
        if points[i] == points[(i + 1) % n]:
            return f"vertices {i + 1} and {(i + 1) % n + 1} are the same point"
    if all(_orient(points[0], points[1], p) == 0 for p in points[2:]):
        return "all the vertices are on one line: the polygon has no area"
    edges = [(points[i], points[(i + 1) % n]) for i in range(n)]
    for i in range(n):
        for j in range(i + 1, n):
            if j == i + 1 or (i == 0 and j == n - 1):  # neighbours share a vertex
                a, b = edges[i]
                c, d = edges[j]
                shared = b if j == i + 1 else a
                other = d if j == i + 1 else c
                base = a if j == i + 1 else b
                # neighbours overlap only when folded back onto each other
                if _orient(base, shared, other) == 0 and _on_segment(base, shared, other) and other != shared:
                    return f"edges {i + 1} and {j + 1} overlap: the polygon is self-intersecting"
                continue
            if _cross(*edges[i], *edges[j]):
                return f"edges {i + 1} and {j + 1} cross: the polygon is self-intersecting"
    return None


def _segment_distance(p: Point, a: Point, b: Point) -> float:
    dx, dy = b[0] - a[0], b[1] - a[1]
    length2 = dx * dx + dy * dy
    t = 0.0 if length2 == 0 else max(0.0, min(1.0, ((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / length2))
    return math.hypot(p[0] - (a[0] + t * dx), p[1] - (a[1] + t * dy))


def boundary_distance(x: float, y: float, polygon: Sequence[Point]) -> float:
    """The distance from (x, y) to the polygon's boundary, never negative."""
    n = len(polygon)
    return min(_segment_distance((x, y), polygon[i], polygon[(i + 1) % n]) for i in range(n))


def inside(x: float, y: float, polygon: Sequence[Point]) -> bool:
    """The point is inside the polygon or on its boundary (even-odd rule)."""
    n = len(polygon)
    result = False
    for i in range(n):
        a, b = polygon[i], polygon[(i + 1) % n]
        if _orient(a, b, (x, y)) == 0 and _on_segment(a, b, (x, y)):
            return True
        if (a[1] > y) != (b[1] > y):
            cross_x = a[0] + (y - a[1]) * (b[0] - a[0]) / (b[1] - a[1])
            if x < cross_x:
                result = not result
    return result
