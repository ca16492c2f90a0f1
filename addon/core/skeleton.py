"""The skeleton a method returns: a validated tree of bones plus the intermediate results that produced it."""
import numpy as np

from .roles import BoneRole
from .stages import Stage


class Skeleton:
    """A tree of B bones, each running from a head point to a tail point.

    Attributes:
        names: tuple of B unique, non-empty bone names.
        heads, tails: (B, 3) float64, read-only; every head differs from its tail.
        parents: (B,) int32, read-only; ``parents[i]`` is the index of bone i's parent (any other bone) or -1 for
            a root. The parent links form a forest: at least one root and no cycles.
        stages: the method's intermediate results by name (``rigger.core.stages`` types: outline, triangulation,
            chordal axis, chains, joints, ...), in world coordinates. Overlays, reports and tests read them; treat
            them as read-only.
        timings: seconds per step of the method; :func:`rigger.rig_mesh` adds ``"total"``.
        params: the parameter values the method ran with (:func:`rigger.rig_mesh` fills them in).
        body_plan: the recognised ``rigger.core.bodyplan.BodyPlan`` (kind, confidence, reason), or None before
            recognition (:func:`rigger.rig_mesh` fills it in).
        roles: one ``rigger.core.roles.BoneRole`` (role, side, index, digit) per bone, or None before recognition.
    """

    def __init__(self, names, heads, tails, parents, stages=None, timings=None, params=None, roles=None,
                 body_plan=None):
        self.names = _validated_names(names)
        count = len(self.names)
        self.heads = _validated_points(heads, count, "heads")
        self.tails = _validated_points(tails, count, "tails")
        zero_length = np.flatnonzero((self.heads == self.tails).all(axis=1))
        if zero_length.size:
            raise ValueError(f"bone {self.names[zero_length[0]]!r} has zero length (its head equals its tail)")
        self.parents = _validated_parents(parents, self.names)
        self.stages = _validated_stages({} if stages is None else stages)
        self.timings = {} if timings is None else dict(timings)
        self.params = {} if params is None else dict(params)
        self.roles = roles
        self.body_plan = body_plan

    @property
    def roles(self):
        """One ``BoneRole`` per bone, or None before the body plan was recognised."""
        return self._roles

    @roles.setter
    def roles(self, roles):
        if roles is not None:
            roles = tuple(roles)
            if len(roles) != len(self) or not all(isinstance(role, BoneRole) for role in roles):
                raise ValueError(f"roles must be one rigger.core.roles.BoneRole per bone ({len(self)})")
        self._roles = roles

    @property
    def body_plan(self):
        """The recognised ``BodyPlan``, or None before recognition."""
        return self._body_plan

    @body_plan.setter
    def body_plan(self, plan):
        from .bodyplan import BodyPlan

        if plan is not None and not isinstance(plan, BodyPlan):
            raise ValueError(f"body_plan must be a rigger.core.bodyplan.BodyPlan, got {type(plan).__name__}")
        self._body_plan = plan

    def __len__(self):
        return len(self.names)

    def __repr__(self):
        return f"Skeleton({len(self)} bones, roots {[self.names[i] for i in self.roots]})"

    @property
    def extent(self):
        """The largest extent of the box around the bones' ends."""
        return float(np.ptp(np.concatenate([self.heads, self.tails]), axis=0).max())

    @property
    def roots(self):
        """Indices of the bones without a parent, in index order."""
        return tuple(int(i) for i in np.flatnonzero(self.parents == -1))

    def children(self, index):
        """Indices of the bones whose parent is bone ``index``, in index order."""
        return tuple(int(i) for i in np.flatnonzero(self.parents == index))

    def joints(self):
        """(J, 3) float64: the RigNet joint set, every bone head plus the tail of every leaf bone, coincident points
        once (in first-seen order)."""
        is_leaf = np.ones(len(self), dtype=bool)
        is_leaf[self.parents[self.parents >= 0]] = False
        points = np.concatenate([self.heads, self.tails[is_leaf]])
        _, first = np.unique(points, axis=0, return_index=True)
        return points[np.sort(first)]

    def transformed(self, matrix):
        """A copy with heads and tails mapped by the affine 4x4 ``matrix`` (e.g. world to armature-local frame).

        ``stages``, ``timings``, ``params``, ``roles`` and ``body_plan`` are shared by reference: the stages and the
        plan's up stay in the world's frame.
        """
        matrix = np.asarray(matrix, dtype=np.float64)
        if matrix.shape != (4, 4) or not np.isfinite(matrix).all():
            raise ValueError(f"transform must be a finite 4x4 matrix, got shape {matrix.shape}")
        if not np.array_equal(matrix[3], [0, 0, 0, 1]):
            raise ValueError("transform must be affine (last row 0, 0, 0, 1)")
        if np.linalg.det(matrix[:3, :3]) == 0:
            raise ValueError("transform is singular")
        linear, offset = matrix[:3, :3], matrix[:3, 3]
        moved = Skeleton(self.names, self.heads @ linear.T + offset, self.tails @ linear.T + offset, self.parents,
                         self.stages, roles=self.roles, body_plan=self.body_plan)
        moved.timings, moved.params = self.timings, self.params
        return moved

    def to_dict(self):
        """``{"bones": [{"name", "head", "tail", "parent"}, ...]}`` with plain floats and the parent's name (None
        for a root): ready for JSON. With roles, each bone also has its ``role``, ``side``, ``role_index`` and
        ``digit``; stages are not included."""
        bones = [
            {
                "name": name,
                "head": head,
                "tail": tail,
                "parent": None if parent < 0 else self.names[parent],
            }
            for name, head, tail, parent in zip(self.names, self.heads.tolist(), self.tails.tolist(),
                                                self.parents.tolist())
        ]
        for bone, role in zip(bones, self.roles or ()):
            bone.update(role=role.role, side=role.side, role_index=role.index, digit=role.digit)
        return {"bones": bones}

    @classmethod
    def from_dict(cls, data, stages=None):
        """The inverse of :meth:`to_dict`; parents may be listed before or after their children."""
        try:
            bones = data["bones"]
            names = [bone["name"] for bone in bones]
            heads = [bone["head"] for bone in bones]
            tails = [bone["tail"] for bone in bones]
            parent_names = [bone["parent"] for bone in bones]
        except (KeyError, TypeError) as error:
            raise ValueError(f"a skeleton dict needs 'bones', each with name, head, tail and parent ({error!r})") \
                from None
        index = {name: i for i, name in enumerate(names) if isinstance(name, str)}
        unknown = [name for name in parent_names if name is not None and name not in index]
        if unknown:
            raise ValueError(f"parent {unknown[0]!r} is not a bone of this skeleton")
        parents = [-1 if name is None else index[name] for name in parent_names]
        return cls(names, heads, tails, parents, stages)


