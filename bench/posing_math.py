"""The posing benchmark's maths, free of bpy: skinned rigs, random poses, linear blend skinning, fitting a rig to a
deformed mesh, and the measures of a rig that poses (vertex and face-normal error, seam cracks, limb recall, mirror
twins, unsided bones).

A rig here is what deformation needs: bone heads, parents and per-vertex skin weights. A pose gives every bone a
world transform ``x -> R x + t``; a bone rotates about its own head and is carried by its parent, a root bone may
also move (as a root bone can in Blender). Tails do not move anything: a child's head is carried by its parent.
"""
import re
from dataclasses import dataclass

import numpy as np
from scipy.sparse import csr_matrix
from scipy.spatial import cKDTree
from scipy.spatial.transform import Rotation

import rigdata
from rigger.core.polyline import segment_distances

STEPS = 30  # at most this many Levenberg-Marquardt steps in a fit
CONVERGED = 1e-4  # a fit stops when a step lowers its squared error by less than this fraction,
ACCURATE = 1e-7  # or when its root-mean-square vertex error is below this fraction of the mesh's size
COINCIDENT = 1e-5  # fraction of the size under which two rest vertices share a position (UV-seam duplicates)
CHAIN_STEP = 0.005  # spacing of the points along an artist chain, as a fraction of the size
FOLLOWS = 0.03  # a chain is followed when its points lie this close (fraction of size) to a path on average
MIRROR_SYMMETRIC = 0.01  # a body is two-sided when its mirror image lies this close to it (median, fraction of size)
PLANE_SEARCH = 0.05  # the mirror plane's offset is searched this far (fraction of size) either side of the box's centre
PLANE_STEP = 0.001  # ... in steps of this
PLANE_PROBES = 3000  # ... with about this many of the vertices
OFF_PLANE = 0.03  # a bone lies off the mid-plane when its midpoint is farther than this (fraction of size)
SIDE = re.compile(r"^(.*)\.([LR])$")  # Rigger's side suffix: ``limb01.02.L`` / ``limb01.02.R``


@dataclass(frozen=True)
class SkinnedRig:
    """Bone ``heads`` (B, 3) and ``parents`` (B,) (-1 for a root) with skin weights as padded per-vertex lists:
    ``bones`` (V, m) int and ``weights`` (V, m) float, unused slots with weight 0."""

    heads: np.ndarray
    parents: np.ndarray
    bones: np.ndarray
    weights: np.ndarray

    @classmethod
    def of(cls, heads, parents, weights):
        """A rig from a (V, B) weight matrix (dense or sparse); each vertex's weights are normalised to sum to 1.
        ValueError when a vertex has no weight."""
        matrix = csr_matrix(weights)
        matrix.eliminate_zeros()
        counts = np.diff(matrix.indptr)
        if (counts == 0).any():
            raise ValueError(f"{int((counts == 0).sum())} vertices have no skin weight")
        width = int(counts.max())
        rows = np.repeat(np.arange(matrix.shape[0]), counts)
        slots = np.arange(len(rows)) - matrix.indptr[rows]
        bones = np.zeros((matrix.shape[0], width), dtype=np.int64)
        values = np.zeros((matrix.shape[0], width))
        bones[rows, slots] = matrix.indices
        values[rows, slots] = matrix.data
        values /= values.sum(axis=1, keepdims=True)
        return cls(np.asarray(heads, np.float64), np.asarray(parents, np.int64), bones, values)

    def __len__(self):
        return len(self.heads)

    def order(self):
        """Bone indices with every parent before its children."""
        return topological_order(self.parents)

    def subtrees(self):
        """(B, B) boolean: ``[b, k]`` when bone k is bone b or one of its descendants."""
        inside = np.eye(len(self), dtype=bool)
        for bone in self.order()[::-1]:
            if self.parents[bone] >= 0:
                inside[self.parents[bone]] |= inside[bone]
        return inside

    def dominant(self):
        """(V,) each vertex's bone of largest weight and (V,) that weight."""
        slot = self.weights.argmax(axis=1)
        rows = np.arange(len(slot))
        return self.bones[rows, slot], self.weights[rows, slot]


