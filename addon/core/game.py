"""The ``game`` target's skeleton: Rigger's skeleton, with its roles, redrawn as a deform-only skeleton a game engine
and a mocap library expect (bpy-free; ``rigger.blender.game`` builds it).

The naming scheme (one for every body plan; the README says the same for users):

- ``root``: the hierarchy's single root, on the ground under the hips (the mesh's lowest point along the plan's up),
  pointing up; it deforms nothing. ``Hips`` hangs from it and everything else from ``Hips``.
- The trunk, from the hips joint (where the legs hang; the named hips joint when that lies lower,
  ``core.roles.hips_below``) to where the neck begins: ``Hips`` up to the spine joint (the
  named joint where the ``spine`` role begins), then ``Spine``, ``Spine1``, ``Spine2``, the last from the chest joint
  (where ``chest`` begins). A missing joint is put where Mixamo's humanoids have it: the spine joint at ``SPINE_AT``
  and the chest joint at ``CHEST_AT`` of the trunk's length; ``Spine1`` halfway between them.
- Every other role is one bone per chain of that role, Rigger's bones of the chain merged into it, named with
  Mixamo's word for the role: ``Neck``, ``Head``, ``Jaw``, ``Shoulder``, ``Arm`` (upper arm), ``ForeArm``, ``Hand``,
  ``UpLeg`` (thigh), ``Leg`` (shin), ``Foot``, ``ToeBase``; sided ones get ``Left`` / ``Right`` before the word
  (``LeftForeArm``), by the character's own side (``core.facing``: a character facing +Y has its ``.L`` bones on its
  right, and its ``Left`` bones on its left). A quadruped's front legs have the roles, so the names, of arms and its
  hind legs those of legs. The neck of any plan but a humanoid's keeps Rigger's joints: ``Neck``, ``Neck1``,
  ``Neck2``, ..., as Mixamo numbers its spine (an animal's long neck bends along its length; engines' humanoids have
  one ``Neck``). A leg's ``hips`` bones (from the body's middle to the hip joint) are the pelvis: they
  merge into ``Hips``.
- A forearm (shin, neck) that ends without a hand (foot, head) gets one: ``_completed_ends``; a humanoid's upper
  arm (thigh) without a forearm (shin) after it is split at the elbow (knee): ``_split_middles``.
- Fingers: ``LeftHandThumb1``..``3``, ``Index``, ``Middle``, ``Ring``, ``Pinky``, at most three bones each (Rigger's
  bones merged at the joints nearest the thirds); a finger without a digit is ``LeftHandFinger1``..``3``.
- Parts without a Mixamo name keep one bone per Rigger bone, numbered from 1 along the chain: ``Tail1``, ``Tail2``,
  ``LeftEar1``, ``LeftWing1``, ``Fin1``, ``Extra1`` (role ``other``) and ``Stem1`` (role ``root``: a stem under the
  hips).
- A second chain of the same name (a second pair of arms) gets ``_2`` after the name (``LeftArm_2``), a third ``_3``:
  a chain takes the number of the chain it hangs from (``LeftArm_2``'s forearm is ``LeftForeArm_2``), else chains
  are numbered from the highest start down.

Each bone with a Mixamo name begins at its role's named joint (``core.roles.named_joints``: a knee where the artists'
rigs have it, which may lie inside a bone of Rigger's) when it lies near (``core.roles.within_reach``; a thigh's or
upper arm's up the Rigger bone the limb hangs from, or down its own, counts as near), the bones ending there moved
with it.

The hierarchy is Rigger's read from the hips outwards (Rigger may root a quadruped at its neck): a chain hangs from the
game bone that holds the joint it starts from, else the nearest joint on its way to the hips; a chain Rigger hangs
beside its parent bone's end rather than at it (a deer's ears, near where its head bone begins) hangs from the game
bone that took that parent over. Twins hang from one bone
or from twins, and twins (``Left…`` and ``Right…`` bones that mirror each other within ``TWIN_TOLERANCE`` of the size)
get exactly mirrored points across the mirror plane.
"""
from dataclasses import dataclass, replace

import numpy as np

from .facing import facing, foot_ahead
from .mesh import validated_vertices
from .polyline import arc_lengths, arc_nearest, point_at, segment_distances
from .roles import LIMB_STARTS, BoneRole, hips_below, landmarks, named_joints, within_reach
from .skeleton import Skeleton

ROOT = "root"
SPINE_AT = 0.2  # share of the trunk from the hips joint to the neck where Mixamo's Spine begins (0a59c5ff: 0.2) ...
CHEST_AT = 0.7  # ... and Spine2 (0.7)
TWIN_TOLERANCE = 0.02  # twins whose points mirror within this share of the size are mirrored exactly
ROOT_LENGTH = 0.1  # the root bone's length, a share of the size
MERGE_TOLERANCE = 1e-9  # points this close (a share of the size) are one joint

