"""Ground-truth rigs and how skeletons are scored against them (the RigNet convention of ../shared/README.md).

Bench-only: reads OBJ meshes and RigNet ``rig_info`` files, normalises everything so the mesh's largest bounding-box
extent is 1, and measures CD-J2J, CD-J2B, CD-B2B and the fraction of bone samples inside the mesh. For skinning, it
also reads the weights of a Blender mesh object's vertex groups (without importing bpy: the object is passed in).
"""
import re
from dataclasses import dataclass

import numpy as np
from scipy.sparse import csr_matrix
from scipy.spatial import cKDTree

from rigger.core.arrays import concatenated_ranges
from rigger.core.mesh import fan_triangles

HELPER_JOINT = re.compile(r"PoleTarget|^Dummy_|_rootJoint$")
BONE_SAMPLE_STEP = 0.005
# Point-triangle pairs per winding-number chunk: bounds memory to a few (chunk, 3) float arrays of ~24 MB each.
WINDING_CHUNK_PAIRS = 1_000_000


def load_obj(path):
    """Vertices (N, 3) float64 and triangles (M, 3) int64 of an OBJ file; polygons are fan-triangulated.

    Reads only ``v`` and ``f`` lines. Face corners may be ``a``, ``a/b``, ``a//c`` or ``a/b/c``; indices are 1-based,
    negative ones count back from the last vertex defined before the face, as the OBJ format says.
    """
    vertex_rows, corner_tokens, face_sizes, vertices_before_face = [], [], [], []
    with open(path, encoding="utf-8", errors="replace") as lines:
        for line_number, line in enumerate(lines, 1):
            fields = line.split()
            if not fields:
                continue
            if fields[0] == "v":
                if len(fields) < 4:
                    raise ValueError(f"{path}:{line_number}: a vertex needs 3 coordinates, got {line.strip()!r}")
                vertex_rows.append(fields[1:4])
            elif fields[0] == "f":
                if len(fields) < 4:
                    raise ValueError(f"{path}:{line_number}: a face needs at least 3 corners, got {line.strip()!r}")
                corner_tokens.extend(corner.split("/", 1)[0] for corner in fields[1:])
                face_sizes.append(len(fields) - 1)
                vertices_before_face.append(len(vertex_rows))
    if not vertex_rows or not face_sizes:
        raise ValueError(f"{path}: no vertices or no faces")
    try:
        vertices = np.array(vertex_rows, dtype=np.float64)
        raw_indices = np.array(corner_tokens, dtype=np.int64)
    except ValueError as error:
        raise ValueError(f"{path}: unreadable number ({error})") from None
    if not np.isfinite(vertices).all():
        raise ValueError(f"{path}: non-finite vertex coordinates")
    face_sizes = np.array(face_sizes, dtype=np.int64)
    known_vertices = np.repeat(np.array(vertices_before_face, dtype=np.int64), face_sizes)
    if (raw_indices == 0).any():
        raise ValueError(f"{path}: face index 0 (OBJ indices start at 1)")
    indices = np.where(raw_indices < 0, raw_indices + known_vertices, raw_indices - 1)
    if (indices < 0).any() or (indices >= len(vertices)).any():
        raise ValueError(f"{path}: face index out of range (the file defines {len(vertices)} vertices)")
    return vertices, fan_triangles(indices, face_sizes)