def topological_order(parents):
    """Indices of a forest's nodes, every parent before its children (ValueError on a cycle)."""
    parents = np.asarray(parents)
    depth = np.zeros(len(parents), dtype=np.int64)
    for node in range(len(parents)):
        ancestor, steps = parents[node], 0
        while ancestor >= 0:
            steps += 1
            if steps > len(parents):
                raise ValueError("the parent links contain a cycle")
            ancestor = parents[ancestor]
        depth[node] = steps
    return np.argsort(depth, kind="stable")


def artist_rig(rig):
    """The artist's joints as a rig: every joint turns about its own position and carries its weights, a leaf
    joint's weights go to its parent (see ``rigdata.weight_owners``): the leaf starts no bone."""
    skin = rig.skin.tocoo()
    owners = rigdata.weight_owners(rig.parents)
    return SkinnedRig.of(rig.positions, rig.parents,
                         csr_matrix((skin.data, (skin.row, owners[skin.col])), shape=skin.shape))


def skinned_rig(obj, bones):
    """The rig of ``bones`` (names, heads, parents) with the weights the Blender mesh object ``obj`` holds for them."""
    return SkinnedRig.of(bones.heads, bones.parents, rigdata.vertex_weights(obj, list(bones.names)))


def nearest_bone_rig(heads, tails, parents, vertices):
    """A rig whose every vertex follows only its nearest bone (distance to the bone segment)."""
    nearest = segment_distances(vertices, np.asarray(heads, np.float64), np.asarray(tails, np.float64)).argmin(axis=1)
    weights = csr_matrix((np.ones(len(vertices)), (np.arange(len(vertices)), nearest)),
                         shape=(len(vertices), len(heads)))
    return SkinnedRig.of(heads, parents, weights)


# --- poses and linear blend skinning -----------------------------------------------------------------------------

def posed_from_local(rig, rotations):
    """World transforms (R (B, 3, 3), t (B, 3)) when every bone turns by its local rotation ``rotations[b]`` about
    its own head, applied down the hierarchy (root heads stay where they are)."""
    world_r = np.empty((len(rig), 3, 3))
    world_t = np.empty((len(rig), 3))
    for bone in rig.order():
        parent = rig.parents[bone]
        head = rig.heads[bone]
        if parent < 0:
            world_r[bone], moved_head = rotations[bone], head
        else:
            world_r[bone] = world_r[parent] @ rotations[bone]
            moved_head = world_r[parent] @ head + world_t[parent]
        world_t[bone] = moved_head - world_r[bone] @ head
    return world_r, world_t


def random_rotations(count, max_degrees, rng):
    """``count`` rotations (count, 3, 3), each about a uniformly random axis by an angle uniform in [0, max]."""
    axes = rng.normal(size=(count, 3))
    axes /= np.linalg.norm(axes, axis=1, keepdims=True)
    angles = rng.uniform(0.0, np.radians(max_degrees), count)
    return Rotation.from_rotvec(axes * angles[:, None]).as_matrix()


def random_poses(rig, count, max_degrees, rng):
    """``count`` poses of ``rig``: every bone rotated about its head by up to ``max_degrees`` about a random axis."""
    return [posed_from_local(rig, random_rotations(len(rig), max_degrees, rng)) for _ in range(count)]


def positions(pose, bones, vertices):
    """(V, m, 3) each vertex moved by the transforms of its m ``bones`` (V, m) in ``pose``."""
    world_r, world_t = pose
    every = (vertices @ world_r.transpose(2, 0, 1).reshape(3, -1)).reshape(len(vertices), -1, 3)  # (V, B, 3)
    every += world_t
    rows = np.arange(len(vertices))[:, None] * len(world_r) + bones
    return np.take(every.reshape(-1, 3), rows.ravel(), axis=0).reshape(*bones.shape, 3)