WORDS = {"hips": "Hips", "neck": "Neck", "head": "Head", "jaw": "Jaw", "shoulder": "Shoulder", "upper_arm": "Arm",
         "forearm": "ForeArm", "hand": "Hand", "thigh": "UpLeg", "shin": "Leg", "foot": "Foot", "toe": "ToeBase",
         "tail": "Tail", "ear": "Ear", "wing": "Wing", "fin": "Fin", "other": "Extra", "root": "Stem"}
NUMBERED = frozenset({"tail", "ear", "wing", "fin", "other", "root"})  # one game bone per Rigger bone
DIGIT_WORDS = {"thumb": "Thumb", "index": "Index", "middle": "Middle", "ring": "Ring", "pinky": "Pinky", None: "Finger"}
FINGER_BONES = 3
TRUNK = ("hips", "spine", "chest")
SIDE_WORDS = {"L": "Left", "R": "Right", None: ""}
# a bone, the end bone it may lack, the named joint that begins at, where it ends (the first found), what it carries
ENDS = (("ForeArm", "Hand", ("hand",), ("hand_tip",), ("finger",)),
        ("Leg", "Foot", ("foot",), ("toe", "toe_tip"), ("toe",)),
        ("Neck", "Head", ("head",), ("head_top",), ("jaw", "ear")))
END_SHARE = 0.5  # an end bone with nowhere to end goes on along its limb bone for this share of that bone's length
END_STARTS = (0.5, 1.0)  # an end bone begins at its named joint only when that lies this far along the limb bone
# a limb bone, the bone after it it may lack, the named joint that begins at, the roles that bone carries
MIDDLES = (("UpLeg", "Leg", "shin", ("foot", "toe")), ("Arm", "ForeArm", "forearm", ("hand", "finger")))
SPLIT_SHARES = (0.2, 0.8)  # a limb bone is split where the missing bone begins only this far along it
HUMANOID = ("Hips", "Spine", "Spine1", "Spine2", "Neck", "Head",
            *(f"{side}{word}" for side in ("Left", "Right")
              for word in ("Shoulder", "Arm", "ForeArm", "Hand", "UpLeg", "Leg", "Foot")))  # what engines expect


def missing_humanoid_bones(names):
    """The bones of ``HUMANOID`` (a game engine's humanoid, less fingers and toes) that ``names`` lacks."""
    return [name for name in HUMANOID if name not in names]


@dataclass(frozen=True)
class GameSkeleton:
    """The game skeleton (``skeleton``: names, world points, parents, roles, the body plan) and, for each bone of
    Rigger's skeleton, the index of the game bone that took it over (``owners``)."""

    skeleton: Skeleton
    owners: tuple


def game_skeleton(skeleton, vertices):
    """The :class:`GameSkeleton` of ``skeleton`` (with its roles and body plan, as ``rigger.rig_mesh`` returns it)
    rigging a mesh with ``vertices`` (N, 3), by the scheme of this module's docstring. ValueError without roles, or
    for vertices that are no (N, 3) finite numbers."""
    if skeleton.roles is None or skeleton.body_plan is None:
        raise ValueError("the game skeleton needs a skeleton with roles and a body plan (from rigger.rig_mesh)")
    vertices = validated_vertices(vertices)
    up = np.asarray(skeleton.body_plan.up, dtype=np.float64)
    up /= np.linalg.norm(up)
    size = float(np.ptp(vertices, axis=0).max())
    graph = _Graph(skeleton, size)
    start = graph.hips_node()
    order, arriving = graph.oriented(start)
    chains = graph.chains(order, arriving)
    joints = named_joints(skeleton)
    bones = _Bones(graph, joints)
    trunk = next((chain for chain in chains if chain.key == ("trunk", None, None) and chain.nodes[0] == start), None)
    if trunk is not None:
        bones.trunk(trunk)
    for chain in chains:
        if chain is not trunk:
            bones.chain(chain)
    bones.name_instances(up, size, skeleton.stages.get("mirror_plane"))
    bones.at_named_joints(MERGE_TOLERANCE * size)
    names, heads, tails, parents, roles = bones.finished(arriving)
    faced = facing(skeleton)
    if skeleton.body_plan.kind == "humanoid":
        names, heads, tails, parents, roles = _split_middles(names, heads, tails, parents, roles, joints)
    names, heads, tails, parents, roles = _completed_ends(names, heads, tails, parents, roles,
                                                          {**joints, **landmarks(skeleton)}, vertices, faced)
    parents = _twin_parents(names, heads, tails, parents)
    heads, tails = _mirrored_twins(names, heads, tails, skeleton.stages.get("mirror_plane"), size)
    hips = heads[bones.hips] if bones.hips is not None else graph.points[start]
    ground = float((vertices @ up).min())
    foot = hips - (hips @ up - ground) * up
    names = [ROOT, *names]
    heads = np.vstack([foot, heads])
    tails = np.vstack([foot + ROOT_LENGTH * size * up, tails])
    parents = [-1] + [parent + 1 for parent in parents]
    roles = [BoneRole("root"), *roles]
    if faced.swapped:
        names, roles = _own_sides(names, roles)
    game = Skeleton(names, heads, tails, parents, roles=roles, body_plan=skeleton.body_plan)
    return GameSkeleton(game, tuple(owner + 1 for owner in bones.owners(len(skeleton))))