@dataclass(frozen=True)
class Bones:
    """A skeleton as bones: ``heads`` and ``tails`` (B, 3), ``parents`` (B,) with -1 for a root bone."""

    heads: np.ndarray
    tails: np.ndarray
    parents: np.ndarray

    def __post_init__(self):
        heads, tails = np.asarray(self.heads, np.float64), np.asarray(self.tails, np.float64)
        parents = np.asarray(self.parents, np.int64)
        if heads.ndim != 2 or heads.shape[1:] != (3,) or tails.shape != heads.shape or parents.shape != heads[:, 0].shape:
            raise ValueError(f"bones need heads (B, 3), tails (B, 3), parents (B,); got {heads.shape}, "
                             f"{tails.shape}, {parents.shape}")
        object.__setattr__(self, "heads", heads)
        object.__setattr__(self, "tails", tails)
        object.__setattr__(self, "parents", parents)

    @classmethod
    def of(cls, skeleton):
        """The bones of any object with ``heads``, ``tails`` and ``parents`` (e.g. a ``rigger.Skeleton``)."""
        return cls(skeleton.heads, skeleton.tails, skeleton.parents)

    def __len__(self):
        return len(self.heads)

    def joints(self):
        """The joint set scored by CD-J2J: bone heads plus the tails of leaf bones, each position once."""
        has_child = np.zeros(len(self), dtype=bool)
        has_child[self.parents[self.parents >= 0]] = True
        return np.unique(np.concatenate([self.heads, self.tails[~has_child]]), axis=0)

    def total_length(self):
        """The summed length of the bones."""
        return float(np.linalg.norm(self.tails - self.heads, axis=1).sum())

    def samples(self, step=BONE_SAMPLE_STEP):
        """Points every ``step`` (or closer) along each bone, both ends included; (S, 3)."""
        lengths = np.linalg.norm(self.tails - self.heads, axis=1)
        segments = np.maximum(np.ceil(lengths / step).astype(np.int64), 1)
        bone_of_sample = np.repeat(np.arange(len(self)), segments + 1)
        fraction = concatenated_ranges(np.zeros_like(segments), segments + 1) / segments[bone_of_sample]
        heads = self.heads[bone_of_sample]
        return heads + fraction[:, None] * (self.tails[bone_of_sample] - heads)

    def mapped(self, normalisation):
        """The same bones in a normalised frame."""
        return Bones(normalisation.points(self.heads), normalisation.points(self.tails), self.parents)


@dataclass(frozen=True)
class Rig:
    """An artist rig: joint ``names``, ``positions`` (J, 3), ``parents`` (J,) (-1 for a root), ``root`` name, and
    ``skin``: a sparse (vertices, J) matrix of skin weights."""

    names: tuple
    positions: np.ndarray
    parents: np.ndarray
    root: str
    skin: csr_matrix

    def bones(self):
        """One bone per parent→child joint pair, parented like the joints."""
        children = np.flatnonzero(self.parents >= 0)
        bone_of_joint = np.full(len(self.names), -1)
        bone_of_joint[children] = np.arange(len(children))
        return Bones(self.positions[self.parents[children]], self.positions[children],
                     bone_of_joint[self.parents[children]])

    def without_helpers(self, pattern=HELPER_JOINT):
        """The rig without non-deforming helper joints; children of a dropped joint go to its nearest kept ancestor."""
        keep = np.array([not pattern.search(name) for name in self.names], dtype=bool)
        parents = kept_ancestors(self.parents, keep)
        names = tuple(name for name, kept in zip(self.names, keep) if kept)
        root = self.root if self.root in names else next(
            (name for name, parent in zip(names, parents) if parent < 0), None)
        return Rig(names, self.positions[keep], parents, root, self.skin[:, keep])

    def attached(self):
        """The rig as one tree: the root of every part not under ``root`` (Quaternius rigs keep their IK-driven feet
        as separate roots) becomes a child of the nearest joint under ``root``, which carries it as the IK chain
        would when the rig is posed."""
        parents = self.parents.copy()
        top = np.arange(len(parents))
        for _ in range(len(parents)):
            top = np.where(parents[top] >= 0, parents[top], top)
        main = np.flatnonzero(top == self.names.index(self.root))
        for part_root in np.flatnonzero(parents < 0):
            if part_root != self.names.index(self.root):
                distances = np.linalg.norm(self.positions[main] - self.positions[part_root], axis=1)
                parents[part_root] = main[np.argmin(distances)]
        return Rig(self.names, self.positions, parents, self.root, self.skin)