def deformed(rig, pose, vertices):
    """(V, 3) the vertices moved by linear blend skinning: sum over a vertex's bones of weight * (R v + t)."""
    return np.einsum("vm,vmi->vi", rig.weights, positions(pose, rig.bones, vertices))


def skew(vectors):
    """(..., 3, 3) the cross-product matrices [a]x of (..., 3) vectors: [a]x b = a x b."""
    a = np.asarray(vectors)
    zero = np.zeros(a.shape[:-1])
    return np.stack([np.stack([zero, -a[..., 2], a[..., 1]], -1),
                     np.stack([a[..., 2], zero, -a[..., 0]], -1),
                     np.stack([-a[..., 1], a[..., 0], zero], -1)], -2)


# --- fitting a rig to a deformed mesh ------------------------------------------------------------------------------

def rotation_fit(sources, targets, weights):
    """The rotation R minimising sum w |R p - q|^2 over rows p of ``sources`` and q of ``targets`` (Kabsch); the
    identity when the weighted points leave it undetermined in every direction."""
    h = np.einsum("n,ni,nj->ij", weights, targets, sources)
    if not np.abs(h).max() > 0:
        return np.eye(3)
    u, _, vt = np.linalg.svd(h)
    flip = np.diag([1.0, 1.0, np.sign(np.linalg.det(u @ vt)) or 1.0])
    return u @ flip @ vt


def rigid_fit(sources, targets, weights):
    """The rotation and translation (R, t) minimising sum w |R p + t - q|^2."""
    total = weights.sum()
    source_centre = weights @ sources / total
    target_centre = weights @ targets / total
    rotation = rotation_fit(sources - source_centre, targets - target_centre, weights)
    return rotation, target_centre - rotation @ source_centre


