"""Typed stages: the intermediate results a method returns beside its skeleton, for overlays, reports and tests.

A stage checks its own arrays when it is made (ValueError naming the stage and what is wrong), maps itself from
the frame a method worked in back to the world (``mapped``), and says how it is drawn (``drawing``: world-space
``Lines``, ``Points``, ``ClassedFaces`` or ``Labels``, or None for data that is not drawn). The Blender layer draws
those primitives and nothing else, so a new stage type, a subclass of :class:`Stage`, gets its overlay without a line
changed there. Planar stages (an outline, a triangulation, a graph in a view's plane) hold the :class:`Frame` of
their view, whose plane gives their 2D points a place in 3D.
"""
import dataclasses
import math
import numbers

import numpy as np

TERMINAL, SLEEVE, JUNCTION, ISOLATED = 2, 1, 0, 3  # triangle classes: how many edges lie on the outline
UNIT_TOLERANCE = 1e-6  # directions (view, plane normals, frame axes) are unit vectors within this


@dataclasses.dataclass(frozen=True)
class Placement:
    """Where a method worked: at ``factor`` times the mesh's size, along ``axes`` (rows: its axes in world
    coordinates; None for the world's own). Maps coordinates back to the world."""

    factor: float = 1.0
    axes: np.ndarray = None

    def point(self, points):
        """3D points (or one) in the world."""
        return self.vector(np.asarray(points) / self.factor)

    def vector(self, vectors):
        """Directions (unscaled) in the world."""
        return vectors if self.axes is None else vectors @ self.axes

    def length(self, values):
        """Lengths, or 2D coordinates in a plane whose axes turn with the frame, at the world's size."""
        return values / self.factor


# Drawing primitives: what the Blender layer turns into overlay objects, all in world coordinates.

@dataclasses.dataclass(frozen=True, eq=False)
class Lines:
    """Line segments: ``points`` (K, 3) and ``edges`` (E, 2) indices into them, drawn as tubes."""

    points: np.ndarray
    edges: np.ndarray

    def __post_init__(self):
        _primitive_points(self)
        object.__setattr__(self, "edges", _indices(self, "edges", 2, len(self.points)).astype(np.int64))


@dataclasses.dataclass(frozen=True, eq=False)
class Points:
    """Points (K, 3), drawn as small spheres."""

    points: np.ndarray

    def __post_init__(self):
        _primitive_points(self)


@dataclasses.dataclass(frozen=True, eq=False)
class ClassedFaces:
    """Triangles (T, 3) over ``points`` (K, 3), each of a class (``classes`` (T,)), drawn as see-through faces with
    tubes along their edges; ``palette`` gives (class code, name, RGB) per class, in priority order: an edge
    between two classes is drawn in the colour of the later one."""

    points: np.ndarray
    triangles: np.ndarray
    classes: np.ndarray
    palette: tuple

    def __post_init__(self):
        _primitive_points(self)
        triangles = _indices(self, "triangles", 3, len(self.points)).astype(np.int64)
        classes = np.asarray(self.classes)
        codes = [code for code, _, _ in self.palette]
        if classes.shape != (len(triangles),) or not np.isin(classes, codes).all() or min(codes, default=0) < 0:
            raise ValueError(f"ClassedFaces: 'classes' of shape {classes.shape} is not one palette code (>= 0) per "
                             f"triangle")
        object.__setattr__(self, "triangles", triangles)
        object.__setattr__(self, "classes", classes.astype(np.int64))


@dataclasses.dataclass(frozen=True, eq=False)
class Labels:
    """Short texts at points: ``points`` (K, 3) and one string per point (``texts``), drawn as text."""

    points: np.ndarray
    texts: tuple

    def __post_init__(self):
        _primitive_points(self)
        texts = tuple(self.texts) if isinstance(self.texts, (list, tuple)) else None
        if texts is None or len(texts) != len(self.points) or not all(isinstance(text, str) for text in texts):
            raise ValueError(f"Labels: 'texts' must be one string per point ({len(self.points)})")
        object.__setattr__(self, "texts", texts)