def _own_sides(names, roles):
    """``names`` and ``roles`` with left and right swapped, for a skeleton whose ``.L`` bones lie on the character's
    right."""
    words = {"Left": "Right", "Right": "Left"}
    names = [next((words[word] + name[len(word):] for word in words if name.startswith(word)), name) for name in names]
    roles = [replace(role, side={"L": "R", "R": "L"}.get(role.side, role.side)) for role in roles]
    return names, roles


def _key(role):
    """The chain key of a bone role: the trunk's roles are one chain, a leg's hips bones the pelvis."""
    if role.role in TRUNK and role.side is None:
        return ("trunk", None, None)
    if role.role == "hips":
        return ("pelvis", role.side, None)
    return (role.role, role.side, role.digit if role.role == "finger" else None)


class _Graph:
    """Rigger's skeleton as an undirected graph of joints: one edge per bone, plus a link (no bone) from the nearer
    end of a parent to a child's head where the child does not start at one of its parent's ends."""

    def __init__(self, skeleton, size):
        self.skeleton = skeleton
        points, index = [], {}

        def node(point):
            key = tuple(np.round(np.asarray(point) / (MERGE_TOLERANCE * max(size, 1e-300))).astype(np.int64))
            if key not in index:
                index[key] = len(points)
                points.append(np.asarray(point, dtype=np.float64))
            return index[key]

        self.ends = [(node(head), node(tail)) for head, tail in zip(skeleton.heads, skeleton.tails)]
        self.edges = []  # (a, b, bone index or -1 for a link, chain key); a bone's edge has the bone's index
        self.link_parent = {}  # link edge -> the parent bone it leaves
        keys = [_key(role) for role in skeleton.roles]
        for bone, (a, b) in enumerate(self.ends):
            self.edges.append((a, b, bone, keys[bone]))
        for bone, parent in enumerate(skeleton.parents):
            if parent >= 0 and self.ends[bone][0] not in self.ends[parent]:
                head = skeleton.heads[bone]
                end = min(self.ends[parent], key=lambda n: np.linalg.norm(np.asarray(points[n]) - head))
                self.link_parent[len(self.edges)] = parent
                self.edges.append((end, self.ends[bone][0], -1, keys[bone]))
        self.points = np.array(points)
        self.neighbours = [[] for _ in points]
        for edge, (a, b, _, _) in enumerate(self.edges):
            self.neighbours[a].append((b, edge))
            self.neighbours[b].append((a, edge))

    def hips_node(self):
        """Where the hips are: the end of the trunk's longest path on the side of its hips bones (else the end
        farther from the neck and head); without a trunk, the head of Rigger's first root bone."""
        trunk = [edge for edge, (_, _, bone, key) in enumerate(self.edges) if key[0] == "trunk" and bone >= 0]
        if not trunk:
            return self.ends[self.skeleton.roots[0]][0]
        path = self._longest_path(set(trunk))
        ends = (path[0], path[-1])
        roles = self.skeleton.roles

        def hips_at(node):
            return any(self.edges[edge][2] >= 0 and roles[self.edges[edge][2]].role == "hips"
                       for _, edge in self.neighbours[node] if edge in trunk)

        sided = [end for end in ends if hips_at(end)]
        if len(sided) == 1:
            return sided[0]
        heads = [self.points[self.edges[edge][0]] for edge, (_, _, bone, key) in enumerate(self.edges)
                 if key[0] in ("neck", "head") and bone >= 0]
        if heads:
            centre = np.mean(heads, axis=0)
            return max(ends, key=lambda end: np.linalg.norm(self.points[end] - centre))
        return ends[0]

    def _longest_path(self, edges):
        """The longest path (by length) through the edge set ``edges`` (a forest), as nodes."""
        nodes = {n for edge in edges for n in self.edges[edge][:2]}

        def farthest(start):
            distance, before, todo = {start: 0.0}, {start: None}, [start]
            while todo:
                node = todo.pop()
                for other, edge in self.neighbours[node]:
                    if edge in edges and other not in distance:
                        distance[other] = distance[node] + self._length(edge)
                        before[other] = node
                        todo.append(other)
            end = max(distance, key=distance.get)
            path = [end]
            while before[path[-1]] is not None:
                path.append(before[path[-1]])
            return path

        return farthest(farthest(min(nodes))[0])

    def _length(self, edge):
        a, b = self.edges[edge][:2]
        return float(np.linalg.norm(self.points[a] - self.points[b]))

    def oriented(self, start):
        """Breadth-first order of the nodes from ``start`` and, per node, the edge arriving at it (None at the start
        and at nodes of other components, whose first node is then taken as a start too)."""
        arriving = {start: None}
        order = [start]
        for seed in [start, *range(len(self.points))]:
            if seed not in arriving:
                arriving[seed] = None
                order.append(seed)
            at = order.index(seed)
            while at < len(order):
                node = order[at]
                for other, edge in self.neighbours[node]:
                    if other not in arriving:
                        arriving[other] = edge
                        order.append(other)
                at += 1
        return order, arriving

    def other_end(self, edge, node):
        a, b = self.edges[edge][:2]
        return b if node == a else a

    def chains(self, order, arriving):
        """The chains: runs of edges of one key, each from the node nearest the hips outwards, taking at a fork the
        branch with the longest run of the same key (the others start chains of their own)."""
        children = {}
        for node in order:
            edge = arriving[node]
            if edge is not None:
                children.setdefault(self.other_end(edge, node), []).append(node)
        key_of = {node: self.edges[arriving[node]][3] for node in order if arriving[node] is not None}
        reach = {}
        for node in reversed(order):  # the length of the longest same-key run from each node outwards
            same = [child for child in children.get(node, ()) if key_of[child] == key_of.get(node)]
            reach[node] = max((reach[child] + 1 for child in same), default=0)
        chains = []
        for node in order:
            for child in children.get(node, ()):
                if node in key_of and key_of[child] == key_of[node] and child == self._continuation(node, children,
                                                                                                     key_of, reach):
                    continue
                nodes = [node, child]
                while (following := self._continuation(nodes[-1], children, key_of, reach)) is not None:
                    nodes.append(following)
                chains.append(_Chain(key_of[child], nodes, [arriving[n] for n in nodes[1:]]))
        return chains

    @staticmethod
    def _continuation(node, children, key_of, reach):
        same = [child for child in children.get(node, ()) if key_of[child] == key_of.get(node)]
        return max(same, key=lambda child: (reach[child], -child)) if same else None