def kept_ancestors(parents, keep):
    """Parent indices among the kept nodes only: each kept node's nearest kept ancestor (-1 when none)."""
    new_index = np.full(len(keep), -1)
    new_index[keep] = np.arange(np.count_nonzero(keep))
    result = []
    for node in np.flatnonzero(keep):
        ancestor = parents[node]
        while ancestor >= 0 and not keep[ancestor]:
            ancestor = parents[ancestor]
        result.append(new_index[ancestor] if ancestor >= 0 else -1)
    return np.array(result, dtype=np.int64)


def load_rig(path, n_vertices=None):
    """The rig in a RigNet ``rig_info`` file (``joints``/``root``/``hier``/``skin`` lines).

    ``n_vertices`` sets the skin matrix's row count (default: the highest skinned vertex + 1).
    """
    names, positions, hierarchy, skin_rows, root = [], [], [], [], None
    with open(path, encoding="utf-8", errors="replace") as lines:
        for line_number, line in enumerate(lines, 1):
            fields = line.split()
            if not fields or fields[0].startswith("#"):
                continue
            where = f"{path}:{line_number}"
            keyword = fields[0]
            try:
                if keyword == "joints" and len(fields) == 5:
                    names.append(fields[1])
                    positions.append([float(value) for value in fields[2:5]])
                elif keyword == "root" and len(fields) == 2:
                    root = fields[1]
                elif keyword == "hier" and len(fields) == 3:
                    hierarchy.append((fields[1], fields[2], where))
                elif keyword == "skin" and len(fields) >= 2 and len(fields) % 2 == 0:
                    skin_rows.append((int(fields[1]), fields[2::2], [float(w) for w in fields[3::2]], where))
                else:
                    raise ValueError(f"{where}: unrecognised line {line.strip()[:80]!r}")
            except ValueError as error:
                if str(error).startswith(where):
                    raise
                raise ValueError(f"{where}: unreadable number in {line.strip()[:80]!r}") from None
    if not names:
        raise ValueError(f"{path}: no joints")
    index = {name: i for i, name in enumerate(names)}
    if len(index) != len(names):
        raise ValueError(f"{path}: a joint name appears twice")
    if root is not None and root not in index:
        raise ValueError(f"{path}: root {root!r} is not a joint")

    def joint_index(name, where):
        if name not in index:
            raise ValueError(f"{where}: unknown joint {name!r}")
        return index[name]

    parents = np.full(len(names), -1, dtype=np.int64)
    for parent, child, where in hierarchy:
        child_index = joint_index(child, where)
        if parents[child_index] >= 0:
            raise ValueError(f"{where}: joint {child!r} has two parents")
        parents[child_index] = joint_index(parent, where)
    _check_acyclic(parents, path)

    rows, columns, weights = [], [], []
    for vertex, joint_names, joint_weights, where in skin_rows:
        if vertex < 0:
            raise ValueError(f"{where}: negative vertex index")
        rows.extend([vertex] * len(joint_names))
        columns.extend(joint_index(name, where) for name in joint_names)
        weights.extend(joint_weights)
    height = n_vertices if n_vertices is not None else (max(rows) + 1 if rows else 0)
    if rows and max(rows) >= height:
        raise ValueError(f"{path}: skin names vertex {max(rows)} but the mesh has {height}")
    skin = csr_matrix((weights, (rows, columns)), shape=(height, len(names)))
    if root is None:
        root = names[int(np.flatnonzero(parents < 0)[0])]
    return Rig(tuple(names), np.array(positions, dtype=np.float64), parents, root, skin)


def load_ground_truth(folder):
    """Vertices, triangles and artist rig (helper joints dropped) of the ground-truth model in ``folder`` (a
    ``pathlib.Path``): ``NAME/NAME.obj`` and ``NAME/NAME_rig.txt``, the skin sized to the mesh."""
    vertices, triangles = load_obj(folder / f"{folder.name}.obj")
    rig = load_rig(folder / f"{folder.name}_rig.txt", len(vertices)).without_helpers()
    return vertices, triangles, rig


def _check_acyclic(parents, source):
    for start in range(len(parents)):
        joint = start
        for _ in range(len(parents)):
            joint = parents[joint]
            if joint < 0:
                break
        else:
            raise ValueError(f"{source}: the joint hierarchy has a cycle")