class Stage:
    """Base of the stage types (frozen dataclasses without value equality: they hold arrays). Class attributes
    declare the overlay: ``label`` for its toggle, ``colour`` (RGB) for its lines or points, ``shown`` whether it
    starts shown."""

    label = ""
    colour = (0.8, 0.8, 0.8)
    shown = True

    def mapped(self, placement):
        """This stage with its coordinates mapped to the world by ``placement``."""
        return self

    def drawing(self):
        """The primitive that draws this stage, or None when it is not drawn."""
        return None

    def to_dict(self):
        """The fields by name (nested stages as dicts), arrays as they are."""
        return {field.name: value.to_dict() if isinstance(value, Stage) else value
                for field in dataclasses.fields(self) for value in [getattr(self, field.name)]}


@dataclasses.dataclass(frozen=True, eq=False)
class Frame(Stage):
    """The view a method looked along: ``direction``, and the plane its planar stages lie on, through ``origin`` +
    ``depth`` times the direction, spanned by ``u`` and ``v`` (2D point (x, y) at origin + depth direction + x u +
    y v); ``axes`` (rows) is the frame the method worked in. Not drawn: the planar stages show its plane."""

    origin: np.ndarray
    u: np.ndarray
    v: np.ndarray
    direction: np.ndarray
    depth: float
    axes: np.ndarray

    label = "View"

    def __post_init__(self):
        _vector(self, "origin")
        for name in ("u", "v", "direction"):
            _vector(self, name, unit=True)
        _finite_number(self, "depth")
        _points(self, "axes", 3, count=3)
        if np.abs(np.asarray(self.axes) @ np.asarray(self.axes).T - np.eye(3)).max() > UNIT_TOLERANCE:
            raise ValueError("Frame: 'axes' are not orthonormal rows")

    def mapped(self, placement):
        return Frame(placement.point(self.origin), placement.vector(self.u), placement.vector(self.v),
                     placement.vector(self.direction), placement.length(self.depth), placement.vector(self.axes))

    def lift(self, points):
        """(K, 2) points of the plane in 3D."""
        base = self.origin + self.depth * self.direction
        return base + points[:, :1] * self.u + points[:, 1:] * self.v

    def lift_used(self, points, indices):
        """The (K, 2) ``points`` that the rows of ``indices`` (into them) use, in 3D, and the rows renumbered to
        index those: what a drawing of a triangulation or a graph keeps."""
        used, compact = np.unique(indices, return_inverse=True)
        return self.lift(np.asarray(points, dtype=np.float64)[used]), compact.reshape(-1, indices.shape[1])


@dataclasses.dataclass(frozen=True, eq=False)
class Outline(Stage):
    """A view's silhouette: closed ``loops`` of (K, 2) points in the ``frame``'s plane, outer ones counter-clockwise,
    holes clockwise."""

    frame: Frame
    loops: list

    label = "Silhouette"
    colour = (1.0, 0.85, 0.1)

    def __post_init__(self):
        _frame(self)
        if not isinstance(self.loops, (list, tuple)):
            raise ValueError(f"{_name(self)}: 'loops' is a {type(self.loops).__name__}, not a list of (K, 2) arrays")
        for index, loop in enumerate(self.loops):
            _check_points(loop, 2, f"{_name(self)}: loop {index}", minimum=3)

    def mapped(self, placement):
        return Outline(self.frame.mapped(placement), [placement.length(loop) for loop in self.loops])

    def drawing(self):
        return _polylines([self.frame.lift(np.asarray(loop, dtype=np.float64)) for loop in self.loops], closed=True)


@dataclasses.dataclass(frozen=True, eq=False)
class Triangulation(Stage):
    """Triangles of a view's outline: ``vertices`` (V, 2) in the ``frame``'s plane, ``triangles`` (T, 3) indices,
    and the class of each (``classes`` (T,): TERMINAL, SLEEVE, JUNCTION or ISOLATED)."""

    frame: Frame
    vertices: np.ndarray
    triangles: np.ndarray
    classes: np.ndarray

    label = "Triangulation"
    palette = ((TERMINAL, "terminal", (0.95, 0.4, 0.05)), (SLEEVE, "sleeve", (0.25, 0.45, 1.0)),
               (JUNCTION, "junction", (0.85, 0.1, 0.75)), (ISOLATED, "isolated", (0.55, 0.55, 0.55)))
    edge_priority = (SLEEVE, ISOLATED, TERMINAL, JUNCTION)  # an edge between classes is drawn in the later one's

    def __post_init__(self):
        _frame(self)
        _points(self, "vertices", 2)
        triangles = _indices(self, "triangles", 3, len(self.vertices))
        classes = np.asarray(self.classes)
        if classes.shape != (len(triangles),) or not np.isin(classes, [code for code, _, _ in self.palette]).all():
            raise ValueError(f"{_name(self)}: 'classes' of shape {classes.shape} is not one of "
                             f"{sorted(code for code, _, _ in self.palette)} per triangle")
        corners = np.sort(triangles, axis=1)
        if (corners[:, 1:] == corners[:, :-1]).any():
            raise ValueError(f"{_name(self)}: a triangle repeats a vertex")

    def mapped(self, placement):
        return Triangulation(self.frame.mapped(placement), placement.length(self.vertices), self.triangles,
                             self.classes)

    def drawing(self):
        if not len(self.triangles):
            return None
        points, triangles = self.frame.lift_used(self.vertices, np.asarray(self.triangles, dtype=np.int64))
        by_code = {code: (code, name, colour) for code, name, colour in self.palette}
        return ClassedFaces(points, triangles, np.asarray(self.classes, dtype=np.int64),
                            tuple(by_code[code] for code in self.edge_priority))