def _validated_stages(stages):
    if not isinstance(stages, dict):
        raise ValueError(f"stages must be a dict of stage name to stage, got {type(stages).__name__}")
    for name, stage in stages.items():
        if not isinstance(name, str) or not name:
            raise ValueError(f"stage names must be non-empty strings, got {name!r}")
        if not isinstance(stage, Stage):
            raise ValueError(f"stage {name!r} is a {type(stage).__name__}, not a rigger.core.stages.Stage")
    return stages


def _validated_names(names):
    if isinstance(names, str):
        raise ValueError("names must be a sequence of strings, not one string")
    names = tuple(names)
    if not names:
        raise ValueError("a skeleton needs at least one bone")
    for name in names:
        if not isinstance(name, str) or not name:
            raise ValueError(f"bone names must be non-empty strings, got {name!r}")
    seen = set()
    for name in names:
        if name in seen:
            raise ValueError(f"bone name {name!r} is used twice")
        seen.add(name)
    return names


def _validated_points(values, count, what):
    try:
        array = np.array(values, dtype=np.float64)
    except (TypeError, ValueError) as error:
        raise ValueError(f"{what} must be a ({count}, 3) array of numbers ({error})") from None
    if array.shape != (count, 3):
        raise ValueError(f"{what} must have shape ({count}, 3) for {count} bones, got {array.shape}")
    if not np.isfinite(array).all():
        raise ValueError(f"{what} contain NaN or infinite coordinates")
    array.setflags(write=False)
    return array


def _validated_parents(values, names):
    count = len(names)
    array = np.asarray(values)
    if array.shape != (count,) or array.dtype.kind not in "iu":
        raise ValueError(f"parents must be {count} integer bone indices, got {array.dtype} array of shape "
                         f"{array.shape}")
    if array.min() < -1 or array.max() >= count:
        raise ValueError(f"parent indices must be -1 (root) or between 0 and {count - 1}")
    parents = array.astype(np.int32)
    _reject_cycles(parents.tolist(), names)
    parents.setflags(write=False)
    return parents


def _reject_cycles(parents, names):
    """Follow each bone's parent chain once; meeting the chain being walked again is a cycle."""
    unvisited, on_path, done = 0, 1, 2
    state = [unvisited] * len(parents)
    for start in range(len(parents)):
        path = []
        bone = start
        while bone != -1 and state[bone] == unvisited:
            state[bone] = on_path
            path.append(bone)
            bone = parents[bone]
        if bone != -1 and state[bone] == on_path:
            cycle = path[path.index(bone):]
            raise ValueError(f"bone parents form a cycle: {' -> '.join(names[i] for i in cycle)}")
        for visited in path:
            state[visited] = done