class Fitter:
    """Fits one rig's pose to deformed copies of its rest mesh: each bone rotates about its own (carried) head,
    parents first; a root bone may also move.

    A first pass fits each bone, parents first, by weighted Procrustes to the vertices it dominates (weighted by
    their weight on it), carried by its parent. Levenberg-Marquardt steps then minimise the linear blend skinning
    error over all bones at once (a small rotation of a bone about its head, its subtree carried along, moves each
    vertex by the cross product with the part of the vertex the subtree carries), so a rig fitted to its own poses
    converges to zero error and any other rig to a local optimum at least as good as the first pass.
    """

    def __init__(self, rig, rest):
        self.rig, self.rest = rig, np.asarray(rest, np.float64)
        self.order = rig.order()
        self.inside = rig.subtrees()
        dominant, weight = rig.dominant()
        self.dominated = [np.flatnonzero(dominant == bone) for bone in range(len(rig))]
        self.dominant_weight = weight
        # (V, m, B): the weight of a vertex's m-th entry when that entry's bone is bone b or below it, else 0
        carried = np.where(self.inside.T[rig.bones], rig.weights[..., None], 0.0)
        self.free = np.flatnonzero(carried.any(axis=(0, 1)))  # bones that move some vertex: the unknowns
        self.roots = np.flatnonzero(rig.parents < 0)
        self.root_share = carried[:, :, self.roots].sum(axis=1)  # (V, roots)
        carried = carried[:, :, self.free]
        # The (vertex, free bone) pairs where the bone's subtree carries part of the vertex, in vertex order; per
        # pair, its weight (share) and, as a sparse (pairs, V * m) matrix, how it gathers the vertex's moved copies.
        share = carried.sum(axis=1)
        self.pair_vertex, self.pair_bone = np.nonzero(share)
        self.pair_share = share[self.pair_vertex, self.pair_bone]
        pair_of = np.full(share.shape, -1)
        pair_of[self.pair_vertex, self.pair_bone] = np.arange(len(self.pair_vertex))
        vertex, slot, free = np.nonzero(carried)
        count, width = carried.shape[:2]
        self.gather = csr_matrix((carried[vertex, slot, free], (pair_of[vertex, free], vertex * width + slot)),
                                 shape=(len(self.pair_vertex), count * width))
        # the sparsity of the (V, 3F) lever matrix, one row per vertex: pairs in vertex order, 3 columns each
        self.lever_columns = (3 * self.pair_bone[:, None] + np.arange(3)).ravel()
        self.lever_rows = np.r_[0, np.cumsum(3 * np.bincount(self.pair_vertex, minlength=len(rest)))]
        self.size = float(np.ptp(self.rest, axis=0).max())

    def fit(self, target, steps=STEPS, tolerance=CONVERGED):
        """The pose (R, t) reproducing ``target`` (V, 3) best, and the number of Levenberg-Marquardt steps taken."""
        pose = self._first_pass(target)
        residual = deformed(self.rig, pose, self.rest) - target
        error = float((residual ** 2).sum())
        damping = 1e-3
        floor = len(target) * (ACCURATE * self.size) ** 2
        for step in range(1, steps + 1):
            normal, gradient = self._normal_equations(pose, residual)
            scale = np.diag(normal) + 1e-12 * max(float(np.diag(normal).max()), 1e-300)
            while True:
                change = np.linalg.solve(normal + damping * np.diag(scale), -gradient)
                candidate = self._moved(pose, change)
                candidate_residual = deformed(self.rig, candidate, self.rest) - target
                candidate_error = float((candidate_residual ** 2).sum())
                if candidate_error < error or damping > 1e8:
                    break
                damping *= 4.0
            if candidate_error >= error:
                break
            gain = error - candidate_error
            pose, residual, error = candidate, candidate_residual, candidate_error
            damping = max(damping / 3.0, 1e-9)
            if gain <= tolerance * (error + gain) or error <= floor:
                break
        return pose, step

    def _first_pass(self, target):
        rig, rest = self.rig, self.rest
        world_r = np.tile(np.eye(3), (len(rig), 1, 1))
        world_t = np.zeros((len(rig), 3))
        for bone in self.order:
            parent, head = rig.parents[bone], rig.heads[bone]
            if parent >= 0:
                world_r[bone], world_t[bone] = world_r[parent], world_t[parent]
            vertices = self.dominated[bone]
            if not len(vertices):
                continue
            weights = self.dominant_weight[vertices]
            if parent < 0:
                world_r[bone], world_t[bone] = rigid_fit(rest[vertices], target[vertices], weights)
            else:
                moved_head = world_r[bone] @ head + world_t[bone]
                world_r[bone] = rotation_fit(rest[vertices] - head, target[vertices] - moved_head, weights)
                world_t[bone] = moved_head - world_r[bone] @ head
        return world_r, world_t

    def _heads(self, pose):
        world_r, world_t = pose
        return np.einsum("bij,bj->bi", world_r, self.rig.heads) + world_t

    def _normal_equations(self, pose, residual):
        """J^T J and J^T r of the posed vertices' derivative J by a small world rotation of each free bone about its
        posed head (its subtree carried: a vertex moves by omega x lever, lever = the part of the vertex the subtree
        carries, measured from the head), then by a translation of each root's subtree."""
        posed = positions(pose, self.rig.bones, self.rest)
        free = len(self.free)
        heads = self._heads(pose)[self.free][self.pair_bone]
        lever = self.gather @ posed.reshape(-1, 3) - self.pair_share[:, None] * heads  # (pairs, 3)
        flat = csr_matrix((lever.ravel(), self.lever_columns, self.lever_rows), shape=(len(posed), 3 * free))
        moments = (flat.T @ flat).toarray().reshape(free, 3, free, 3)  # [f, i, g, j] = sum_v lever_vf,i lever_vg,j
        # [omega]x^T [omega']x blocks: (a . b) I - b a^T
        rotation_block = (np.einsum("figi->fg", moments)[:, None, :, None] * np.eye(3)[None, :, None, :]
                          - moments.transpose(2, 1, 0, 3))
        root_share = self.root_share
        cross = skew((flat.T @ root_share).reshape(free, 3, -1).transpose(0, 2, 1))  # (F, roots, 3, 3)
        roots = len(self.roots)
        normal = np.zeros((3 * (free + roots), 3 * (free + roots)))
        normal[:3 * free, :3 * free] = rotation_block.reshape(3 * free, 3 * free)
        normal[:3 * free, 3 * free:] = cross.transpose(0, 2, 1, 3).reshape(3 * free, 3 * roots)
        normal[3 * free:, :3 * free] = normal[:3 * free, 3 * free:].T
        normal[3 * free:, 3 * free:] = np.kron(root_share.T @ root_share, np.eye(3))
        products = np.asarray(flat.T @ residual).reshape(free, 3, 3)  # [f, i, j] = sum_v lever_vf,i residual_v,j
        turning = np.stack([products[:, 1, 2] - products[:, 2, 1], products[:, 2, 0] - products[:, 0, 2],
                            products[:, 0, 1] - products[:, 1, 0]], axis=1)  # sum_v lever_vf x residual_v
        gradient = np.concatenate([turning.ravel(), (root_share.T @ residual).ravel()])
        return normal, gradient

    def _moved(self, pose, change):
        """The pose after rotating each free bone's subtree by its part of ``change`` about the bone's head (deepest
        bones first, so each turns about its current head) and translating each root's subtree."""
        world_r, world_t = pose[0].copy(), pose[1].copy()
        rotations = change[:3 * len(self.free)].reshape(-1, 3)
        turn = dict(zip(self.free.tolist(), Rotation.from_rotvec(rotations).as_matrix()))
        for bone in self.order[::-1]:
            if bone not in turn:
                continue
            centre = world_r[bone] @ self.rig.heads[bone] + world_t[bone]
            subtree = self.inside[bone]
            world_r[subtree] = np.einsum("ij,bjk->bik", turn[bone], world_r[subtree])
            world_t[subtree] = (world_t[subtree] - centre) @ turn[bone].T + centre
        for root, shift in zip(self.roots, change[3 * len(self.free):].reshape(-1, 3)):
            world_t[self.inside[root]] += shift
        return world_r, world_t