@dataclasses.dataclass(frozen=True, eq=False)
class AxisGraph(Stage):
    """A graph along the middle of a view's outline: ``points`` (n, 2) in the ``frame``'s plane, the half-width of
    the shape at each (``radius`` (n,)), and ``links`` (m, 2) node pairs."""

    frame: Frame
    points: np.ndarray
    radius: np.ndarray
    links: np.ndarray

    label = "Chordal Axis"
    colour = (0.1, 0.8, 1.0)

    def __post_init__(self):
        _frame(self)
        _points(self, "points", 2)
        radius = np.asarray(self.radius)
        if radius.shape != (len(self.points),) or not np.isfinite(radius).all():
            raise ValueError(f"{_name(self)}: 'radius' of shape {radius.shape} is not a finite number per point")
        _indices(self, "links", 2, len(self.points))

    def mapped(self, placement):
        return type(self)(self.frame.mapped(placement), placement.length(self.points), placement.length(self.radius),
                          self.links)

    def drawing(self):
        links = np.asarray(self.links, dtype=np.int64).reshape(-1, 2)
        links = np.unique(np.sort(links, axis=1), axis=0)
        links = links[links[:, 0] != links[:, 1]]
        if not len(links):
            return None
        return Lines(*self.frame.lift_used(self.points, links))


@dataclasses.dataclass(frozen=True, eq=False)
class MergedAxis(AxisGraph):
    """The axis graph after round blobs swallowed the axis inside their discs."""

    label = "Merged Axis"
    colour = (0.1, 0.45, 0.55)
    shown = False


@dataclasses.dataclass(frozen=True, eq=False)
class PrunedBranches(AxisGraph):
    """The axis branches pruning removed (their links)."""

    label = "Pruned Branches"
    colour = (1.0, 0.15, 0.15)


@dataclasses.dataclass(frozen=True, eq=False)
class Chains(Stage):
    """3D polylines (K, 3) with K >= 2 (a method's chains through the mesh, before they became bones)."""

    lines: list

    label = "Chains"
    colour = (0.2, 0.9, 0.3)

    def __post_init__(self):
        if not isinstance(self.lines, (list, tuple)):
            raise ValueError(f"{_name(self)}: 'lines' is a {type(self.lines).__name__}, not a list of (K, 3) arrays")
        for index, line in enumerate(self.lines):
            _check_points(line, 3, f"{_name(self)}: line {index}", minimum=2)

    def mapped(self, placement):
        return Chains([placement.point(line) for line in self.lines])

    def drawing(self):
        return _polylines([np.asarray(line, dtype=np.float64) for line in self.lines], closed=False)


@dataclasses.dataclass(frozen=True, eq=False)
class Joints(Stage):
    """Joint positions (J, 3)."""

    points: np.ndarray

    label = "Joints"
    colour = (0.95, 0.95, 0.95)

    def __post_init__(self):
        _points(self, "points", 3)

    def mapped(self, placement):
        return Joints(placement.point(self.points))

    def drawing(self):
        return Points(np.asarray(self.points, dtype=np.float64)) if len(self.points) else None