@dataclass
class _Chain:
    key: tuple
    nodes: list  # from the node nearest the hips outwards
    edges: list  # edge indices between consecutive nodes


class _Bones:
    """Game bones being made: name parts, points, the chain they come from and which graph edges they own."""

    def __init__(self, graph, joints):
        self.graph = graph
        self.joints = joints  # named joints, {(role, side, digit): point}
        self.bones = []  # dicts: base, number, suffix, side, points (head, tail), role, start node, chain id, hang
        self.edge_owner = {}  # graph edge -> game bone index
        self.node_owner = {}  # graph node -> the game bone that holds it (children hang from it)
        self.hips = None  # the Hips bone, once the trunk made it

    def _add(self, base, side, number, head, tail, role, start, chain, edges, end_nodes, hang=None):
        index = len(self.bones)
        self.bones.append({"base": base, "side": side, "number": number, "head": np.asarray(head, float),
                           "tail": np.asarray(tail, float), "role": role, "start": start, "chain": chain,
                           "suffix": "", "hang": hang})
        for edge in edges:
            self.edge_owner[edge] = index
        for node in end_nodes:
            self.node_owner[node] = index
        return index

    def trunk(self, chain):
        """Hips, Spine, Spine1, Spine2 along the trunk chain (see the module docstring)."""
        graph, roles = self.graph, self.graph.skeleton.roles
        points = graph.points[chain.nodes]
        role_at = [roles[graph.edges[edge][2]].role if graph.edges[edge][2] >= 0 else None for edge in chain.edges]
        hips = hips_below(self.joints, points[0], np.asarray(graph.skeleton.body_plan.up, dtype=np.float64),
                          MERGE_TOLERANCE * graph.skeleton.extent)
        shift = int(hips is not None)  # the points before the chain's own
        if shift:
            points, role_at = np.vstack([hips, points]), [None] + role_at
        arc = arc_lengths(points)
        total = arc[-1]

        def begins(names, share):
            named = next((self.joints[(name, None, None)] for name in names if (name, None, None) in self.joints),
                         None)
            at = next((k for k, role in enumerate(role_at) if role in names), None)
            along = arc_nearest(points, arc, named) if named is not None else arc[at] if at is not None else None
            return along if along is not None and 0 < along < total else share * total

        spine = begins(("spine", "chest"), SPINE_AT)
        chest = begins(("chest",), CHEST_AT)
        if not spine < chest < total:
            spine, chest = SPINE_AT * total, CHEST_AT * total
        cuts = [0.0, spine, 0.5 * (spine + chest), chest, total]
        at = point_at(points, arc, np.array(cuts))
        names = [("Hips", BoneRole("hips")), ("Spine", BoneRole("spine")), ("Spine1", BoneRole("spine", index=1)),
                 ("Spine2", BoneRole("chest"))]
        made = [self._add(base, None, "", at[k], at[k + 1], role, chain.nodes[0] if k == 0 else None, id(chain),
                          [], []) for k, (base, role) in enumerate(names)]
        for k, edge in enumerate(chain.edges):
            middle = 0.5 * (arc[k + shift] + arc[k + shift + 1])
            self.edge_owner[edge] = made[int(np.searchsorted(cuts[1:-1], middle))]
        for k, node in enumerate(chain.nodes):  # a node at a cut holds the bone that ends there
            self.node_owner[node] = made[min(int(np.searchsorted(cuts[1:-1], arc[k + shift], side="left")), 3)]
        self.hips = made[0]

    def chain(self, chain):
        graph = self.graph
        role_name, side, digit = chain.key
        if role_name in ("pelvis", "trunk"):  # a leg's hips bones (the pelvis), a trunk branch: Hips holds them
            owner = self.hips
            if owner is not None:
                for edge in chain.edges:
                    self.edge_owner[edge] = owner
                for node in chain.nodes[1:]:
                    self.node_owner[node] = owner
                return
            role_name = "hips"
        if role_name not in WORDS:  # a role the scheme has no word for (the trunk's, off the middle)
            role_name = "other"
        bones = [graph.edges[edge][2] for edge in chain.edges]
        first = graph.skeleton.roles[next((bone for bone in bones if bone >= 0), bones[0])]
        jointed = role_name == "neck" and graph.skeleton.body_plan.kind != "humanoid"
        if role_name == "finger":
            spans = _finger_spans(graph.points[chain.nodes], [bone >= 0 for bone in bones])
            base = "Hand" + DIGIT_WORDS[digit]
        elif role_name in NUMBERED or jointed:
            spans = [(k, k + 1) for k, bone in enumerate(bones) if bone >= 0] or [(0, len(bones))]
            base = WORDS[role_name]
        else:  # from the first bone's head: a link before it (a limb beside its parent's joint) is no bone's
            real = [k for k, bone in enumerate(bones) if bone >= 0]
            spans = [(real[0], real[-1] + 1)] if real else [(0, len(bones))]
            base = WORDS[role_name]
        numbered = role_name == "finger" or role_name in NUMBERED
        hang = graph.link_parent.get(chain.edges[0]) if chain.nodes[1] == graph.edges[chain.edges[0]][1] else None
        for number, (low, high) in enumerate(spans, start=1):
            role = BoneRole(first.role, first.side, number - 1 if numbered or jointed else 0, first.digit)
            text = str(number) if numbered else str(number - 1) if number > 1 else ""
            self._add(base, side, text, graph.points[chain.nodes[low]], graph.points[chain.nodes[high]], role,
                      chain.nodes[0] if number == 1 else None, id(chain), chain.edges[low:high],
                      chain.nodes[low + 1:high + 1], hang if number == 1 else None)

    def name_instances(self, up, size, plane=None):
        """``_2``, ``_3`` after the names that several chains share: ordered by the number of the bone each hangs
        from (a forearm on ``LeftArm_2`` is ``LeftForeArm_2``), then the chains going on from that bone's end before
        those branching off it on the way, then from the highest start, then to the highest end (heights within a
        billionth of the ``size`` alike), then by where that end lies: by where the chains are, not by the order
        the skeleton met them in, so a mesh scaled or moved keeps its numbers. Names are numbered from the hips
        outwards, so a chain's parent is numbered before it. With a mirror ``plane``, a right chain whose ends lie
        within ``TWIN_TOLERANCE`` of a left chain's mirror image then takes that chain's number (a rock monster's
        claws and elbow spikes, numbered alike on both sides)."""
        first_of_chain, last_of_chain = {}, {}
        for index, bone in enumerate(self.bones):
            first_of_chain.setdefault(bone["chain"], index)
            last_of_chain[bone["chain"]] = index
        by_name = {}
        for chain, index in first_of_chain.items():
            bone = self.bones[index]
            by_name.setdefault((bone["side"], bone["base"]), []).append(chain)

        def parent_number(chain):
            owner = self.node_owner.get(self.bones[first_of_chain[chain]]["start"])
            suffix = "" if owner is None or self.bones[owner]["chain"] == chain else self.bones[owner]["suffix"]
            return int(suffix[1:] or 1)

        def branching(chain):
            """Whether the chain leaves the bone it hangs from before that bone's end (a side branch)."""
            first = self.bones[first_of_chain[chain]]
            owner = self.node_owner.get(first["start"])
            return owner is not None and self.bones[owner]["chain"] != chain and \
                not np.allclose(first["head"], self.bones[owner]["tail"])

        def placed(chain):
            start, end = self.bones[first_of_chain[chain]]["head"], self.bones[last_of_chain[chain]]["tail"]
            return (-round(float(start @ up) / size, 9), -round(float(end @ up) / size, 9), *(-end).tolist())

        for chains in by_name.values():
            chains.sort(key=lambda chain: (parent_number(chain), branching(chain), *placed(chain)))
            for count, chain in enumerate(chains[1:], start=2):
                self._suffixed(chain, f"_{count}")
        if plane is None:
            return

        def ends(chain):
            return np.stack([self.bones[first_of_chain[chain]]["head"], self.bones[last_of_chain[chain]]["tail"]])

        for (side, base), rights in by_name.items():
            lefts = by_name.get(("L", base), []) if side == "R" else []
            pairs = sorted((float(np.abs(plane.reflect(ends(right)) - ends(left)).max()), k, left)
                           for k, right in enumerate(rights) for left in lefts)
            twin = {}
            for gap, k, left in pairs:
                if gap <= TWIN_TOLERANCE * size and k not in twin and left not in twin.values():
                    twin[k] = left
            if not twin:
                continue
            taken = {self.bones[first_of_chain[left]]["suffix"] for left in twin.values()}
            free = iter(suffix for suffix in ["", *(f"_{n}" for n in range(2, len(rights) + len(lefts) + 2))]
                        if suffix not in taken)
            for k, right in enumerate(rights):
                self._suffixed(right, self.bones[first_of_chain[twin[k]]]["suffix"] if k in twin else next(free))

    def _suffixed(self, chain, suffix):
        """Every bone of ``chain`` numbered with ``suffix``."""
        for bone in self.bones:
            if bone["chain"] == chain:
                bone["suffix"] = suffix

    def at_named_joints(self, tolerance):
        """Move the head of each first bone of a Mixamo name to its role's named joint, with the bones of its side
        ending there (siblings starting there have joints of their own; a sided branch off a midline bone leaves that
        bone's end on the midline), when it is within reach (``core.roles.within_reach``). Which bones end at a joint
        is read before any move, so twins are judged alike whatever moved between them (the neck's start, a hair)."""
        tails = [other["tail"].copy() for other in self.bones]
        for index, bone in enumerate(self.bones):
            role = bone["role"]
            key = (role.role, role.side, None)
            if bone["number"] or bone["suffix"] or role.index or key not in self.joints:
                continue
            old, new = bone["head"].copy(), np.asarray(self.joints[key], float)
            ending = [other for other, tail in zip(self.bones, tails) if np.linalg.norm(tail - old) <= tolerance]
            ends = [bone["tail"]] + [other["head"] for other in ending]
            limb_start = role.role in LIMB_STARTS
            start = bone["start"]
            if limb_start and start is not None and np.linalg.norm(self.graph.points[start] - old) <= tolerance:
                ends += [self.graph.points[node] for node, edge in self.graph.neighbours[start]
                         if self.edge_owner.get(edge) != index]  # Rigger's bones there, but those the bone holds
            if not within_reach(old, new, ends, limb_start=limb_start):
                continue
            bone["head"] = new.copy()
            for other in ending:
                if other["side"] == bone["side"]:  # a shoulder's joint off the midline leaves the spine's end there
                    other["tail"] = new.copy()

    def finished(self, arriving):
        """(names, heads, tails, parents, roles): each bone hangs from the game bone holding the joint its chain
        starts at (the Hips at the hips node; a chain hung beside its Rigger parent's end, ``hang``: the game bone
        that took that parent over), or from the bone before it in its chain."""
        names = [f"{SIDE_WORDS[bone['side']]}{bone['base']}{bone['number']}{bone['suffix']}" for bone in self.bones]
        if len(set(names)) != len(names):
            raise ValueError(f"game bone names collide: {sorted(n for n in names if names.count(n) > 1)}")
        parents = []
        hips = self.hips
        for index, bone in enumerate(self.bones):
            if index == hips:  # under the root
                parents.append(-1)
            elif bone["start"] is None:  # the next bone of a chain
                parents.append(index - 1)
            else:  # a chain hung beside its parent bone's end (ears near a head's start): from that bone's owner
                owner = self.edge_owner.get(bone["hang"]) if bone["hang"] is not None else None
                if owner is None:
                    owner = self._holder(bone["start"], arriving, index)
                parents.append(owner if owner is not None else -1 if hips is None else hips)
        heads = np.array([bone["head"] for bone in self.bones])
        tails = np.array([bone["tail"] for bone in self.bones])
        return names, heads, tails, parents, [bone["role"] for bone in self.bones]

    def _holder(self, node, arriving, index):
        """The game bone (not ``index``) holding ``node``, else the nearest joint on the way from it to the hips
        (a finger whose fork no bone ends at hangs from the bone it forks off), else None."""
        seen = set()
        while node not in seen and arriving.get(node) is not None:
            seen.add(node)
            edge = arriving[node]
            for owner in (self.node_owner.get(node), self.edge_owner.get(edge)):
                if owner is not None and owner != index:
                    return owner
            node = self.graph.other_end(edge, node)
        owner = self.node_owner.get(node)  # the hips node, which a trunk begun below it holds
        return owner if owner is not None and owner != index else None

    def owners(self, count):
        """The game bone owning each of Rigger's ``count`` bones."""
        owners = [-1] * count
        for edge, (a, b, bone, _) in enumerate(self.graph.edges):
            if bone < 0:
                continue
            owner = self.edge_owner.get(edge)  # an edge closing a loop has none: its ends' holders take it
            owners[bone] = owner if owner is not None else self.node_owner.get(a, self.node_owner.get(b, self.hips))
        return owners