# --- measures ----------------------------------------------------------------------------------------------------

def face_normals(points, triangles):
    corners = points[triangles]
    return np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])


def normal_angles(fitted, target, triangles, faces=None):
    """Angles in degrees between the face normals of ``fitted`` and ``target``, on ``faces`` (default all)."""
    triangles = triangles if faces is None else triangles[faces]
    a, b = face_normals(fitted, triangles), face_normals(target, triangles)
    lengths = np.linalg.norm(a, axis=1) * np.linalg.norm(b, axis=1)
    cosine = np.einsum("ij,ij->i", a, b) / np.where(lengths > 0, lengths, 1.0)
    return np.degrees(np.arccos(np.clip(np.where(lengths > 0, cosine, 1.0), -1.0, 1.0)))


def proper_faces(vertices, triangles):
    """Indices of the triangles with a non-zero area at rest (only they have a normal)."""
    areas = np.linalg.norm(face_normals(vertices, triangles), axis=1)
    return np.flatnonzero(areas > 1e-12 * max(float(areas.max()), 1e-300))


def coincident_pairs(vertices, size, tolerance=COINCIDENT):
    """(P, 2) index pairs of vertices that share a rest position (closer than ``tolerance`` * ``size``)."""
    return cKDTree(vertices).query_pairs(tolerance * size, output_type="ndarray").reshape(-1, 2)


