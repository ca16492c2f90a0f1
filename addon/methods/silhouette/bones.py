"""Bone building: bones along the placed chains of each island, hidden limbs hung from the bones they reach, and
their names."""
import numpy as np

from ...core.graphs import components
from ...core.joints import chain_joints, symmetric_joints
from ...core.mirror import mirror_chain_pairs, mirror_completed
from ...core.naming import bone_names
from ...core.polyline import arc_lengths, nearest_on_segments, point_at, segment_distances
from .depth import is_across
from .outline import loop_edges


class BoneBuilder:
    """Accumulates bones island by island; the first island's trunk holds the single root bone. Chains are cut as
    ``cutting`` says. With a ``symmetry`` (None without a mirror plane) twins are named for their sides; across an
    exact one, the mesh's mirror plane, they get mirror-image joints and a limb its longer twin's image, so a
    symmetric mesh gets a symmetric rig; across a plane a body only roughly mirrors about, just one bone count.
    ``tuning``: the method's (hanging hidden limbs)."""

    def __init__(self, cutting, symmetry, tuning):
        self.cutting, self.symmetry, self.tuning = cutting, symmetry, tuning
        self.exact = symmetry is not None and symmetry.exact
        self.bone_length = cutting.bone_length
        self.heads, self.tails, self.parents = [], [], []
        self.chain_of_bone, self.index_in_chain = [], []
        self.lines = []  # one polyline per chain, indexed by chain number
        self.across = set()  # the bones across the depth (``depth.is_across``): a leg's, no limb hangs from them

    def add_island(self, root_point, placed, sil=None):
        """Bones along the placed chains of one island; the widest chain leaving the root becomes its trunk, the
        widest on the mirror plane when one leaves it there (a spine, not an arm, carries the body). Across a plane,
        a chain on it never hangs from a chain off it (``_on_plane_parents``), across the mesh's own plane twins
        that leave the middle leave it together (``_twins_together``), and when every chain leaving a root on the
        mesh's plane lies off it, the body gets a chain on the plane for them to hang from (``_stem``, with the
        island's view ``sil``)."""
        from_start = set()  # chains hanging from their parent chain's first bone (by default: from its last)
        if self.symmetry is not None:
            placed = self._on_plane_parents(placed)
            if self.exact:
                placed = self._forks_mirrored(placed)
                placed = self._twins_together(placed)
                if sil is not None:
                    placed, from_start = self._stem(root_point, placed, sil)
        roots = [i for i, (_, parent, _) in enumerate(placed) if parent < 0]
        on_plane = {i: self.symmetry is not None and self.symmetry.side(placed[i][0]) == 0 for i in roots}
        trunk = max(roots, key=lambda i: (on_plane[i], placed[i][2].mean()))
        order = _parents_first([trunk] + [i for i in range(len(placed)) if i != trunk], placed)
        inner = {parent for _, parent, _ in placed}
        across = [is_across(line, widths) for line, _, widths in placed]
        joints = self._joints([(line, widths, i not in inner) for i, (line, _, widths) in enumerate(placed)], across)
        if not self.heads and not across[trunk] and (on_plane[trunk] or self.symmetry is None):
            joints[trunk] = self._trunk_joints(placed[trunk], joints[trunk], trunk not in inner)
        attach, _ = self.attachment(root_point)
        last_bone, first_bone = {}, {}
        for i in order:
            line, parent, _ = placed[i]
            if parent >= 0:
                up = (first_bone if i in from_start else last_bone)[parent]
            elif i == trunk:
                up = attach
            else:
                up = first_bone[trunk]
            added = self._add_chain(line, joints[i], up)
            first_bone[i], last_bone[i] = (added[0], added[-1]) if added else (up, up)
            if across[i]:
                self.across.update(added)

    def _trunk_joints(self, placed, joints, leaf):
        """The joints of the body's trunk (the first island's, with no twin): at least ``trunk_bones`` bones, or
        ``max_bones`` when that is fewer."""
        line, _, widths = placed
        least = self.tuning.trunk_bones
        if self.cutting.max_bones > 0:
            least = min(least, self.cutting.max_bones)
        if len(joints) - 1 >= least:
            return joints
        return chain_joints(line, self.cutting, widths, leaf, min_bones=least)

    def _on_plane(self, line):
        """Whether the chain ``line`` lies on the builder's mirror plane (False without one)."""
        return self.symmetry is not None and self.symmetry.side(line) == 0

    def _on_plane_parents(self, placed):
        """The placed chains with each chain on the plane that hangs from a chain off it (a head whose branch the
        triangulation put on an arm near the shoulders) hung instead from the nearest ancestor on the plane (or the
        root), starting where its sided ancestors leave that one: raising an arm must not carry the head."""
        side = [self.symmetry.side(line[1:]) for line, _, _ in placed]  # its own course, after it leaves its parent
        moved = list(placed)
        for i, (line, parent, widths) in enumerate(placed):
            if side[i] != 0 or parent < 0 or side[parent] == 0:
                continue
            start = placed[parent][0][0]
            while parent >= 0 and side[parent] != 0:
                start, parent = placed[parent][0][0], placed[parent][1]
            moved[i] = (np.vstack([start, line[1:]]), parent, widths)
        return moved

    def _forks_mirrored(self, placed):
        """The placed chains with every fork that one side alone has mirrored onto the other: a chain off the plane
        with no mirror twin (a stem) whose children, run on from its start, each have one among the chains that
        leave the same place on the other side. The triangulation of a mirror-image outline may fork two limbs a
        little way out on one side (a bird's wing and the tuft beside it, from a short stem) and at the middle on the
        other; that side gets the images of the stem and its children in their stead (the mesh mirrors exactly), so
        both sides carry the same chains and twins are named alike."""
        lines = [line for line, _, _ in placed]
        sides = [self.symmetry.side(line, by_tip=True) for line in lines]
        paired = {k for i, j in mirror_chain_pairs(lines, self.symmetry)
                  if self.symmetry.whole_twins(lines[i], lines[j]) for k in (i, j)}
        moved, added, taken = list(placed), [], set()
        for stem, (line, parent, widths) in enumerate(placed):
            children = [k for k, (_, up, _) in enumerate(placed) if up == stem]
            if sides[stem] == 0 or stem in paired or len(children) < 2:
                continue
            others = [j for j, (_, up, _) in enumerate(placed)
                      if up == parent and j not in taken and j not in paired and sides[j] == -sides[stem]]
            twins = {k: next((j for j in others if self.symmetry.whole_twins(np.vstack([line, lines[k][1:]]),
                                                                             lines[j])), None) for k in children}
            if None in twins.values() or len(set(twins.values())) < len(children):
                continue
            image = len(placed) + len(added)
            added.append((self.symmetry.reflect(line), parent, widths))
            for k, j in twins.items():
                moved[j] = (self.symmetry.reflect(lines[k]), image, placed[k][2])
                taken.add(j)
        return moved + added

    def _twins_together(self, placed):
        """The placed chains with mirror twins that start apart, one of them on the plane, both starting there, from
        that twin's parent: the triangulation splits a junction on the plane into two (a leg leaving the root, its
        twin the end of a short trunk bone), and twins hanging from two places do not mirror when posed."""
        lines = [line for line, _, _ in placed]
        moved = list(placed)
        axis, offset = self.symmetry.plane
        for pair in mirror_chain_pairs(lines, self.symmetry):
            near, far = sorted(pair, key=lambda i: abs(lines[i][0, axis] - offset))
            start = lines[near][0]
            if (self.symmetry.side(start[None]) != 0
                    or np.linalg.norm(lines[far][0] - self.symmetry.reflect(start)) <= 1e-9 * self.bone_length):
                continue
            if _descends(placed[near][1], far, moved):
                continue  # hanging it there would hang it from itself
            line, _, widths = placed[far]
            moved[far] = (np.vstack([start, line[1:]]), placed[near][1], widths)
        return moved

    def _stem(self, root_point, placed, sil):
        """(placed chains, the ones among them that hang from their parent chain's first bone): with a body chain
        first when the root lies on the mirror plane and every chain leaving it lies off the plane (a penguin's or a
        bat's round body whose axis is a fan: only wings and ears survive pruning). The chain runs on the plane from
        the root, the way those chains leave it on average, to the outline (``_body_line``), in pieces: each pair of
        twins leaves it level with where the pair leaves the root's disc (``_levels``), from the first bone of the
        piece that starts there (a bat's ears turn with its head), so no twin hangs from its twin."""
        roots = [i for i, (_, parent, _) in enumerate(placed) if parent < 0]
        if self.symmetry.side(root_point[None]) != 0 or any(self._on_plane(placed[i][0]) for i in roots):
            return placed, set()
        along = np.cross(np.eye(3)[self.symmetry.plane[0]], sil.direction)  # the plane's line in the view
        if np.linalg.norm(along) < 1e-9:
            return placed, set()  # the view looks straight across the plane: it sees no line of it
        radius = max(placed[i][2][0] for i in roots)
        exits = {i: point_at(placed[i][0], arc_lengths(placed[i][0]), radius) for i in roots}  # off the disc
        away = np.mean([exits[i] - root_point for i in roots], axis=0)
        along *= (1.0 if along @ away >= 0 else -1.0) / np.linalg.norm(along)
        line, widths = _body_line(sil, root_point, along, radius)
        if len(line) < 2:
            return placed, set()
        level = self._levels({i: (exits[i] - root_point) @ along for i in roots}, placed, sil.cell, len(line))
        bounds = [0] + sorted({at for at in level.values() if 0 < at < len(line) - 1}) + [len(line) - 1]
        pieces = [(line[a:b + 1], k - 1, np.r_[widths[a] if k == 0 else 0.0, widths[a + 1:b + 1]])  # 0: no disc
                  for k, (a, b) in enumerate(zip(bounds[:-1], bounds[1:]))]                        # to leave
        moved, from_start = [], set()
        for i, (chain, parent, chain_widths) in enumerate(placed):
            at = level.get(i, 0)
            if at == 0:
                moved.append((chain, parent + len(pieces) if parent >= 0 else -1, chain_widths))
                continue
            beyond = arc_lengths(chain) > radius
            beyond[-1] = True  # a chain ending within the disc keeps its tip
            piece = bounds.index(at)  # the piece starting there (the last one, ending there, at the outline)
            if piece < len(pieces):
                from_start.add(len(pieces) + i)
            moved.append((np.vstack([line[at], chain[beyond]]), min(piece, len(pieces) - 1),
                          np.r_[widths[at], chain_widths[beyond]]))
        return pieces + moved, from_start

    def _levels(self, along_line, placed, cell, count):
        """Root chain -> the point of the body chain (``count`` points a ``cell`` apart) it leaves from, given how
        far along that chain each leaves the root's disc (``along_line``): twins level at their mean, none closer
        than the joint spacing to another level or the ends (no stub bones), and all at the root when some leave
        the other way (a fan open all round, an octopus seen from above: the body chain's way is no body's)."""
        chains = list(along_line)
        along_line = dict(along_line)
        for pair in mirror_chain_pairs([placed[i][0] for i in chains], self.symmetry):
            twins = [chains[k] for k in pair]
            along_line.update(dict.fromkeys(twins, np.mean([along_line[i] for i in twins])))
        least = self.cutting.tuning.joint_spacing * self.bone_length
        if min(along_line.values()) < -least:
            return dict.fromkeys(chains, 0)
        level = {i: int(np.clip(np.rint(at / cell), 0, count - 1)) for i, at in along_line.items()}
        kept = 0
        for at in sorted(set(level.values())):
            near = kept if (at - kept) * cell < least else count - 1 if (count - 1 - at) * cell < least else at
            level.update({i: near for i in level if level[i] == at})
            kept = near
        return level

    def add_limbs(self, limbs, views):
        """Bones along extra chains, (polyline, half-widths) each, hung from the nearest bone already there that their
        start reaches within the mesh as all the silhouettes ``views`` see it (the primary one and the one the limbs
        come from), on the mirror plane for a chain starting on it (ears, not a leg beside them); a chain starting
        far from that bone (a foot below a leg too stubby to show) is extended back along the path to it, so the leg
        between them gets bones of its own, and mirror pairs stay mirror pairs.
        Limbs that far from one bone that start and meet it together (``_sharing``: a pair of ears, horns on a
        neck) share that extension: one chain from the middle of those points to the middle of their starts, from
        which each hangs (through a bone to its own start when apart), instead of bones lying on each other. Which
        limbs share does not depend on their order, so mirror pairs stay mirror pairs."""
        if not limbs:
            return
        if self.exact:
            limbs = mirror_completed(self._one_sided(limbs), self.symmetry)
        chains, ups, meets_of = [], [], {}  # meets_of: limb number -> where it meets its bone, for the limbs to extend
        for line, widths in limbs:  # every limb hangs from bones already there, none from another (a right foot
            up, meets = self.attachment(line[0], views, self._on_plane(line[:1]))  # from the left one's extension)
            if meets is not None and np.linalg.norm(line[0] - meets) > self.tuning.bridge_reach * self.bone_length:
                meets_of[len(chains)] = meets
            chains.append((line, widths, True))
            ups.append(up)
        if self.symmetry is not None:
            self._twin_meets(meets_of, ups, [line for line, _, _ in chains])
        ends = {}  # limb number -> the bridge chain it hangs from
        for members in self._sharing(meets_of, ups, [line[0] for line, _, _ in chains]):
            meets = np.mean([meets_of[k] for k in members], axis=0)
            shared = len(members) > 1
            start = np.mean([chains[k][0][0] for k in members], axis=0) if shared else meets
            for k in members:
                line, widths, _ = chains[k]
                if np.linalg.norm(line[0] - start) > 1e-9 * self.bone_length:
                    chains[k] = (np.vstack([start, line]), np.r_[0.0, widths], True)  # 0: no disc to leave
            if shared:
                ends.update(dict.fromkeys(members, len(chains)))
                chains.append((np.vstack([meets, start]), np.zeros(2), False))
                ups.append(ups[members[0]])
        joints = self._joints(chains, [False] * len(chains))
        last_bone = {}
        for c in sorted(range(len(chains)), key=lambda c: c in ends):  # bridge chains before the limbs they carry
            line, along = chains[c][0], joints[c]
            up = last_bone[ends[c]] if c in ends else ups[c]
            added = self._add_chain(line, along, up)
            last_bone[c] = added[-1] if added else up

    def _one_sided(self, limbs):
        """The (polyline, half-widths) ``limbs`` without those running from one side of the mirror plane to the other
        (start and tip each beyond the twin tolerance), when that leaves any: a view's copy of a limb that began in
        its twin's part (two legs seen from the side, merged at the hips). The twin's image stands for it."""
        side = self.symmetry.side
        kept = [(line, widths) for line, widths in limbs if side(line[:1]) * side(line[-1:]) >= 0]
        return kept or limbs

    def _twin_meets(self, meets, ups, lines):
        """Make the points where mirror twin limbs to extend meet their bone (``meets``, limb number -> point; the
        limbs' ``ups`` and ``lines``) mirror images, their mean, when both meet one bone within the twin tolerance of
        each other's image: an extension starts where its limb meets the bone, and twins keep their first joints
        (``symmetric_joints``), so unlike meeting points would never mirror."""
        for i, j in mirror_chain_pairs(lines, self.symmetry):
            if i in meets and j in meets and ups[i] == ups[j] and (
                    np.linalg.norm(meets[i] - self.symmetry.reflect(meets[j])) <= self.symmetry.tolerance):
                meets[i] = (meets[i] + self.symmetry.reflect(meets[j])) / 2
                meets[j] = self.symmetry.reflect(meets[i])

    def _sharing(self, meets, ups, starts):
        """The limbs to extend (the keys of ``meets``, where each meets its bone) in groups that share one
        extension: linked when they hang from the same bone, meet it within half a bone length of each other, and
        start within half a bone length or half the longer extension (two extensions that part by less than about
        30° lie on each other: a fox's ears, which start on its head far from the chest); a linked group is kept only
        when every two of its limbs are linked (else each goes alone), so the groups do not depend on the limbs'
        order."""
        share = self.tuning.share_reach
        limbs = list(meets)

        def linked(a, b):
            extension = max(np.linalg.norm(starts[a] - meets[a]), np.linalg.norm(starts[b] - meets[b]))
            return (ups[a] == ups[b] and np.linalg.norm(meets[a] - meets[b]) <= share * self.bone_length
                    and np.linalg.norm(starts[a] - starts[b]) <= share * max(self.bone_length, extension))

        pairs = [(i, j) for i in range(len(limbs)) for j in range(i) if linked(limbs[i], limbs[j])]
        labels = components(len(limbs), np.array(pairs, dtype=np.int64).reshape(-1, 2))
        groups = []
        for label in np.unique(labels):
            members = [limbs[i] for i in np.flatnonzero(labels == label)]
            whole = all(linked(a, b) for a in members for b in members)
            groups += [members] if whole else [[k] for k in members]
        return groups

    def _joints(self, chains, across):
        """Joints along each of the (polyline, half-widths, is a leaf) ``chains``, mirror twins made symmetric; a
        bone ``across`` the depth is one bone."""
        cut = [chain for chain, one in zip(chains, across) if not one]
        if self.symmetry is None:
            joints = iter([chain_joints(line, self.cutting, widths, leaf) for line, widths, leaf in cut])
        else:
            joints = iter(symmetric_joints(cut, self.cutting, self.symmetry))
        return [line.copy() if one else next(joints) for (line, _, _), one in zip(chains, across)]

    def _add_chain(self, line, joints, up):
        """Bones between consecutive ``joints`` of one chain, the first hanging from bone ``up``; returns the
        indices of the bones added (none where the joints coincide)."""
        chain = len(self.lines)
        self.lines.append(line)
        added = []
        for k in range(len(joints) - 1):
            if np.linalg.norm(joints[k + 1] - joints[k]) <= 1e-9 * self.bone_length:
                continue
            self.heads.append(joints[k])
            self.tails.append(joints[k + 1])
            self.parents.append(up)
            self.chain_of_bone.append(chain)
            self.index_in_chain.append(k)
            up = len(self.heads) - 1
            added.append(up)
        return added

    def add_blob(self, sil, point2d, radius):
        """An island whose axis is a single node (a round speck): one short bone through it, pointing up."""
        front, back = sil.depth(point2d[None])
        depth = 0.5 * (front[0] + back[0]) if not np.isnan(front[0]) else 0.0
        centre = sil.lift(point2d[None], [depth])[0]
        half = max(radius, sil.cell) * sil.v
        ends = np.array([centre - half, centre + half])
        self._add_chain(ends, ends, self.attachment(centre)[0])

    def attachment(self, point, views=(), on_plane=False):
        """(bone, where a path from ``point`` meets it): the bone nearest ``point``, or -1 before the first island,
        met nowhere in particular (None), never a bone across the depth (it belongs to its leg); ``on_plane``: of the
        bones on the mirror plane, if any (a head found in a perpendicular view hangs from the spine, not from an arm
        near it). With silhouettes ``views``, the nearest bone that a straight path from ``point`` reaches within the
        mesh as each of them sees it (``Silhouette.encloses``, sampled every grid cell, up to ``path_slack`` outside:
        a path may graze the surface, but a foot beside a hanging hand belongs to the body, not the hand), and the
        point the path meets it at; the nearest bone, met nowhere (None), when no path to the ``path_candidates``
        nearest stays in (a soup of triangles strewn at random has a thousand bones at a small ``bone_length``, and
        paths through it rarely stay in)."""
        if not self.heads:
            return -1, None
        targets = nearest_on_segments(point[None], np.array(self.heads), np.array(self.tails))[0]
        distance = np.linalg.norm(targets - point, axis=1)
        if len(self.across) < len(distance):
            distance[list(self.across)] = np.inf
        if on_plane:
            sided = np.array([not self._on_plane(self.lines[chain]) for chain in self.chain_of_bone])
            if not sided.all():
                distance = np.where(sided, np.inf, distance)
        order = np.argsort(distance, kind="stable")
        if views:
            cell = min(view.cell for view in views)
            for bone in order[:self.tuning.path_candidates]:
                if not np.isfinite(distance[bone]):
                    break  # the bones left are ones it may not hang from (sorted last)
                count = int(np.clip(np.ceil(distance[bone] / cell), 1, self.tuning.path_samples))
                path = point + (np.arange(1, count + 1) / (count + 1))[:, None] * (targets[bone] - point)
                outside = np.zeros(count, bool)
                for view in views:
                    outside |= ~view.encloses(path, view.cell)
                if outside.sum() * distance[bone] / (count + 1) <= self.tuning.path_slack * self.bone_length:
                    return int(bone), targets[bone]
        return int(order[0]), None

    def arrays(self):
        return np.array(self.heads), np.array(self.tails), np.array(self.parents, dtype=np.int64)

    def names(self):
        """The bones' names (``bone_names``), mirror-suffixed across the builder's symmetry."""
        return bone_names(self.chain_of_bone, self.index_in_chain, self.lines, self.symmetry)