def _finger_spans(points, real):
    """(low, high) node spans of a finger's game bones: one per bone up to ``FINGER_BONES``, else cut at the joints
    nearest the thirds of its length."""
    count = len(points) - 1
    if sum(real) <= FINGER_BONES:
        return [(k, k + 1) for k in range(count) if real[k]] or [(0, count)]
    arc = arc_lengths(points)
    cuts = [0]
    for share in np.arange(1, FINGER_BONES) / FINGER_BONES:
        best = int(np.argmin(np.abs(arc - share * arc[-1])))
        cuts.append(min(max(best, cuts[-1] + 1), count - (FINGER_BONES - len(cuts))))
    cuts.append(count)
    return list(zip(cuts, cuts[1:]))


def _split_middles(names, heads, tails, parents, roles, places):
    """A humanoid's ``UpLeg`` (``Arm``) without a ``Leg`` (``ForeArm``) after it, a leg too short for the skeleton to
    bend it (a plush toy's stubby legs), split at the named knee (elbow) in ``places`` when that lies well along it
    (``SPLIT_SHARES``, within a quarter of its length of it), as ``MIDDLES`` says: the new bone runs on to the old
    end and carries what hung there (a foot; a hand and its fingers). ``_completed_ends`` then adds what it lacks."""
    names, heads, tails, parents, roles = list(names), heads.copy(), tails.copy(), list(parents), list(roles)
    for limb in range(len(names)):
        for word, next_word, joint, carried in MIDDLES:
            parsed = _parsed(names[limb], word, ("Left", "Right"))
            if parsed is None or _named(parsed[0], next_word, parsed[1]) in names:
                continue
            side_word, suffix = parsed
            letter = side_word[0]
            point = places.get((joint, letter, None))
            if point is None or not _well_along(point, heads[limb], tails[limb], SPLIT_SHARES):
                continue
            point, tail = np.asarray(point, dtype=np.float64), tails[limb].copy()
            names.append(_named(side_word, next_word, suffix))
            heads, tails = np.vstack([heads, point]), np.vstack([tails, tail])
            tails[limb] = point
            parents.append(limb)
            roles.append(BoneRole(joint, letter))
            added = len(names) - 1
            for child in range(added):
                if parents[child] == limb and roles[child].role in carried:
                    parents[child] = added
    return names, heads, tails, parents, roles