def crack(posed, pairs):
    """The largest distance between the posed vertices of ``pairs`` (0 without pairs), and the pair's index."""
    if not len(pairs):
        return 0.0, -1
    gaps = np.linalg.norm(posed[pairs[:, 0]] - posed[pairs[:, 1]], axis=1)
    worst = int(gaps.argmax())
    return float(gaps[worst]), worst


def leaf_chains(parents):
    """The joint chains of a joint tree from a branch joint (or a root) to a leaf: lists of joint indices."""
    parents = np.asarray(parents)
    children = np.bincount(parents[parents >= 0], minlength=len(parents))
    chains = []
    for leaf in np.flatnonzero(children == 0):
        chain = [int(leaf)]
        while parents[chain[-1]] >= 0:
            chain.append(int(parents[chain[-1]]))
            if children[chain[-1]] != 1 or parents[chain[-1]] < 0:
                break
        chains.append(chain[::-1])
    return chains


def chain_points(positions, chain, step):
    """Points every ``step`` or closer along the polyline through ``positions[chain]``, both ends included."""
    line = positions[chain]
    if len(line) == 1:
        return line
    pieces = []
    for start, end in zip(line[:-1], line[1:]):
        count = max(int(np.ceil(np.linalg.norm(end - start) / step)), 1)
        pieces.append(start + np.linspace(0.0, 1.0, count + 1)[:-1, None] * (end - start))
    return np.concatenate(pieces + [line[-1:]])


def limb_recall(joint_positions, joint_parents, heads, tails, parents, size, tolerance=FOLLOWS, step=CHAIN_STEP):
    """Which of the artist's leaf chains (see :func:`leaf_chains`) a chain of the bones under test follows.

    A chain is followed when its points (every ``step`` * ``size``) lie within ``tolerance`` * ``size`` on average of
    one path of bones from a leaf bone up to its root. Returns (share followed, list of (chain, followed) pairs).
    """
    chains = [chain for chain in leaf_chains(joint_parents) if len(chain) > 1]
    if not chains:
        return float("nan"), []
    outcome = [(chain, closest_path(chain_points(joint_positions, chain, step * size), heads, tails, parents)[0]
                <= tolerance * size) for chain in chains]
    return float(np.mean([followed for _, followed in outcome])), outcome


def bone_paths(parents):
    """The paths of a bone forest from each leaf bone up to its root: lists of bone indices, leaf first."""
    parents = np.asarray(parents)
    is_leaf = np.ones(len(parents), dtype=bool)
    is_leaf[parents[parents >= 0]] = False
    paths = []
    for leaf in np.flatnonzero(is_leaf):
        path, bone = [], int(leaf)
        while bone >= 0:
            path.append(bone)
            bone = int(parents[bone])
        paths.append(path)
    return paths


def closest_path(points, heads, tails, parents):
    """(mean distance, path) of the path of bones (see :func:`bone_paths`) that ``points`` lie closest to on
    average, each point measured to its nearest bone on the path."""
    heads, tails = np.asarray(heads, dtype=np.float64), np.asarray(tails, dtype=np.float64)
    distances = segment_distances(points, heads, tails)
    return min(((float(distances[:, path].min(axis=1).mean()), path) for path in bone_paths(parents)),
               key=lambda pair: pair[0])


@dataclass(frozen=True)
class MirrorPlane:
    """The plane ``x[axis] = offset``, and how far (median, fraction of size) the mesh's mirror image lies from it."""

    axis: int
    offset: float
    asymmetry: float

    def mirrored(self, points):
        points = np.array(points, dtype=np.float64)
        points[..., self.axis] = 2 * self.offset - points[..., self.axis]
        return points

    def distances(self, points):
        return np.abs(np.asarray(points)[..., self.axis] - self.offset)

    def two_sided(self, tolerance=MIRROR_SYMMETRIC):
        return self.asymmetry <= tolerance