def _body_line(sil, root_point, along, radius):
    """Points a grid cell apart from ``root_point`` the way ``along`` (in the view ``sil``), each in the middle of
    the depth interval holding the one before (a head leaning back), to where none does (the outline, or the edge
    of an octopus's mantle above its arms); and the body's half-width at each: the outline's distance, as on the
    axis (the root's disc ``radius`` at the first)."""
    start, depth = sil.project(root_point[None])
    step = sil.project(root_point[None] + sil.cell * along[None])[0] - start
    count = int(np.ceil(np.ptp(np.concatenate(sil.loops), axis=0).max() / sil.cell))  # across the outline
    line2d = start + np.arange(count + 1)[:, None] * step
    outside = np.flatnonzero(np.isnan(sil.depth(line2d[1:])[0])) + 1  # the outline first (depths are cheaper than
    line2d = line2d[:outside[0] if len(outside) else len(line2d)]      # layers); the root is inside
    depths = [float(depth[0])]
    for layer in sil.layers(line2d[1:]):
        holding = layer[(layer[:, 0] <= depths[-1]) & (layer[:, 1] >= depths[-1])]
        if not len(holding):
            break
        depths.append(float(holding[0].mean()))
    line2d = line2d[:len(depths)]
    reach = max(1, int(radius / sil.cell))  # a part's bumps are no bends of the body: smoothed over its disc
    padded = np.pad(np.array(depths), reach, mode="edge")
    depths = np.r_[depth[0], np.convolve(padded, np.full(2 * reach + 1, 1.0 / (2 * reach + 1)), mode="valid")[1:]]
    outline = loop_edges(sil.loops)
    widths = np.concatenate([segment_distances(line2d[k:k + 64], *outline).min(axis=1)
                             for k in range(0, len(line2d), 64)])  # in blocks: a fine outline has many segments
    widths[0] = radius
    return sil.lift(line2d, depths), widths


def _parents_first(order, placed):
    """``order`` (placed chain indices) with every chain moved after its parent, the rest as they were: moving
    twins together (``_twins_together``) may hang a chain from one placed after it."""
    result, done, waiting = [], set(), list(order)
    while waiting:
        for i in waiting:
            if placed[i][1] < 0 or placed[i][1] in done:
                result.append(i)
                done.add(i)
        left = [i for i in waiting if i not in done]
        if len(left) == len(waiting):
            raise ValueError("placed chains hang from each other in a loop")
        waiting = left
    return result


def _descends(chain, ancestor, placed):
    """Whether placed ``chain`` (-1: the root) is ``ancestor`` or hangs from it, directly or not."""
    while chain >= 0:
        if chain == ancestor:
            return True
        chain = placed[chain][1]
    return False