@dataclasses.dataclass(frozen=True, eq=False)
class MirrorPlane(Stage):
    """The plane a mesh is mirror-symmetric about, and its bones' twins mirror across: perpendicular to axis ``axis``
    (0, 1 or 2) of the frame the method worked in, whose world direction is ``normal``, at ``offset`` along it.
    ``exact``: the mesh is a mirror image about it; else it only roughly is (a hand-made or posed body), and the plane
    lies where it mirrors best. Not drawn."""

    axis: int
    offset: float
    normal: np.ndarray
    exact: bool = True

    label = "Mirror Plane"

    def __post_init__(self):
        if not isinstance(self.axis, numbers.Integral) or isinstance(self.axis, bool) or self.axis not in (0, 1, 2):
            raise ValueError(f"{_name(self)}: 'axis' is {self.axis!r}, not 0, 1 or 2")
        _finite_number(self, "offset")
        _vector(self, "normal", unit=True)

    def mapped(self, placement):
        return MirrorPlane(self.axis, placement.length(self.offset), placement.vector(self.normal), self.exact)

    def reflect(self, points):
        """World ``points`` (..., 3) reflected across the plane."""
        points = np.asarray(points, dtype=np.float64)
        return points - 2 * ((points @ self.normal) - self.offset)[..., None] * self.normal


def _name(stage):
    return type(stage).__name__


def _polylines(lines, closed):
    """``Lines`` along the (K, 3) polylines ``lines``, each ``closed`` into a loop or not; None for none."""
    if not lines:
        return None
    edges, offset = [], 0
    for line in lines:
        step = np.arange(len(line) if closed else len(line) - 1)
        edges.append(offset + np.stack([step, (step + 1) % len(line)], axis=1))
        offset += len(line)
    return Lines(np.concatenate(lines), np.concatenate(edges))


def _primitive_points(drawing):
    """A drawing's ``points`` as a finite (K, 3) float64 array, K > 0."""
    _points(drawing, "points", 3)
    object.__setattr__(drawing, "points", np.asarray(drawing.points, dtype=np.float64).reshape(-1, 3))
    if not len(drawing.points):
        raise ValueError(f"{_name(drawing)}: no points to draw")


def _frame(stage):
    if not isinstance(stage.frame, Frame):
        raise ValueError(f"{_name(stage)}: 'frame' is a {type(stage.frame).__name__}, not a Frame")


def _check_points(value, width, what, *, minimum=0):
    """``value`` must be a finite (K, width) array of numbers with K >= minimum."""
    try:
        array = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise ValueError(f"{what} is not a regular array of numbers") from None
    empty = array.shape in ((0,), (0, width)) and minimum == 0
    if not empty and (array.ndim != 2 or array.shape[1] != width or len(array) < minimum):
        raise ValueError(f"{what} has shape {array.shape}, not (K, {width}) with K >= {minimum}")
    if not np.isfinite(array).all():
        raise ValueError(f"{what} has non-finite values")


def _points(stage, name, width, count=None):
    _check_points(getattr(stage, name), width, f"{_name(stage)}: {name!r}")
    if count is not None and len(getattr(stage, name)) != count:
        raise ValueError(f"{_name(stage)}: {name!r} needs {count} rows, not {len(getattr(stage, name))}")


def _vector(stage, name, unit=False):
    array = np.asarray(getattr(stage, name))
    if array.shape != (3,) or array.dtype.kind not in "iuf" or not np.isfinite(array).all():
        raise ValueError(f"{_name(stage)}: {name!r} is not a finite 3D vector")
    if unit and abs(np.linalg.norm(array) - 1) > UNIT_TOLERANCE:
        raise ValueError(f"{_name(stage)}: {name!r} is not a unit vector")


def _finite_number(stage, name):
    value = getattr(stage, name)
    if not (isinstance(value, numbers.Real) and not isinstance(value, bool) and math.isfinite(value)):
        raise ValueError(f"{_name(stage)}: {name!r} is {value!r}, not a finite number")


def _indices(stage, name, width, count):
    """The (K, width) integer array ``name`` of ``stage``, each index below ``count``."""
    array = np.asarray(getattr(stage, name))
    if array.shape in ((0,), (0, width)):
        return array.reshape(0, width)
    if array.ndim != 2 or array.shape[1] != width or array.dtype.kind not in "iu":
        raise ValueError(f"{_name(stage)}: {name!r} of shape {array.shape} and type {array.dtype} is not (K, {width}) "
                         f"integers")
    if array.min() < 0 or array.max() >= count:
        raise ValueError(f"{_name(stage)}: {name!r} indexes outside 0..{count - 1}")
    return array