def tree_problem(bones):
    """Why ``bones`` is not a valid single-rooted tree with finite coordinates, or None when it is."""
    if len(bones) == 0:
        return "no bones"
    if not (np.isfinite(bones.heads).all() and np.isfinite(bones.tails).all()):
        return "non-finite bone coordinates"
    parents = bones.parents
    if ((parents < -1) | (parents >= len(bones))).any():
        return "parent index out of range"
    roots = int((parents == -1).sum())
    if roots != 1:
        return f"{roots} root bones (a tree has exactly one)"
    reached = parents == -1
    for _ in range(len(bones)):
        newly = ~reached & reached[np.maximum(parents, 0)]
        if not newly.any():
            break
        reached |= newly
    if not reached.all():
        return "the parent links contain a cycle"
    return None


@dataclass(frozen=True)
class Normalisation:
    """RigNet's frame: translate the mesh's bounding-box centre to the origin and scale its largest extent to 1."""

    centre: np.ndarray
    scale: float

    @classmethod
    def of_mesh(cls, vertices):
        low, high = vertices.min(axis=0), vertices.max(axis=0)
        extent = float((high - low).max())
        if not extent > 0:
            raise ValueError("the mesh has no extent to normalise by")
        return cls((low + high) / 2, 1.0 / extent)

    def points(self, points):
        return (np.asarray(points, dtype=np.float64) - self.centre) * self.scale


def one_way_distance(source, target):
    """Mean over ``source`` points of the distance to the nearest ``target`` point."""
    if len(source) == 0 or len(target) == 0:
        raise ValueError("distance between point sets needs both non-empty")
    return float(cKDTree(target).query(source)[0].mean())


def chamfer_distance(points_a, points_b):
    """Symmetric Chamfer distance: the two one-way mean nearest distances, averaged."""
    return (one_way_distance(points_a, points_b) + one_way_distance(points_b, points_a)) / 2


def skeleton_distances(predicted_joints, predicted_samples, true_joints, true_samples):
    """CD-J2J, CD-J2B and CD-B2B between two skeletons given as joint sets and bone samplings (same frame)."""
    return {
        "cd_j2j": chamfer_distance(predicted_joints, true_joints),
        "cd_j2b": (one_way_distance(predicted_joints, true_samples)
                   + one_way_distance(true_joints, predicted_samples)) / 2,
        "cd_b2b": chamfer_distance(predicted_samples, true_samples),
    }