def _parsed(name, word, sides):
    """(side word, suffix) of a game bone ``name`` like ``LeftForeArm_2`` (``LeftForeArm``, ``_2`` numbering a
    second pair of arms) that is a ``word`` with one of the ``sides`` before it ("" for none), else None."""
    stem, _, suffix = name.partition("_")
    side_word = stem[:-len(word)]
    return (side_word, suffix) if stem.endswith(word) and side_word in sides else None


def _named(side_word, word, suffix):
    """The game bone name of a ``word`` on a side (``_parsed``), with the suffix of the bone it was read from."""
    return f"{side_word}{word}{'_' + suffix if suffix else ''}"


def _well_along(point, head, tail, shares):
    """Whether ``point`` lies along the bone from ``head`` to ``tail``: between the ``shares`` (low, high) of its
    length along it, within a quarter of its length of it."""
    along = tail - head
    length = float(np.linalg.norm(along))
    share = float((point - head) @ along) / max(length ** 2, 1e-300)
    return shares[0] < share < shares[1] and \
        segment_distances(np.asarray(point)[None], head[None], tail[None])[0, 0] <= 0.25 * length


def _completed_ends(names, heads, tails, parents, roles, places, vertices, faced):
    """A ``Hand`` on every forearm, ``Foot`` on every shin (``Leg``) and ``Head`` on a ``Neck`` that ends without
    one (fingers forking at the wrist, a leg ending at the ground, a neck bone running into a round head, a cow's front
    leg ending at the hoof, a bird's one neck bone; a numbered limb, ``LeftForeArm_2``, keeps its end), as
    ``ENDS`` says: from the named wrist (ankle, head joint) in ``places`` when it lies along the bone, which then ends
    there, else from the bone's end; to the hand's reach (the ball of the foot, else its toes' tip; the head's top)
    when that lies beyond, else on along the bone. A foot the mesh shows ahead of the ankle (``core.facing.foot_ahead``,
    the ``vertices`` and the character's facing ``faced``) runs there instead, to its ball, and a ``ToeBase`` on to
    its tip. The bone's fingers (toes; jaw and ears) hang from it. Game engines' humanoids, animal rigs and mocap need
    all three."""
    names, heads, tails, parents, roles = list(names), heads.copy(), tails.copy(), list(parents), list(roles)
    for limb in range(len(names)):
        for word, end_word, starts, ends, carried in ENDS:
            parsed = _parsed(names[limb], word, ("Left", "Right", ""))
            if parsed is None or parsed[1] or parsed[0] + end_word in names:
                continue  # the named places are the first pair's: a numbered limb (a spur, a second arm) keeps its end
            side_word = parsed[0]
            end_name = side_word + end_word
            letter = side_word[:1] or None
            head, tail = heads[limb], tails[limb]
            along = tail - head
            bone_length = float(np.linalg.norm(along))
            start = tail
            for key in starts:
                point = places.get((key, letter, None))
                if point is not None and _well_along(point, head, tail, END_STARTS):
                    start = np.asarray(point, dtype=np.float64)
            finish = start + END_SHARE * along
            for key in ends:
                point = places.get((key, letter, None))
                if point is not None and np.linalg.norm(point - start) > 0.1 * bone_length:
                    finish = np.asarray(point, dtype=np.float64)
                    break
            foot = foot_ahead(vertices, start, faced, bone_length) if end_word == "Foot" else None
            if foot is not None:
                finish = foot[0]
            tails[limb] = start
            names.append(end_name)
            heads, tails = np.vstack([heads, start]), np.vstack([tails, finish])
            end = len(names) - 1
            parents.append(limb)
            roles.append(BoneRole(end_word.lower(), letter))
            toe_name = side_word + "ToeBase"
            if foot is not None and toe_name not in names:
                names.append(toe_name)
                heads, tails = np.vstack([heads, foot[0]]), np.vstack([tails, foot[1]])
                parents.append(end)
                roles.append(BoneRole("toe", letter))
            for child in range(end):
                if parents[child] == limb and roles[child].role in carried:
                    parents[child] = end
    return names, heads, tails, parents, roles


