"""A body with legs hangs from its pelvis: the joint its legs leave the trunk at is the root, as artists rig it and as
Blender's tools expect, so bending the spine leaves the legs be and turning the neck leaves the body be."""
from collections import deque
from dataclasses import replace

import numpy as np

from .skeleton import Skeleton

LEG_STARTS = ("hips", "thigh")  # the roles a leg (a quadruped's hind leg) begins with
SAME_POINT = 1e-9  # bone ends this close (a share of the skeleton's size) are one joint


def pelvis(skeleton):
    """(bone, end) of the pelvis of ``skeleton`` (with roles; ``end`` 0 for the bone's head, 1 for its tail): the
    end of the unsided bone every leg hangs from where they all start. None when that is the root's head already,
    or when there is no such one place (no legs, legs hanging from different bones or off their ends)."""
    roles = skeleton.roles
    if roles is None:
        return None
    starts = [bone for bone, role in enumerate(roles) if role.side and role.role in LEG_STARTS and role.index == 0
              and skeleton.parents[bone] >= 0 and not roles[skeleton.parents[bone]].side]
    bases = {int(skeleton.parents[bone]) for bone in starts}
    if len(starts) < 2 or len(bases) != 1:
        return None
    base = bases.pop()
    tolerance = SAME_POINT * skeleton.extent
    for end, points in ((1, skeleton.tails), (0, skeleton.heads)):
        if np.linalg.norm(skeleton.heads[starts] - points[base], axis=1).max() <= tolerance:
            return None if end == 0 and skeleton.parents[base] < 0 else (base, end)
    return None


def rerooted(skeleton, bone, end):
    """``skeleton`` rooted at an end of ``bone`` (0 its head, 1 its tail).

    Bones meet at joints: a bone's head is its parent's tail or head where it lies within ``SAME_POINT``, else a
    joint of its own hanging from the nearer of them. The bones on the way from the new root joint to the old one
    turn round (head and tail swap) and trade places in the bone order end for end, keeping the names of the places
    (the new root takes the first one's: ``trunk.00`` when the trunk turns), parents still first. A turned bone, the
    old root, a bone that started where its turned parent ended and one that started where the old root did (a
    front leg beside the neck) hang from the bone now ending there; every other bone keeps its parent. Of the bones
    starting at the new root joint, the one on the way to the old root (else ``bone``) is the root and the others
    hang from it. Stages, timings and parameters are shared, roles go with their bones (a bone keeps its role
    whichever way it runs), and the body plan's places on turned bones are measured from their new heads."""
    count, parents = len(skeleton), skeleton.parents.tolist()
    tolerance = SAME_POINT * skeleton.extent
    head_node, tail_node = [0] * count, [0] * count
    neighbours = [[] for _ in range(2 * count)]  # node -> (node, bone or -1 for a link)
    for child in _parents_first(parents):
        tail_node[child] = count + child
        parent = parents[child]
        head_node[child] = child
        if parent >= 0:
            ends = ((tail_node[parent], skeleton.tails[parent]), (head_node[parent], skeleton.heads[parent]))
            gaps = [np.linalg.norm(skeleton.heads[child] - point) for _, point in ends]
            nearer = ends[int(np.argmin(gaps))][0]
            if min(gaps) <= tolerance:
                head_node[child] = nearer
            else:
                neighbours[child].append((nearer, -1))
                neighbours[nearer].append((child, -1))
        neighbours[head_node[child]].append((tail_node[child], child))
        neighbours[tail_node[child]].append((head_node[child], child))
    start = (head_node, tail_node)[end][bone]
    arriving = {start: None}  # node -> the edge (bone or -1) it is reached by from the new root joint
    previous = {start: None}
    queue = deque([start])
    while queue:
        node = queue.popleft()
        for other, edge in neighbours[node]:
            if other not in arriving:
                arriving[other], previous[other] = edge, node
                queue.append(other)
    reached = [b for b in range(count) if head_node[b] in arriving]  # the new root's island
    old_root = next(b for b in reached if parents[b] < 0)
    way, node = [], head_node[old_root]  # the bones from the new root joint to the old one: they turn
    while node != start:
        if arriving[node] >= 0:
            way.append(arriving[node])
        node = previous[node]
    way.reverse()
    turned = set(way)
    heads, tails = skeleton.heads.copy(), skeleton.tails.copy()
    heads[way], tails[way] = skeleton.tails[way], skeleton.heads[way]
    root = old_root if not way else way[0] if tail_node[way[0]] == start else bone

    def holder(node):  # the bone now ending at a joint (up the links of joints of their own), None at the root
        while node != start and arriving[node] < 0:
            node = previous[node]
        return None if node == start else arriving[node]

    new_parents = list(parents)
    for b in reached:
        if b == root:
            new_parents[b] = -1
        elif b in turned or b == old_root or (parents[b] in turned and head_node[b] == tail_node[parents[b]]) or (
                parents[b] == old_root and head_node[b] == head_node[old_root]):
            held = holder(tail_node[b] if b in turned else head_node[b])
            new_parents[b] = root if held is None else held
    slots = list(range(count))  # the turned bones on the way trade places end for end, the new root's first
    for place, old in zip(sorted(way), way):
        slots[place] = old
    slot_of = {old: place for place, old in enumerate(slots)}
    order = _parents_first([slot_of.get(new_parents[old], -1) for old in slots])  # names go with their places
    old_of = [slots[place] for place in order]
    new_of = {old: k for k, old in enumerate(old_of)}
    plan = skeleton.body_plan
    if plan is not None:
        plan = replace(plan, joints={key: tuple((new_of[b], 1.0 - share if b in turned else share, weight)
                                                for b, share, weight in place)
                                     for key, place in plan.joints.items()})
    moved = Skeleton([skeleton.names[place] for place in order], heads[old_of], tails[old_of],
                     [-1 if new_parents[old] < 0 else new_of[new_parents[old]] for old in old_of], skeleton.stages,
                     roles=None if skeleton.roles is None else [skeleton.roles[old] for old in old_of], body_plan=plan)
    moved.timings, moved.params = skeleton.timings, skeleton.params
    return moved


def _parents_first(parents):
    """Bone indices with every parent before its children, each bone as early in index order as its parent allows
    (an order with parents first already stays)."""
    children = {}
    for child, parent in enumerate(parents):
        children.setdefault(parent, []).append(child)
    order, waiting = [], list(children.get(-1, []))
    while waiting:
        bone = min(waiting)
        waiting.remove(bone)
        order.append(bone)
        waiting += children.get(bone, [])
    return order