def winding_numbers(points, vertices, triangles, chunk_pairs=WINDING_CHUNK_PAIRS):
    """Generalised winding number of each point w.r.t. the triangle soup: the summed signed solid angles / 4π.

    About 1 inside a closed, outward-oriented mesh, 0 outside, fractional near holes of open meshes.
    """
    points = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    corners = [vertices[triangles[:, k]] for k in range(3)]
    rows = max(1, chunk_pairs // max(len(triangles), 1))
    result = np.empty(len(points))
    for start in range(0, len(points), rows):
        origin = points[start:start + rows, None, :]
        a, b, c = (corner[None, :, :] - origin for corner in corners)
        length_a, length_b, length_c = (np.sqrt(np.einsum("ijk,ijk->ij", v, v)) for v in (a, b, c))
        volume = np.einsum("ijk,ijk->ij", a, np.cross(b, c))
        denominator = (length_a * length_b * length_c + np.einsum("ijk,ijk->ij", a, b) * length_c
                       + np.einsum("ijk,ijk->ij", b, c) * length_a + np.einsum("ijk,ijk->ij", c, a) * length_b)
        result[start:start + rows] = np.arctan2(volume, denominator).sum(axis=1) / (2 * np.pi)
    return result


def inside_fraction(points, vertices, triangles):
    """Fraction of points inside the mesh: |winding number| ≥ 0.5, so open meshes and parts whose faces are
    oriented inward still count."""
    return float((np.abs(winding_numbers(points, vertices, triangles)) >= 0.5).mean())


# --- skinning: the artist rig as an armature's bones, and which bone each artist weight belongs to ----------------

MIN_BONE_LENGTH = 1e-5  # Blender deletes bones shorter than 1e-6 when leaving edit mode; keep clear of that


def armature_skeleton(rig):
    """The rig's bones as a ``rigger.Skeleton`` to build an armature from, and each bone's head joint (B,) int.

    One bone per parent→child joint pair, as :meth:`Rig.bones`, named ``bone_000``, ``bone_001``... (joint names can
    outgrow Blender's 63-byte bone names). Bones shorter than ``MIN_BONE_LENGTH`` (RigNet's ``root_dup_*`` joints
    repeat the root's position) are dropped and their children re-parented to the nearest kept ancestor.
    """
    from rigger.core.skeleton import Skeleton

    bones = rig.bones()
    children = np.flatnonzero(rig.parents >= 0)
    keep = np.linalg.norm(bones.tails - bones.heads, axis=1) >= MIN_BONE_LENGTH
    parents = kept_ancestors(bones.parents, keep).astype(np.int32)
    names = [f"bone_{index:03d}" for index in range(np.count_nonzero(keep))]
    return Skeleton(names, bones.heads[keep], bones.tails[keep], parents), rig.parents[children][keep]


def weight_owners(parents):
    """For each joint, the joint whose bone its skin weight moves: itself when a bone starts there (it has children
    or is a root), otherwise its parent, the head of the bone that ends at it."""
    parents = np.asarray(parents)
    starts_a_bone = parents < 0
    starts_a_bone[parents[parents >= 0]] = True
    return np.where(starts_a_bone, np.arange(len(parents)), parents)


def dominant_joints(rig):
    """(V,) the owner joint (see :func:`weight_owners`) of each vertex's largest artist weight, -1 where it has
    none."""
    skin = rig.skin.tocsr()
    top = np.asarray(skin.argmax(axis=1)).ravel()
    weighted = np.asarray(skin.max(axis=1).todense()).ravel() > 0
    return np.where(weighted, weight_owners(rig.parents)[top], -1)


def skinned_mesh(name, vertices, triangles, skeleton, target="plain"):
    """Blender mesh object ``name`` of ``vertices`` and ``triangles`` (as they are: UV-seam duplicates stay), alone
    in a fresh scene with the armature output target ``target`` builds of ``skeleton`` (``plain``: its bones as they
    are; ``game``: the game skeleton), skinned by ``rigger.blender.skinning.skin`` and finished as the add-on
    finishes that target: (the mesh object, the skinning report, the armature's bones as a skeleton: the game's
    root among them, which deforms nothing).
    Imports bpy."""
    import bpy
    from rigger.blender import targets
    from rigger.blender.headless import empty_scene
    from rigger.blender.skinning import skin
    from rigger.core.targets import TARGETS

    empty_scene()
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata(np.asarray(vertices).tolist(), [], np.asarray(triangles).tolist())
    obj = bpy.data.objects.new(name, mesh)
    bpy.context.scene.collection.objects.link(obj)
    built = targets.build(TARGETS[target], skeleton, f"{name}_rig", bpy.context.scene.collection, None,
                          (np.asarray(vertices, dtype=np.float64), np.asarray(triangles)))
    report = skin(obj, built.armature)
    targets.skinned(target, obj, built.armature, report)
    return obj, report, built.bones


def vertex_group_weights(obj, names):
    """(vertex index, index into ``names``, weight) of every weight Blender mesh object ``obj`` holds in the vertex
    groups ``names``, vertex by vertex and, within a vertex, in Blender's own order."""
    column = {group.index: names.index(group.name) for group in obj.vertex_groups if group.name in names}
    for vertex in obj.data.vertices:
        for element in vertex.groups:
            if element.group in column:
                yield vertex.index, column[element.group], element.weight


def vertex_weights(obj, names):
    """(N, len(names)) weights of mesh object ``obj``'s vertices in the vertex groups ``names``, in that order (0
    where a group is missing)."""
    table = np.zeros((len(obj.data.vertices), len(names)))
    for vertex, column, weight in vertex_group_weights(obj, names):
        table[vertex, column] = weight
    return table