def _twin_parents(names, heads, tails, parents):
    """``parents`` with each ``Left…``/``Right…`` pair hanging from one bone or from twin bones: where the two hang
    from bones that are no twins (their joint held by two game bones), both take the left one's parent or both the
    right one's (its twin for the other side), whichever lies nearer their heads, unless that makes a loop."""
    parents = list(parents)
    pairs = _twin_pairs(names)
    twin_of = {**dict(pairs), **{right: left for left, right in pairs}}

    def mirrored(bone):  # the bone's twin, itself when unsided, None when it has no twin
        return twin_of.get(bone, None if names[bone].startswith(("Left", "Right")) else bone)

    def ancestors(bone):
        found = {bone}
        while parents[bone] >= 0:
            bone = parents[bone]
            found.add(bone)
        return found

    for left, right in pairs:
        if parents[left] < 0 or parents[right] < 0 or mirrored(parents[left]) == parents[right]:
            continue
        options = [(parents[left], mirrored(parents[left])), (mirrored(parents[right]), parents[right])]
        options = [(a, b) for a, b in options if a is not None and b is not None
                   and left not in ancestors(a) and right not in ancestors(b)]
        if options:
            gap = [float(segment_distances(heads[[left]], heads[[a]], tails[[a]])[0, 0]
                         + segment_distances(heads[[right]], heads[[b]], tails[[b]])[0, 0]) for a, b in options]
            parents[left], parents[right] = options[int(np.argmin(gap))]
    return parents