def mirror_surface(vertices, triangles):
    """A KD-tree of the surface's samples (vertices, edge midpoints and face centres): a mirror image that falls
    between the vertices of a coarser side still lands on one."""
    corners = vertices[triangles]
    return cKDTree(np.concatenate([vertices, corners.mean(axis=1),
                                   (corners + np.roll(corners, 1, axis=1)).reshape(-1, 3) / 2]))


def mirror_plane(vertices, triangles, size, surface=None):
    """Of the three axis planes, each at the offset the mesh is most symmetric about, the one the mesh is most
    symmetric about.

    Asymmetry: the median distance from a mirrored vertex to the nearest vertex, edge midpoint or face centre (so
    a mirror image that falls between vertices of a coarser side still lands on the surface's samples), as a fraction
    of ``size``. Offsets: every ``PLANE_STEP`` of ``size`` within ``PLANE_SEARCH`` of the bounding box's centre (a
    symmetric body holding a prop to one side is not centred on its box). The plane is chosen by the asymmetry
    relative to the mesh's extent across the plane: a thin body mirrors onto itself front to back whatever its shape.
    """
    tree = mirror_surface(vertices, triangles) if surface is None else surface  # ``mirror_surface``, made once
    low, high = vertices.min(axis=0), vertices.max(axis=0)
    probe = vertices[::max(1, len(vertices) // PLANE_PROBES)]
    planes = []
    for axis in range(3):
        centre = float(low[axis] + high[axis]) / 2
        offsets = centre + size * np.arange(-PLANE_SEARCH, PLANE_SEARCH + PLANE_STEP / 2, PLANE_STEP)
        rough = [np.median(tree.query(MirrorPlane(axis, offset, 0.0).mirrored(probe))[0]) for offset in offsets]
        plane = MirrorPlane(axis, float(offsets[int(np.argmin(rough))]), 0.0)
        asymmetry = float(np.median(tree.query(plane.mirrored(vertices))[0])) / size
        planes.append(MirrorPlane(axis, plane.offset, asymmetry))
    extent = np.maximum(high - low, 1e-300)
    return min(planes, key=lambda plane: plane.asymmetry * size / extent[plane.axis])


def twin_mismatches(names, heads, tails, plane, size):
    """{base name: largest distance (fraction of size) between a joint of ``base.L`` and the mirror image of its
    twin's joint in ``base.R``} for every name pair (head to head and tail to tail)."""
    index = {name: i for i, name in enumerate(names)}
    result = {}
    for name, i in index.items():
        match = SIDE.match(name)
        if not match or match.group(2) != "L" or f"{match.group(1)}.R" not in index:
            continue
        j = index[f"{match.group(1)}.R"]
        result[match.group(1)] = float(max(np.linalg.norm(heads[i] - plane.mirrored(heads[j])),
                                           np.linalg.norm(tails[i] - plane.mirrored(tails[j])))) / size
    return result


def local_asymmetry(vertices, surface, plane, heads, tails, bones, size):
    """{bone: the median distance (fraction of size) from the mirror images of the vertices nearest that bone (of all
    the ``heads``/``tails`` segments) to the ``surface`` (``mirror_surface``)} for each of ``bones``: whether the mesh
    itself mirrors there (a figure posed with one arm raised does not, however symmetric the rest of it)."""
    nearest = segment_distances(vertices, np.asarray(heads), np.asarray(tails)).argmin(axis=1)
    result = {}
    for bone in bones:
        near = vertices[nearest == bone]
        result[bone] = float(np.median(surface.query(plane.mirrored(near))[0])) / size if len(near) else float("nan")
    return result


def unsided_off_plane(names, heads, tails, plane, size, tolerance=OFF_PLANE):
    """Names of the bones without a ``.L``/``.R`` suffix whose midpoint lies more than ``tolerance`` * ``size`` off
    the plane."""
    midpoints = (np.asarray(heads) + np.asarray(tails)) / 2
    off = plane.distances(midpoints) > tolerance * size
    return [name for name, far in zip(names, off) if far and not SIDE.match(name)]