def _twin_pairs(names):
    """(left, right) indices of every ``Left…`` bone in ``names`` and its ``Right…`` twin."""
    index = {name: k for k, name in enumerate(names)}
    return [(k, index["Right" + name[4:]]) for k, name in enumerate(names)
            if name.startswith("Left") and "Right" + name[4:] in index]


def _mirrored_twins(names, heads, tails, plane, size):
    """Heads and tails with every ``Left…``/``Right…`` pair that mirrors within ``TWIN_TOLERANCE`` of ``size`` made
    exact mirror images (their mean across the plane): the method's mirror plane, else the plane fitted to the
    pairs."""
    pairs = _twin_pairs(names)
    if not pairs:
        return heads, tails
    left = np.concatenate([heads[[a for a, _ in pairs]], tails[[a for a, _ in pairs]]])
    right = np.concatenate([heads[[b for _, b in pairs]], tails[[b for _, b in pairs]]])
    if plane is not None:
        normal, offset = np.asarray(plane.normal, float), float(plane.offset)
    else:
        normal = (left - right).sum(axis=0)
        if not np.linalg.norm(normal) > 0:
            return heads, tails
        normal /= np.linalg.norm(normal)
        offset = float(np.mean(0.5 * (left + right) @ normal))

    def reflect(points):
        return points - 2 * ((points @ normal) - offset)[..., None] * normal

    heads, tails = heads.copy(), tails.copy()
    for a, b in pairs:
        for points in (heads, tails):
            image = reflect(points[b])
            if np.linalg.norm(points[a] - image) <= TWIN_TOLERANCE * size:
                points[a] = 0.5 * (points[a] + image)
                points[b] = reflect(points[a])
    return heads, tails
