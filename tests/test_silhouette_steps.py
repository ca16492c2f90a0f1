"""The silhouette method's steps and the core pieces it builds on, on hand-made inputs: spur pruning, rooting a path,
counting stacked parts (``methods.silhouette``); joints along a chain, the mirror plane, mirror twins and their
names (``core.joints``, ``core.mirror``, ``core.naming``)."""
import numpy as np
import pytest

from meshes import box, combine
from rigger import silhouette
from rigger.core.arrays import column_bounds
from rigger.core.graphs import chains_of
from rigger.core.joints import Cutting, chain_joints, symmetric_joints
from rigger.core.mirror import (Symmetry, mirror_chain_pairs, mirror_completed, mirror_plane, mirrored,
                                 sided_symmetry, symmetric_planes)
from rigger.core.naming import bone_names
from rigger.core.polyline import arc_lengths, segment_distances
from rigger.methods.silhouette import depth
from rigger.methods.silhouette.chordal import ChordalAxis
from rigger.methods.silhouette.outline import loop_edges
from rigger.methods.silhouette.tree import Chain, Pruning, prune_spurs, rooted_chains
from rigger.methods.silhouette.tuning import Tuning
from rigger.methods.silhouette.views import reflection_in_view

TUNING = Tuning()
ACROSS_X = Symmetry((0, 0.0), 0.05, TUNING)  # chains mirror across x = 0 within 0.05
ROUGHLY_ACROSS_X = Symmetry((0, 0.0), 0.05, TUNING, middle=0.0)  # ... on a body that only roughly mirrors


def cutting(max_bones=0):
    """Chains cut at 40 degree corners into bones 0.1 long, at most ``max_bones`` per chain (0: no limit)."""
    return Cutting(np.radians(40), 0.1, max_bones, TUNING)


def rooted_path(radius):
    """Root and chains of a straight path of len(radius) axis nodes with the given half-widths."""
    count = len(radius)
    points = np.stack([np.arange(count, dtype=float), np.zeros(count)], axis=1)
    links = np.stack([np.arange(count - 1), np.arange(1, count)], axis=1)
    keys, chains = chains_of(list(range(count)), links)
    return rooted_chains(points, keys, chains, np.asarray(radius, dtype=float), TUNING)


def test_a_column_is_one_chain_from_its_thicker_end():
    radius = np.r_[0.2, np.linspace(1.0, 1.1, 18), 0.2]  # tapered tips, a little thicker at the far end
    root, chains = rooted_path(radius)
    assert root == 19
    assert len(chains) == 1 and chains[0].nodes == list(range(19, -1, -1)) and chains[0].parent == -1


def test_a_path_with_a_body_is_rooted_at_the_body():
    radius = np.r_[np.full(12, 0.3), 2.0, np.full(7, 0.3)]  # two thin wings, one wide body between them
    root, chains = rooted_path(radius)
    assert root == 12
    assert sorted(len(chain.nodes) for chain in chains) == [8, 13]
    assert all(chain.nodes[0] == 12 and chain.parent == -1 for chain in chains)


def test_loops_are_cut_where_parts_touch_and_the_result_is_a_tree():
    """A body (node 0 at the hips, node 1 at the chest, joined by a spine 2-5) with legs and a head, and an arm from
    the chest tapering to a hand that rests on the hips (nodes 6-14): the arm hangs whole from the chest, its tip
    at the hips left off. Feet touching, a link between the legs' tips (no node between) closing a second loop,
    goes: each leg keeps its own foot."""
    spine = [(0.0, y, 1.0) for y in (1.0, 2.0, 3.0, 4.0)]
    arm = [(1.2 + 0.2 * k, 4.5 - 0.5 * k, 0.5 - 0.04 * k) for k in range(9)]
    limbs = [[(x, -y, 0.3) for y in range(1, 5)] for x in (-0.5, 0.5)] + [[(0.0, 5.0 + y, 0.6) for y in range(4)]]
    nodes = np.array([(0.0, 0.0, 1.5), (0.0, 5.0, 1.5)] + spine + arm + limbs[0] + limbs[1] + limbs[2])
    points, radius = nodes[:, :2], nodes[:, 2]
    leg_a, leg_b, head = (list(range(15 + 4 * k, 19 + 4 * k)) for k in range(3))
    chains = [[0, 2, 3, 4, 5, 1], [1] + list(range(6, 15)) + [0], [0] + leg_a, [0] + leg_b, [1] + head,
              [leg_a[-1], leg_b[-1]]]
    root, rooted = rooted_chains(points, [0, 1], chains, radius, TUNING)
    links = [(a, b) for chain in rooted for a, b in zip(chain.nodes, chain.nodes[1:])]
    assert len(links) == len({frozenset(link) for link in links}) == len(nodes) - 1  # every node once: a tree
    arm_chain = next(chain for chain in rooted if 6 in chain.nodes)
    assert arm_chain.nodes == [1] + list(range(6, 15))
    assert {frozenset((leg_a[-1], leg_b[-1]))}.isdisjoint(frozenset(link) for link in links)


def test_a_wide_branch_reaching_far_is_a_limb_not_a_bump():
    """A cow's neck with its head, seen from the side: it leaves the shoulders wide (2 across) and reaches 2.6
    beyond their disc, less than prune (1.35) times its width, so it reads as a bump; reaching past ``max_reach``
    keeps it. Two thin legs make the shoulders a branch point."""
    neck = [(x, 0.0, 1.0) for x in np.linspace(1.3, 3.2, 8)] + [(3.5, 0.0, 0.3)]
    legs = [[(0.0, -y, 0.2) for y in range(1, 7)], [(-x, 0.0, 0.2) for x in range(1, 7)]]
    nodes = np.array([(0.0, 0.0, 1.2)] + neck + legs[0] + legs[1])
    points, radius = nodes[:, :2], nodes[:, 2]
    chains = [[0] + list(range(1, 10)), [0] + list(range(10, 16)), [0] + list(range(16, 22))]
    kept = {tuple(link) for link in prune_spurs(points, radius, chains, Pruning(1.35, 0.5, max_reach=2.5))}
    assert (8, 9) in kept and len(kept) == 21
    bumped = {tuple(link) for link in prune_spurs(points, radius, chains, Pruning(1.35, 0.5))}
    assert (8, 9) not in bumped and len(bumped) == 12


def reflect(points):
    """The mirror image of (P, 2) points across x = 0."""
    return points * [-1.0, 1.0]


def chest_with_legs(*branches, legs=(-0.5, 0.5)):
    """(points, radius, chains) of an axis: a chest (node 0, radius 1) with a thin leg of 6 nodes at each x of
    ``legs`` (nodes 1-12) and the ``branches`` ((x, y, radius) node lists) off it, numbered on from there (13)."""
    nodes, chains = [(0.0, 0.0, 1.0)], []
    for part in [[(side, -y, 0.3) for y in range(2, 8)] for side in legs] + list(branches):
        chains.append([0] + list(range(len(nodes), len(nodes) + len(part))))
        nodes += part
    nodes = np.array(nodes)
    return nodes[:, :2], nodes[:, 2], chains


def tips_kept(*branches, prune=1.35, legs=(-0.5, 0.5), **rules):
    """Whether each of the ``branches`` off ``chest_with_legs``' chest keeps its tip after ``prune_spurs``."""
    points, radius, chains = chest_with_legs(*branches, legs=legs)
    links = prune_spurs(points, radius, chains, Pruning(prune, **rules))
    return [chain[-1] in links for chain in chains[-len(branches):]]


def stub(direction, ratio, radius=0.3, y=0.0):
    """Five nodes of a branch of half-width ``radius`` leaving the chest's disc (radius 1) along ``direction``
    (raised by ``y``), sticking out ``ratio`` times its width beyond it."""
    direction = np.array(direction) / np.linalg.norm(direction)
    reach = np.linspace(1.02, 1 - radius + 2 * radius * ratio, 5)
    return [(direction[0] * x, direction[1] * x + y, radius) for x in reach]


def test_a_spur_whose_mirror_image_is_kept_stays():
    """A figure's two arms off its chest, mirror images across x = 0 but for the left one reaching a little less:
    at prune 1.35 the right arm (sticking out 1.4 times its width) is kept and the left (1.3) would go. With the
    reflection the left one stays with its image; a bump on the mirror line (its own image) still goes, both arms
    go once neither is long enough, and at prune 0.8 all three stay."""
    def arm(side, ratio):  # half-width 0.5 off a chest disc of radius 1: sticks out 0.5 + reach beyond it
        return [(side * x, 0.0, 0.5) for x in np.linspace(1.5, 0.5 + ratio, 6)]
    parts = (arm(1, 1.4), arm(-1, 1.3), [(0.0, 1.3, 0.8), (0.0, 1.6, 0.8)])  # the bump sticks out 1.4, 1.6 wide
    assert tips_kept(*parts) == [True, False, False]
    assert tips_kept(*parts, mirror=reflect) == [True, True, False]
    assert tips_kept(*parts, prune=1.45, mirror=reflect) == [False, False, False]
    assert tips_kept(*parts, prune=0.8, mirror=reflect) == [True, True, True]


def test_a_stubby_head_going_on_from_the_spine_stays():
    """A helmeted trooper's head on a short neck, seen from the front: off the shoulders' disc (radius 1), between
    two arms, it sticks out 1.2 times its neck's width, under prune (1.35), so it went as a bump, and noise of 0.1%
    of the size took the head off a rig that had it. On the mirror line, going on straight from the spine (a chain
    on the line down through the same disc), it stays; turned off the line, too short for a part (less than half the
    disc's radius beyond it), or with no spine on the line to go on from, it goes."""
    arms = stub((1.0, 0.0), 3.0), stub((-1.0, 0.0), 3.0)
    spine = {"legs": (0.0,), "mirror": reflect}
    assert tips_kept(*arms, stub((0.0, 1.0), 1.2), **spine) == [True, True, True]
    assert tips_kept(*arms, stub((0.0, 1.0), 1.2), legs=(0.0,)) == [True, True, False]  # no mirror plane
    assert tips_kept(*arms, stub((1.0, 1.0), 1.2), **spine) == [True, True, False]  # turned off the line
    assert tips_kept(*arms, stub((0.0, 1.0), 1.2, radius=0.1), **spine) == [True, True, False]  # reaching 0.24
    assert tips_kept(*arms, stub((0.0, 1.0), 1.2), mirror=reflect) == [True, True, False]  # legs off the line


def test_a_mirror_pair_of_stubby_branches_stays_where_a_lone_one_goes():
    """Two ears off a head (a chest disc of radius 1), each sticking out 0.9 times its width: under prune (1.35),
    over pair_prune (0.74). With the reflection the pair stays; a lone ear, a pair under pair_prune, or either rule
    missing, and they go."""
    def ear(side, ratio, y=0.0):
        return stub((side, 0.0), ratio, y=y)

    pair = {"mirror": reflect, "pair_prune": 0.74}
    assert tips_kept(ear(1, 0.9), ear(-1, 0.9), **pair) == [True, True]
    assert tips_kept(ear(1, 0.9), [(-0.3, 1.05, 0.1)], **pair) == [False, False]  # a lone ear (and a speck)
    assert tips_kept(ear(1, 0.9), ear(-1, 0.9), mirror=reflect) == [False, False]
    assert tips_kept(ear(1, 0.9), ear(-1, 0.9), pair_prune=0.74) == [False, False]
    assert tips_kept(ear(1, 0.9), ear(-1, 0.9, y=0.8), **pair) == [False, False]  # not each other's image
    assert tips_kept(ear(1, 0.9), ear(-1, 0.6), **pair) == [False, False]
    assert tips_kept(ear(1, 0.7), ear(-1, 0.7), **pair) == [False, False]
    # a short ear's image lies on a long one but not the other way round: neither is the other's twin, so both go,
    # also off a head with one neck, where dropping the long one alone would leave the short one part of the neck
    for legs in ((-0.5, 0.5), (0.0,)):
        assert tips_kept(ear(1, 1.34), ear(-1, 0.8), legs=legs, **pair) == [False, False]


def test_mirror_twin_arms_whose_chains_end_in_other_corners_of_their_hands_stay_together():
    """Two arms alike off a chest (radius 1), each sticking out 1.2 times its width (under prune, over pair_prune),
    one chain running out level, the other turned 14 degrees down into another corner of its hand: neither tip's
    mirror image lies on the other arm, but within its width of the other's tip. Noise of 0.05% of the size did
    that to a cartoon man's arms, and both went. Twins alike in reach and width stay together; unlike ones go."""
    pair = {"mirror": reflect, "pair_prune": 0.74}
    level, turned = stub((1.0, 0.0), 1.2), stub((-1.0, -0.25), 1.2)
    assert tips_kept(level, turned, **pair) == [True, True]
    assert tips_kept(level, stub((-1.0, -0.25), 0.78), **pair) == [False, False]  # reaching 1.2 / 0.78 as far
    assert tips_kept(level, stub((-1.0, -0.6), 1.2), **pair) == [False, False]  # the image a width away


def test_without_a_mirror_plane_two_stubby_branches_alike_in_size_stay_as_a_pair():
    """A hand-made figure's two stubby arms off its chest (radius 1) are never exact mirror images: with
    ``local_pairs`` two spurs over pair_prune (0.74) that stick out about as far and are about as wide both stay,
    wherever they point; a lone one, a pair unlike in width or reach, or one under pair_prune goes."""
    def kept(*arms, local_pairs=True):  # whether each arm's tip stays
        return tips_kept(*arms, pair_prune=0.74, local_pairs=local_pairs)

    assert kept(stub((1, 0.2), 0.9), stub((-1, 0.4), 0.8)) == [True, True]
    assert kept(stub((1, 0.2), 0.9), stub((-1, 0.4), 0.8), local_pairs=False) == [False, False]
    assert kept(stub((1, 0.2), 0.9)) == [False]
    assert kept(stub((1, 0.2), 0.8), stub((-1, 0.4), 0.48 / 0.36, radius=0.18)) == [False, False]  # reach alike
    assert kept(stub((1, 0.2), 1.3), stub((-1, 0.4), 0.78)) == [False, False]  # width alike
    assert kept(stub((1, 0.2), 0.9), stub((-1, 0.4), 0.9, radius=0.3 / 1.3)) == [False, False]  # 1.3 x 1.3 > 1.5
    assert kept(stub((1, 0.2), 0.7), stub((-1, 0.4), 0.7)) == [False, False]
    assert kept(stub((1, 0.2), 0.9), stub((1, 0.5), 0.9)) == [False, False]  # side by side: tips 0.33 apart
    assert kept(stub((1, 0.2), 0.9), stub((-1, 0.4), 0.8), stub((0, 1), 0.85)).count(True) == 2


def test_without_a_mirror_plane_a_stubby_branch_stays_with_its_alike_twin_kept():
    """Two arms alike in size off a chest, one sticking out 1.4 times its width (over prune, 1.35: kept), the other
    1.3 (a spur over pair_prune): without a mirror plane, twins near the threshold stay or go together, so the
    shorter arm stays with its twin, as it would in a pair under prune; one unlike its twin still goes. Noise too
    small to see moves an arm across the threshold; it should not cost the figure one arm."""
    def kept(*arms):
        return tips_kept(*arms, pair_prune=0.74, local_pairs=True)

    assert kept(stub((1, 0.2), 1.4), stub((-1, 0.4), 1.3)) == [True, True]
    assert kept(stub((1, 0.2), 1.4), stub((-1, 0.4), 0.9, radius=0.18)) == [True, False]  # 1.5 x 1.67 > 1.5
    assert tips_kept(stub((1, 0.2), 1.4), stub((-1, 0.4), 1.3), pair_prune=0.74) == [True, False]


def test_a_wide_part_that_reaches_far_through_its_corners_stays_once_they_go():
    """A head off a chest (a neck 0.9 wide, ending where it forks into two corner branches, an ear and a snout):
    pruning takes the corner branches together, and the head, a wide bump measured to its fork, would go with them.
    A part reaching ``max_reach`` beyond its base is kept however wide; it reaches as far as its corners did, so it
    stays (noise too small to see decides whether its outline forks there or not)."""
    points, radius, chains = chest_with_legs([(0.0, y, 0.9) for y in (1.2, 1.5, 1.8)] + [(0.0, 2.0, 0.8)])
    fork = chains[-1][-1]
    for side in (-1, 1):
        corner = [(side * 0.2, 2.5, 0.5), (side * 0.4, 2.9, 0.45), (side * 0.6, 3.2, 0.05)]
        chains.append([fork] + list(range(len(points), len(points) + 3)))
        points = np.vstack([points, [c[:2] for c in corner]])
        radius = np.r_[radius, [c[2] for c in corner]]
    links = prune_spurs(points, radius, chains, Pruning(1.35, max_reach=2.0))
    assert fork in links and chains[-1][-1] not in links and chains[-2][-1] not in links
    assert fork not in prune_spurs(points, radius, chains, Pruning(1.35, max_reach=2.4))  # reaching 2.3: a bump


def test_without_a_mirror_plane_the_two_corner_branches_at_a_limb_s_end_still_go():
    """An arm ending at a hand node (radius 0.3) that forks into two alike corner branches, each sticking out 1.1
    times its width: pruning them leaves the hand the arm's end, no base the tree runs through, so they go."""
    points, radius, chains = chest_with_legs([(x, 0.0, 0.3) for x in np.linspace(1.2, 3.0, 7)])
    hand = chains[-1][-1]
    corners = np.array([(3.2, 0.2, 0.12), (3.4, 0.35, 0.2), (3.2, -0.2, 0.12), (3.4, -0.35, 0.2)])
    points, radius = np.vstack([points, corners[:, :2]]), np.r_[radius, corners[:, 2]]
    chains += [[hand, len(points) - 4, len(points) - 3], [hand, len(points) - 2, len(points) - 1]]
    links = prune_spurs(points, radius, chains, Pruning(1.35, pair_prune=0.74, local_pairs=True))
    assert hand in links and len(points) - 3 not in links and len(points) - 1 not in links


def test_outline_noise_is_not_kept_for_lying_on_the_body_it_mirrors_onto():
    """Two specks of outline noise mirroring each other on the edge of the chest's disc, between two legs: each
    speck's image lies on the chest, not on a kept branch, so both go."""
    specks = [(0.5, 0.85, 0.01)], [(-0.5, 0.85, 0.01)]  # 0.99 from the chest's centre, 1.0 its radius
    points, radius, chains = chest_with_legs(*specks)
    kept = prune_spurs(points, radius, chains, Pruning(1.35, mirror=reflect))
    leg, *speck_tips = (chain[-1] for chain in chains[1:])
    assert all(tip not in kept for tip in speck_tips) and leg in kept


def test_a_round_part_without_a_neck_is_kept():
    """A gingerbread man's head on its shoulders: the body's blob (radius 1) carries a head blob (radius 0.85)
    centred 1.1 away, just off the body's disc, through one node as wide as the head: it sticks out 0.95, under
    prune (1.35) times its width (1.7), so without ``blobs`` it goes as a bump. As a blob of its own it stays;
    a smaller blob, one centred on the body's disc, or one sticking out less than ``min_reach`` goes."""
    def head_kept(head, is_blob=True, min_reach=0.0):
        points, radius, chains = chest_with_legs([(0.0, 1.05, head[2]), head])
        leg, tip = chains[1][-1], chains[2][-1]
        blobs = np.zeros(len(points), bool)
        blobs[[0, tip]] = True, is_blob
        kept = prune_spurs(points, radius, chains, Pruning(1.35, min_reach), blobs=blobs)
        assert leg in kept  # the legs are limbs whatever happens to the head
        return tip in kept

    assert head_kept((0.0, 1.1, 0.85))
    assert not head_kept((0.0, 1.1, 0.85), is_blob=False)
    assert not head_kept((0.0, 1.1, 0.6))  # a bump ending in a smaller blob (an ear on a head)
    assert not head_kept((0.0, 0.95, 0.85))  # a blob centred inside the body's disc
    assert not head_kept((0.0, 1.1, 0.85), min_reach=1.0)


def test_a_chain_running_on_from_a_round_part_to_a_corner_goes_back_to_the_part_however_it_wiggles():
    """A foot (a blob of radius 0.75, off the chest's disc) whose axis runs on to a corner of the outline 0.95 away
    (within a radius and a half) but zigzags on the way, 1.5 along: the chain is a bump as a whole, yet the foot
    keeps its branch, cut back to the foot. A corner 1.2 away is beyond the foot: the whole branch goes."""
    def kept(corner):
        foot = (1.6, 0.0, 0.75)
        zigzag = [(1.6 + x, corner * f, 0.05) for x, f in ((-0.2, 0.25), (0.2, 0.5), (-0.2, 0.75), (0.0, 1.0))]
        points, radius, chains = chest_with_legs([(1.02, 0.0, 0.7), foot, *zigzag])
        blobs = np.zeros(len(points), bool)
        blobs[[0, chains[-1][2], chains[-1][-1]]] = True
        links = prune_spurs(points, radius, chains, Pruning(1.35, heads=True), blobs=blobs)
        return chains[-1][2] in links, chains[-1][-1] in links

    assert kept(0.95) == (True, False)
    assert kept(1.2) == (False, False)


def test_blobs_near_the_mirror_line_are_centred_on_it():
    """Hubs within half their radius of the line x = 0 move onto it (halfway to their image); one farther off,
    and every other node, stay; the graph itself is left as it was."""
    points = np.array([(0.2, 0.0), (0.6, 1.0), (0.3, 2.0), (-0.05, 3.0)])
    radius = np.array([0.5, 1.0, 0.5, 0.1])
    graph = ChordalAxis(points, radius, np.ones(4, bool), np.array([(0, 1), (1, 2), (2, 3)]), np.zeros(4, int))
    centred = graph.centred_on_mirror(np.array([0, 1, 2]), reflect)
    np.testing.assert_array_equal(centred.points, [(0.0, 0.0), (0.6, 1.0), (0.3, 2.0), (-0.05, 3.0)])
    assert graph.points[0, 0] == 0.2
    assert graph.centred_on_mirror(np.zeros(0, int), lambda p: -p).points.tolist() == points.tolist()


def layers(*intervals):
    return np.array(intervals, dtype=float).reshape(-1, 2)


def test_sheets_are_not_parts():
    """An open sheet hit once is a zero-thickness interval: no part for a chain to split into, unless nothing else
    is there."""
    np.testing.assert_array_equal(depth.solid_layers(layers((0.0, 1.0), (2.0, 2.0)), 0.5, TUNING), layers((0.0, 1.0)))
    np.testing.assert_array_equal(depth.solid_layers(layers((2.0, 2.0)), 0.5, TUNING), layers((2.0, 2.0)))


def test_a_chain_splits_into_its_limbs_not_into_their_toes():
    """Seen from the side: the body (one part), then both legs (two), then each foot's two toes (four)."""
    node_layers = ([layers((0, 4))] * 6 + [layers((0, 1), (3, 4))] * 6
                   + [layers((0, 0.4), (0.6, 1), (3, 3.4), (3.6, 4))] * 8)
    assert depth.layer_count(node_layers, TUNING) == 2
    assert depth.layer_count([layers((0, 1))] * 10, TUNING) == 1
    assert depth.layer_count([layers((0, 1), (3, 4))] * 10, TUNING) == 2


def test_long_toes_do_not_make_more_legs_and_fingers_parting_one_by_one_stay_fingers():
    """A stubby dinosaur's hind legs seen from the side, hanging from the body's end: two legs, then each foot's two
    toes over more nodes than the legs had (with noise, the nodes under the toes were enough to outvote the legs),
    then the toes' tips merging. A hand seen edge-on: the palm, then its fingers parting one after another (two,
    then three parts for a node each), then all four: four fingers, not two."""
    toes = layers((0, 0.4), (0.6, 1), (3, 3.4), (3.6, 4))
    dinosaur = [layers((0, 4))] * 2 + [layers((0, 1), (3, 4))] * 10 + [toes] * 10 + [layers((0.6, 0.7))] * 3
    assert depth.layer_count(dinosaur, TUNING) == 2
    fingers = layers((0, 0.2), (0.3, 0.5), (0.6, 0.8), (0.9, 1.1))
    hand = [layers((0, 1.1))] * 8 + [layers((0, 0.2), (0.3, 1.1)), layers((0, 0.2), (0.3, 0.5), (0.6, 1.1))] \
        + [fingers] * 10
    assert depth.layer_count(hand, TUNING) == 4


def test_plates_of_one_limb_are_one_part():
    """A robot's forearm seen along the view: shells and plates thinner than the arm is wide, a little apart."""
    plates = layers((0.0, 0.3), (0.35, 0.6), (0.9, 1.1))
    np.testing.assert_array_equal(depth.separate_parts(plates, 1.0, TUNING), layers((0.0, 1.1)))
    legs = layers((0.0, 1.0), (3.0, 4.2))
    np.testing.assert_array_equal(depth.separate_parts(legs, 1.0, TUNING), legs)
    assert depth.layer_count([depth.separate_parts(plates, 1.0, TUNING)] * 10, TUNING) == 1


def test_a_nose_beside_a_head_is_not_a_second_head():
    """Two intervals each thicker than the part is wide, but one a fifth of the other's thickness (a nose, a brim):
    one part. Two alike (legs, fingers) stay two."""
    head = layers((0.0, 0.4), (0.6, 2.6))
    np.testing.assert_array_equal(depth.separate_parts(head, 0.4, TUNING), layers((0.6, 2.6)))
    legs = layers((0.0, 0.8), (1.2, 2.4))
    np.testing.assert_array_equal(depth.separate_parts(legs, 0.4, TUNING), legs)


def test_fingers_fork_off_their_arm_but_legs_split_from_the_body():
    """An arm (one round part as thick as it is wide), then four fingers apart: the chain forks at the wrist. A leg
    pair seen from the side runs into the body (one part much thicker than the legs are wide): split from the
    start."""
    radius = np.full(20, 0.5)
    fingers = [layers((0, 0.8), (1, 1.8), (2, 2.8), (3, 3.8))] * 8
    arm = [layers((1.4, 2.4))] * 12 + fingers
    assert depth.fork_point(arm, radius, 4, TUNING) == 11
    body = [layers((0, 4))] * 6 + [layers((0, 1), (3, 4))] * 14
    assert depth.fork_point(body, radius, 2, TUNING) == 0


class FlatSilhouette:
    """A stand-in for ``Silhouette``: fixed depth intervals per axis node, depth along z."""

    cell = 0.01

    def __init__(self, node_layers):
        self.node_layers = node_layers

    def layers(self, points):
        return [self.node_layers[int(round(x))] for x in points[:, 0]]

    def lift(self, points, depth):
        return np.column_stack([points, np.broadcast_to(depth, (len(points),))])


def placed_along_x(node_layers, chains=None, side_axis=None, **options):
    """``depth.place_chains`` on axis nodes 0, 1, ... along x (half-width 0.5), node k seeing ``node_layers[k]``,
    rooted at node 0; ``chains`` defaults to one chain through them all."""
    count = len(node_layers)
    points = np.stack([np.arange(count, dtype=float), np.zeros(count)], axis=1)
    return depth.place_chains(FlatSilhouette(node_layers), points, np.full(count, 0.5), 0,
                              chains or [Chain(list(range(count)), -1)],
                              depth.Placing(TUNING, side_axis=side_axis, **options))


def test_a_forked_chain_is_one_stem_then_a_chain_per_part():
    node_layers = [layers((1.4, 2.4))] * 12 + [layers((0, 0.8), (1, 1.8), (2, 2.8), (3, 3.8))] * 8
    _, placed = placed_along_x(node_layers)
    stem, *fingers = placed
    assert stem[1] == -1 and len(stem[0]) == 12  # nodes 0..11, the wrist last
    assert len(fingers) == 4 and all(parent == 0 for _, parent, _ in fingers)
    for line, _, _ in fingers:
        np.testing.assert_array_equal(line[0], stem[0][-1])  # each finger starts at the wrist
    tips = sorted(line[-1, 2] for line, _, _ in fingers)
    np.testing.assert_allclose(tips, [0.4, 1.4, 2.4, 3.4])  # one per finger, centred in it


def test_a_head_seen_across_the_mirror_plane_does_not_run_into_one_ear():
    """A head (one part on the mirror plane z = 0, half-width 0.5) with thin ears on each side seen from the side:
    where the rays pass only beside the plane (a gap in the head's outline, and the ears' tips) the chain neither
    steps into one ear nor ends in one. Without the plane, or without splitting, it follows one ear to its tip, as
    it must for a single part off to one side."""
    ears = layers((-0.8, -0.7), (0.7, 0.8))
    node_layers = [layers((-0.5, 0.5))] * 5 + [ears] + [layers((-0.5, 0.5))] * 3 + [ears] * 3
    (_, [(line, _, _)]) = placed_along_x(node_layers, mirror=(0.0, 0.05))
    assert len(line) == 9  # the ears' tips cut
    np.testing.assert_array_equal(line[:, 2], 0.0)  # on the plane throughout
    for plane in (None, (0.0, 0.05)):
        (_, [(line, _, _)]) = placed_along_x(node_layers, split=False, mirror=plane)
        assert len(line) == len(node_layers) and line[-1, 2] == -0.75


def test_a_chain_that_cannot_end_before_its_tip_between_the_ears_follows_one_ear():
    """A chain running between two ears from its start, or one that another chain hangs from, cannot end on the
    plane before its tip stretch: it follows one ear as it would without a plane, rather than run through the
    gap between the ears."""
    ears = layers((-0.8, -0.7), (0.7, 0.8))
    beside = [layers((-0.5, 0.5))] + [ears] * 5
    on_then_beside = [layers((-0.5, 0.5))] * 4 + [ears] * 2 + [layers((-0.8, -0.7))] * 2
    for node_layers, chains in ((beside, [Chain(list(range(6)), -1)]),
                                (on_then_beside, [Chain(list(range(6)), -1), Chain([5, 6, 7], 0)])):
        _, placed = placed_along_x(node_layers, chains, mirror=(0.0, 0.05))
        line = placed[0][0]
        assert len(line) == 6 and line[-1, 2] == -0.75


def test_parts_that_come_together_again_before_the_tip_are_one_chain():
    """A neck (one part), then a head whose rays cross two parts (eye holes, horns seen edge-on), then one part
    spanning both to its crown: one chain, not two parallel necks. Two arms one behind the other, the front one
    shorter, still split: past the front wrist the rays cross the back arm alone, which spans no gap."""
    head = [layers((-0.5, 0.5))] * 6 + [layers((-0.5, -0.1), (0.1, 0.5))] * 8 + [layers((-0.45, 0.45))] * 6
    _, placed = placed_along_x(head)
    assert len(placed) == 1 and len(placed[0][0]) == len(head)
    arms = [layers((-0.5, 1.5))] * 4 + [layers((-0.5, 0.4), (0.6, 1.5))] * 10 + [layers((0.6, 1.5))] * 4
    _, placed = placed_along_x(arms)
    assert len(placed) == 2


def straight(length, points=101):
    return np.stack([np.linspace(0.0, length, points), np.zeros(points), np.zeros(points)], axis=1)


@pytest.mark.parametrize("length, bones", [(0.05, 1), (0.1, 1), (0.15, 2), (0.25, 3), (0.4, 4), (0.9, 4)])
def test_a_straight_chain_gets_one_bone_per_bone_length_begun_up_to_the_limit(length, bones):
    joints = chain_joints(straight(length), cutting(max_bones=4))
    assert len(joints) == bones + 1
    np.testing.assert_allclose(np.diff(joints[:, 0]), length / bones)  # evenly cut


def test_a_finger_gets_two_bones_a_short_link_one():
    """A leaf chain (a finger) half a bone long or more gets two bones, as artists give it; a link between two
    branch points that short gets one, and a stub of a leaf one."""
    assert len(chain_joints(straight(0.07), cutting(max_bones=4), leaf=True)) == 3
    assert len(chain_joints(straight(0.07), cutting(max_bones=4))) == 2
    assert len(chain_joints(straight(0.04), cutting(max_bones=4), leaf=True)) == 2


def test_corners_get_joints_even_beyond_the_limit():
    zigzag = np.array([[0, 0, 0], [0.2, 0, 0], [0.2, 0.2, 0], [0.4, 0.2, 0], [0.4, 0.4, 0]], dtype=float)
    joints = chain_joints(zigzag, cutting(max_bones=2))
    for corner in zigzag[1:-1]:
        assert np.linalg.norm(joints - corner, axis=1).min() < 1e-9
    assert np.linalg.norm(np.diff(joints, axis=0), axis=1).min() >= 0.035 - 1e-9  # no stub bones


def test_a_straight_thigh_and_shin_between_corners_still_get_a_knee():
    """A thin leg that bends at the hip, again below it and at the ankle: those joints use up its four bones and leave
    thigh and shin one straight piece 2.5 bone lengths long. It is cut in two, a knee at its middle, not one bone
    that cannot bend where the leg does."""
    leg = np.array([[0, 0, 0], [0.06, 0, 0], [0.09, -0.03, 0], [0.09, -0.28, 0], [0.13, -0.28, 0]], dtype=float)
    joints = chain_joints(leg, cutting(max_bones=4), widths=np.full(len(leg), 0.005))
    for corner in leg:
        assert np.linalg.norm(joints - corner, axis=1).min() < 1e-9
    assert np.linalg.norm(joints - [0.09, -0.155, 0], axis=1).min() < 1e-9
    assert np.linalg.norm(np.diff(joints, axis=0), axis=1).max() <= 2 * 0.1 + 1e-9


def wave(length, amplitude, waves, points=401):
    line = straight(length, points)
    line[:, 1] = amplitude * np.sin(np.linspace(0.0, 2 * np.pi * waves, points))
    return line


def test_wiggles_within_the_part_place_joints_but_add_no_bones():
    """A wing whose axis wiggles by less than its half-width (feathers): one bone per bone length begun, not one
    per wiggle; a snake bending farther than its half-width gets a joint at every bend, beyond the limit."""
    wing = wave(0.4, 0.008, 6)
    joints = chain_joints(wing, cutting(), widths=np.full(401, 0.012))
    assert len(joints) - 1 == np.ceil(arc_lengths(wing)[-1] / 0.1) == 5
    snake = wave(0.4, 0.03, 6)
    joints = chain_joints(snake, cutting(max_bones=4), widths=np.full(401, 0.01))
    assert len(joints) - 1 > 4
    for crest in np.flatnonzero(np.abs(snake[:, 1]) >= 0.03 - 1e-12)[1:-1]:
        assert np.linalg.norm(joints - snake[crest], axis=1).min() <= 0.35 * 0.1


def test_a_line_jittering_in_depth_gets_no_stub_bones():
    """A leg whose depth flickers between two values near the knee: its arc length grows, its bones must not
    shrink to stubs there."""
    line = straight(0.4)
    line[45:55:2, 2] = 0.03  # every other point 0.03 off: many short corners within a tenth of a bone
    joints = chain_joints(line, cutting(max_bones=4), widths=np.full(len(line), 0.01))
    assert np.linalg.norm(np.diff(joints, axis=0), axis=1).min() >= 0.035 - 1e-9


class FixedSide:
    """A stand-in for ``SideAxis`` that puts every occluded node at depth 0 (the body's middle)."""

    def depth_at(self, point, radius, interval, previous, width_cost):
        return 0.0


def test_one_node_seeing_two_legs_as_one_part_is_a_slip_not_an_occlusion():
    """A leg at depth 3: one node's ray pairs its hits across both legs (one thick interval); the leg stays put.
    Several such nodes in a row are an occlusion (an arm in front of the body): the side view decides there."""
    sil = FlatSilhouette(None)
    leg, merged = layers((2.5, 3.5)), layers((-3.5, 3.5))
    points, radius = np.zeros((9, 2)), np.full(9, 0.5)
    slip = [leg] * 4 + [merged] + [leg] * 4
    occluding = depth.Placing(TUNING, side_axis=FixedSide())
    depths = depth.resolve_occlusion(sil, points, radius, slip, np.full(9, 3.0), occluding)
    np.testing.assert_array_equal(depths, 3.0)
    occluded = [leg] * 3 + [merged] * 3 + [leg] * 3
    depths = depth.resolve_occlusion(sil, points, radius, occluded, np.full(9, 3.0), occluding)
    np.testing.assert_array_equal(depths, [3, 3, 3, 0, 0, 0, 3, 3, 3])


def test_split_legs_keep_their_sides_where_they_merge_into_the_hips():
    """A leg pair seen from the side, one part per leg at depths -3 and 3, merging with the hips into one thick
    interval near the body: a side view that puts the merged nodes at the body's middle must not pull both copies
    onto one line there; each keeps its side."""
    node_layers = [layers((-3.5, 3.5))] * 5 + [layers((-3.5, -2.5), (2.5, 3.5))] * 15
    _, placed = placed_along_x(node_layers, side_axis=FixedSide())
    assert len(placed) == 2
    np.testing.assert_array_equal(sorted(line[1, 2] for line, _, _ in placed), [-3.0, 3.0])


def test_split_twins_across_the_mirror_plane_stay_mirror_images():
    """A leg pair seen across the mirror plane z = 0: apart at the tips, merged near the body, and in between only
    the near leg seen (the far one hidden behind it, or touching it). The copy anchored on the far leg would step
    onto the near one there; twins across the plane are mirror images instead, each on its own side. Without the
    plane the copies go as followed. Each twin hangs from a bone across from the middle to where it begins."""
    node_layers = [layers((-3.5, 3.5))] * 5 + [layers((-3.5, -2.5))] * 2 + [layers((-3.5, -2.5), (2.5, 3.5))] * 5
    root, placed = placed_along_x(node_layers, mirror=(0.0, 0.05))
    legs = [(line, parent) for line, parent, widths in placed if widths.any()]
    across = {k: line for k, (line, _, widths) in enumerate(placed) if not widths.any()}
    assert len(legs) == 2 and len(across) == 2
    for line, parent in legs:
        np.testing.assert_array_equal(across[parent], [root, line[0]])
    near, far = sorted((line for line, _ in legs), key=lambda line: line[-1, 2])
    np.testing.assert_array_equal(near[:, 2], -3.0)
    np.testing.assert_array_equal(far[:, 2], 3.0)
    _, placed = placed_along_x(node_layers)
    assert sorted(line[5, 2] for line, _, _ in placed) == [-3.0, -3.0]


def leaves(*lines):
    """The chains ``symmetric_joints`` takes: each line a leaf, without widths."""
    return [(line, None, True) for line in lines]


def test_twins_traced_apart_get_the_mirror_image_joints_of_their_mean_line():
    """Two arms mirrored across x = 0, one traced a little higher and with its elbow a little off: both get the
    joints of their mean line, mirror images of each other to the last bit, each keeping its own first joint; the
    spine on the plane is left alone."""
    arm = np.array([[0.2, 1.0, 0.0], [0.45, 1.05, 0.0], [0.7, 1.0, 0.0]])
    other = arm * [-1, 1, 1] + [0.0, 0.01, 0.0]
    other[1] += [-0.01, 0.0, 0.0]
    spine = np.array([[0.0, 0.0, 0.0], [0.0, 1.0, 0.0]])
    chains = leaves(spine, arm, other)
    result = symmetric_joints(chains, cutting(), ACROSS_X)
    np.testing.assert_array_equal(result[0], chain_joints(spine, cutting(), leaf=True))
    np.testing.assert_array_equal(result[1][0], arm[0])
    np.testing.assert_array_equal(result[2][0], other[0])
    np.testing.assert_array_equal(result[1][1:] * [-1, 1, 1], result[2][1:])
    mean = (arm + other * [-1, 1, 1]) / 2
    assert len(result[1]) == len(chain_joints(mean, cutting(), leaf=True))


def test_twins_whose_lines_differ_keep_their_own_joints_with_one_bone_count():
    """Two legs whose ends mirror but whose shapes differ (one bent at the knee, one straight: a leg stepping
    forward) keep their own joints but get one bone count: the smaller, unless the one with more bones needs them
    for its corners; then the other gets as many."""
    knee = np.array([[0.0, 0.0, 0.0], [0.2, 0.0, 0.15], [0.4, 0.0, 0.0]])
    own = [chain_joints(line, cutting(), leaf=True) for line in (knee, straight(-0.4))]
    assert (len(own[0]), len(own[1])) == (6, 5)
    result = symmetric_joints(leaves(knee, straight(-0.4)), cutting(), ACROSS_X)
    assert len(result[0]) == len(result[1]) == 5
    assert np.linalg.norm(result[0] - knee[1], axis=1).min() < 1e-9  # the knee keeps its joint
    np.testing.assert_array_equal(result[1], own[1])
    zigzag = np.array([[0.0, 0.0, 0.0], [0.1, 0.0, 0.1], [0.2, 0.0, 0.0], [0.3, 0.0, 0.1], [0.4, 0.0, 0.0]])
    own = [chain_joints(line, cutting(2), leaf=True) for line in (zigzag, straight(-0.4))]
    assert (len(own[0]), len(own[1])) == (5, 3)  # every corner gets a joint, whatever max_bones
    result = symmetric_joints(leaves(zigzag, straight(-0.4)), cutting(2), ACROSS_X)
    assert len(result[0]) == len(result[1]) == 5


def test_twins_of_a_body_that_only_roughly_mirrors_meet_halfway():
    """Across a plane the body only roughly mirrors about, twins whose lines differ (a leg bent at a third of its
    length, its twin straight): each joint moves along its own line halfway to where its twin's image falls, first
    joints kept, so the k-th joints come nearer mirroring each other than their own joints would (as near as lines
    of different shapes allow)."""
    bent, other = np.array([[0.0, 0.0, 0.0], [0.13, 0.0, 0.1], [0.4, 0.0, 0.0]]), straight(-0.45)
    own = [chain_joints(line, cutting(4), leaf=True) for line in (bent, other)]
    result = symmetric_joints(leaves(bent, other), cutting(4), ROUGHLY_ACROSS_X)
    assert len(own[0]) == len(own[1]) == len(result[0]) == len(result[1]) > 2
    for line, joints in zip((bent, other), result):
        np.testing.assert_array_equal(joints[0], line[0])
        assert segment_distances(joints, line[:-1], line[1:]).min(axis=1).max() < 1e-9
    apart = [np.linalg.norm(joints - ACROSS_X.reflect(twin), axis=1)[1:] for joints, twin in (result, own)]
    assert (apart[0] <= apart[1] + 1e-9).all() and apart[0].mean() < 0.8 * apart[1].mean()


def test_twins_of_a_body_that_only_roughly_mirrors_mirror_where_they_nearly_do():
    """Two arms 0.08 thick across a plane the body only roughly mirrors about, the right one traced 0.01 deeper and
    its hand bent down, and two legs, the right foot turned 0.03 out: the joints that nearly mirror after meeting
    halfway (the arms' shoulder ends, the legs) become exact mirror images across the body's middle, each within its
    limb; the bent hand's joints, too far from their twins' images for a mean inside both arms, stay on their own
    lines."""
    left = np.array([[0.0, 1.0, 0.0], [0.6, 1.0, 0.0]])
    right = np.array([[0.0, 1.0, 0.01], [-0.42, 1.0, 0.01], [-0.54, 0.9, 0.01]])
    legs = [np.array([[0.0, 0.5, 0.0], [0.3, 0.4, 0.0], [0.3, 0.0, 0.0]]),
            np.array([[0.0, 0.5, 0.0], [-0.3, 0.4, 0.0], [-0.3, 0.05, 0.0], [-0.33, 0.0, 0.0]])]
    lines = (left, right, *legs)
    chains = [(line, np.full(len(line), 0.04), True) for line in lines]
    result = symmetric_joints(chains, cutting(), Symmetry((0, 0.0), 0.15, TUNING, middle=0.0))
    assert len(result[0]) == len(result[1]) > 3 and len(result[2]) == len(result[3]) > 3
    middle = (0, (result[2][1, 0] + result[3][1, 0]) / 2)
    assert abs(middle[1]) < 1e-9
    arms = np.linalg.norm(result[0] - mirrored(result[1], middle), axis=1)
    assert arms[1] < 1e-12 and arms[-1] > 0.05  # the shoulder's joint mirrors, the hand's does not
    np.testing.assert_allclose(result[2][1:], mirrored(result[3][1:], middle), atol=1e-12)
    for k, (line, joints) in enumerate(zip(lines, result)):
        np.testing.assert_array_equal(joints[0], line[0])
        off = segment_distances(joints, line[:-1], line[1:]).min(axis=1)
        mirrors = np.linalg.norm(joints - mirrored(result[k ^ 1], middle), axis=1) < 1e-12
        assert (off[mirrors] <= 0.04).all() and (off[~mirrors] < 1e-9).all()


def test_a_leaf_running_on_along_its_twins_image_takes_that_image():
    """One arm stops at the wrist, its twin runs on into the hand (pruning kept the hand's branch on one side
    only): both are leaves, so the longer takes the shorter's mirror image, its bone count too, either way round,
    each keeping its own first joint. When the longer has chains hanging from its tip (fingers), the shorter takes
    the longer's joints instead; when neither is a leaf, each keeps its own joints with one bone count."""
    arm = np.array([[0.1, 1.0, 0.0], [0.25, 1.0, 0.0]])
    into_hand = np.array([[-0.1, 1.0, 0.03], [-0.25, 1.0, 0.0], [-0.35, 1.1, 0.0], [-0.45, 1.0, 0.0]])
    for lines, longer in (([arm, into_hand], 1), ([into_hand * [-1, 1, 1], arm * [-1, 1, 1]], 0)):
        result = symmetric_joints(leaves(*lines), cutting(), ACROSS_X)
        own = chain_joints(lines[1 - longer], cutting(), leaf=True)
        np.testing.assert_array_equal(result[1 - longer], own)
        np.testing.assert_array_equal(result[longer][0], lines[longer][0])
        np.testing.assert_allclose(result[longer][1:], own[1:] * [-1, 1, 1])
    fingered = [(arm, None, True), (into_hand, None, False)]
    result = symmetric_joints(fingered, cutting(), ACROSS_X)
    np.testing.assert_allclose(result[0][-1], into_hand[-1] * [-1, 1, 1])
    neither = [(arm, None, False), (into_hand, None, False)]
    result = symmetric_joints(neither, cutting(), ACROSS_X)
    np.testing.assert_allclose(result[1][-1], into_hand[-1])
    assert len(result[0]) == len(result[1])


def test_a_leaf_running_on_past_a_twin_that_goes_on_in_its_children_keeps_its_own_joints_beyond():
    """A wing traced from the body to its tip on the left, while on the right the body's chain stops at a shoulder
    junction from which the wing's own chains go on (so it is no leaf): the left wing takes the right stub's image
    as far as the stub goes, then its own joints to its tip, instead of being cut back to the stub (which left the
    rest of the wing without a bone)."""
    stub = np.array([[0.0, 1.0, 0.0], [0.15, 1.0, 0.0]])
    wing = np.array([[0.0, 1.0, 0.0], [-0.15, 1.0, 0.0], [-0.5, 1.0, 0.0]])
    result = symmetric_joints([(stub, None, False), (wing, None, True)], cutting(), ACROSS_X)
    np.testing.assert_array_equal(result[0], chain_joints(stub, cutting()))
    assert len(result[1]) > len(result[0])
    np.testing.assert_allclose(result[1][:len(result[0])], mirrored(result[0], (0, 0.0)))
    np.testing.assert_allclose(result[1][-1], wing[-1])
    assert np.diff(result[1][:, 0]).max() < 0 and np.linalg.norm(np.diff(result[1], axis=0), axis=1).max() <= 0.1


def test_whole_twins_pair_before_partial_ones():
    """A stub off the left shoulder whose tip lies on the right arm's image does not take that arm from its exact
    twin, whichever chain comes first."""
    arm = np.array([[0.1, 1.0, 0.0], [0.5, 1.0, 0.0], [0.9, 1.0, 0.0]])
    stub = np.array([[0.1, 1.0, 0.0], [0.12, 1.0, 0.0]])
    spine = np.array([[0.0, 0.0, 0.0], [0.0, 1.0, 0.0]])
    assert mirror_chain_pairs([spine, stub, arm * [-1, 1, 1], arm], ACROSS_X) == [(2, 3)]
    assert mirror_chain_pairs([spine, arm, stub, arm * [-1, 1, 1]], ACROSS_X) == [(1, 3)]


def test_min_bones_overrides_the_limit():
    """A mirror twin's count wins over ``max_bones``."""
    assert len(chain_joints(straight(0.07), cutting(max_bones=1), min_bones=3)) == 4


def test_an_arm_whose_twin_reaches_into_the_hand_is_still_its_twin():
    """Pruning kept a finger's branch on one side only: that arm runs on into the hand, past the other's tip. The
    two still pair, either way round (their starts mirror, the shorter one's tip lies on the longer one's image),
    and share a label, so every bone is named for its twin; a limb from the same place going elsewhere does not."""
    arm = np.array([[0.1, 1.0, 0.0], [0.5, 1.0, 0.0], [0.9, 1.0, 0.0]])
    into_hand = np.array([[-0.1, 1.0, 0.0], [-0.5, 1.0, 0.0], [-0.9, 1.0, 0.0], [-1.0, 1.1, 0.1]])
    raised = np.array([[-0.1, 1.0, 0.0], [-0.4, 1.4, 0.0], [-0.6, 1.8, 0.0]])
    spine = np.array([[0.0, 0.0, 0.0], [0.0, 1.0, 0.0]])
    paired = ["trunk.00", "limb01.00.L", "limb01.01.L", "limb01.00.R", "limb01.01.R"]
    for left, right in ((arm, into_hand), (into_hand * [-1, 1, 1], arm * [-1, 1, 1])):
        assert bone_names([0, 1, 1, 2, 2], [0, 0, 1, 0, 1], [spine, left, right], ACROSS_X) == paired
    names = bone_names([0, 1, 1, 2, 2], [0, 0, 1, 0, 1], [spine, arm, raised], ACROSS_X)
    assert names == ["trunk.00", "limb01.00.L", "limb01.01.L", "limb02.00.R", "limb02.01.R"]


def test_legs_from_the_middle_of_the_hips_are_named_for_the_side_their_feet_are_on():
    """Legs hanging from the middle of the hips lie mostly near the mirror plane but are still a left and a right
    leg; a trunk that leans off the plane at its tip, with no twin, stays unsided."""
    spine = np.array([[0.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.08, 2.0, 0.0]])  # leaning: its tip is off the plane
    leg = np.array([[0.0, 0.0, 0.0], [0.02, -0.5, 0.0], [0.12, -1.0, 0.0]])  # on the plane on average, tip off it
    names = bone_names([0, 0, 1, 1, 2, 2], [0, 1, 0, 1, 0, 1], [spine, leg, leg * [-1, 1, 1]], ACROSS_X)
    assert names == ["trunk.00", "trunk.01", "limb01.00.L", "limb01.01.L", "limb01.00.R", "limb01.01.R"]


def test_a_limb_that_its_longer_twins_image_covers_becomes_that_image():
    """Ears seen end-on, in a triangulation that is not symmetric: the right one's tip was pruned, leaving a stub
    along the left one's mirror image (its start placed a little apart in depth), or its branch bent, ending near
    the image's tip; either way the right ear becomes that image. A twin as long as the image (a mirror pair
    already) and a limb going elsewhere are left alone."""
    ear = np.array([[0.1, 1.0, 0.0], [0.3, 1.1, 0.0], [0.5, 1.3, 0.0]])
    widths = np.array([0.1, 0.05, 0.01])
    stub = np.array([[-0.1, 1.0, 0.08], [-0.28, 1.09, 0.0]])
    bent = np.array([[-0.1, 1.0, 0.0], [-0.25, 1.16, 0.0], [-0.48, 1.28, 0.0]])
    for short in (stub, bent):
        limbs = mirror_completed([(ear, widths), (short, widths[:len(short)])], ACROSS_X)
        assert limbs[0][0] is ear
        np.testing.assert_array_equal(limbs[1][0], ear * [-1, 1, 1])
        np.testing.assert_array_equal(limbs[1][1], widths)
    twin = ear * [-1, 1, 1] + [0, 0, 0.02]
    elsewhere = np.array([[-0.1, 1.0, 0.0], [-0.3, 0.7, 0.0]])
    for other in (twin, elsewhere):
        assert mirror_completed([(ear, widths), (other, widths)], ACROSS_X)[1][0] is other
    one_twin = mirror_completed([(ear, widths), (stub, widths[:2]), (bent, widths)], ACROSS_X)
    assert one_twin[1][0] is stub and one_twin[2][0] is not bent  # the ear's image replaces the limb it fits best
    leg = np.array([[0.12, 0.95, 0.0], [0.2, 1.03, 0.0]])  # short, beside the ear: its own twin fits it better
    pair = [(leg, widths[:2]), (leg * [-1, 1, 1], widths[:2])]
    limbs = mirror_completed([(ear, widths), (twin, widths)] + pair, ACROSS_X)
    assert all(got is kept for (got, _), (kept, _) in zip(limbs[2:], pair))


def test_a_flat_mesh_is_not_mirrored_across_its_own_plane():
    """A flat cut-out lies on the plane through its thickness, so mirroring across it moves nothing: that is no
    left and right. A flat T symmetric across x = 0 has that plane; a flat L has none."""
    def plane(outline):
        points = np.array([(x, y, 0.0) for x, y in outline], dtype=float)
        points = np.concatenate([points + [dx, dy, 0.0] for dx in (0, 0.01) for dy in (0, 0.01)])
        return mirror_plane(points, column_bounds(points), 0.02, TUNING)

    t_shape = [(x, 1.0) for x in np.linspace(-1, 1, 21)] + [(0.0, y) for y in np.linspace(-1, 1, 21)]
    l_shape = [(x, -1.0) for x in np.linspace(0, 1, 21)] + [(0.0, y) for y in np.linspace(-1, 1, 21)]
    axis, offset = plane(t_shape)
    assert axis == 0 and offset == pytest.approx(0.005)
    assert plane(l_shape) is None


def test_mirror_planes_are_found_alike_at_any_tolerance():
    """A cloud mirrored across x = 0.25 fits that plane and no other, whether the tolerance makes a grid small
    enough to flag every cell or so fine (a millionth of the size) that only the sorted cell keys fit in memory; with
    each point of one half moved five tolerances off its image, none."""
    rng = np.random.default_rng(3)
    half = rng.uniform([0.25, 0.0, 0.0], [1.0, 1.0, 0.6], (500, 3))
    cloud = np.vstack([half, half * [-1, 1, 1] + [0.5, 0, 0]])
    for tolerance in (0.02, 1e-6):
        planes = symmetric_planes(cloud, column_bounds(cloud), tolerance, TUNING)
        assert [(axis, offset) for axis, offset, _ in planes] == [(0, pytest.approx(0.25))]
        away = rng.normal(size=half.shape)
        moved = np.vstack([half, half * [-1, 1, 1] + [0.5, 0, 0] + 5 * tolerance * away / np.linalg.norm(
            away, axis=1, keepdims=True)])
        assert symmetric_planes(moved, column_bounds(moved), tolerance, TUNING) == []


def test_a_mirror_plane_holds_or_not_wherever_the_mesh_lies():
    """Whether a vertex has a mirror image is decided on exact distances, ``plane_reach`` tolerances: half a cloud's
    images moved 0.9 of that off still fit, 1.1 of it off do not, however far the cloud is moved. Hashed to a grid
    alone, the answer hung on where the cells fell: rignet_8184 moved a fifth of its height lost its plane."""
    rng = np.random.default_rng(4)
    half = rng.uniform([0.25, 0.0, 0.0], [1.0, 1.0, 0.6], (600, 3))
    away = rng.normal(size=half.shape) * [0, 1, 1]  # across the plane's normal: the box and its centre stay
    away /= np.linalg.norm(away, axis=1, keepdims=True)
    tolerance, reach = 0.02, TUNING.plane_reach * 0.02
    for share, fits in ((0.9, True), (1.1, False)):
        images = half * [-1, 1, 1] + [0.5, 0, 0]
        images[::2] += share * reach * away[::2]  # every other point: half the images
        for shift in rng.uniform(-1.0, 1.0, (8, 3)):
            cloud = np.vstack([half, images]) + shift
            planes = symmetric_planes(cloud, column_bounds(cloud), tolerance, TUNING)
            assert [axis for axis, _, _ in planes] == ([0] if fits else []), (share, shift)


def test_the_mirror_plane_reflects_a_front_view_onto_itself_and_a_side_view_not_at_all():
    """Two boxes mirrored across x = 2, joined by a bar: seen along Y or -Z every outline point reflects onto the
    outline; seen along X, across the plane, there is no reflection in the view, nor without a plane."""
    vertices, triangles = combine(box((0.0, 0.0, 0.0), (1.0, 2.0, 3.0)), box((3.0, 0.0, 0.0), (4.0, 2.0, 3.0)),
                                  box((0.5, 1.0, 0.0), (3.5, 1.5, 0.5)))
    traces = {view: silhouette.trace(vertices, triangles, view) for view in ("Y", "-Z", "X")}
    for view in ("Y", "-Z"):
        sil = traces[view]
        outline = np.concatenate(sil.loops)
        starts, ends = outline, np.concatenate([np.roll(loop, -1, axis=0) for loop in sil.loops])
        image = reflection_in_view(sil, (0, 2.0), TUNING)(outline)
        assert segment_distances(image, starts, ends).min(axis=1).max() < sil.cell  # onto the outline
        assert np.abs(image - outline).max() > 1  # and moved
    assert reflection_in_view(traces["X"], (0, 2.0), TUNING) is None
    assert reflection_in_view(traces["Y"], None, TUNING) is None


def test_legs_close_together_from_the_middle_of_the_hips_get_their_sides():
    """Legs leaving the middle of the hips whose feet lie 3 hundredths off the plane: on average on the plane, but
    their tips are beyond the side tolerance, so they pair and are named for their sides; with the twin tolerance
    for both, they would stay unsided."""
    spine = np.array([[0.0, 0.0, 0.0], [0.0, 1.0, 0.0]])
    leg = np.array([[0.0, 0.0, 0.0], [0.01, -0.5, 0.0], [0.03, -1.0, 0.0]])
    chains, where = [0, 1, 1, 2, 2], [0, 0, 1, 0, 1]
    names = bone_names(chains, where, [spine, leg, leg * [-1, 1, 1]], Symmetry((0, 0.0), 0.05, TUNING, 0.02))
    assert names == ["trunk.00", "limb01.00.L", "limb01.01.L", "limb01.00.R", "limb01.01.R"]
    assert bone_names(chains, where, [spine, leg, leg * [-1, 1, 1]], ACROSS_X) == [
        "trunk.00", "limb01.00", "limb01.01", "limb02.00", "limb02.01"]


def figure(arm_heights, spine_along):
    """Vertices of a stick figure sampled densely: a spine through the origin along ``spine_along`` (an axis), and
    two arms along x at the given heights (y), one each way."""
    t = np.linspace(0.0, 1.0, 200)[:, None]
    spine = (t - 0.5) * 2 * np.eye(3)[spine_along]
    arms = [np.column_stack([sign * t[:, 0], np.full(len(t), height), np.zeros(len(t))])
            for sign, height in zip((1, -1), arm_heights)]
    return np.concatenate([spine, *arms])


def test_a_roughly_symmetric_body_gets_a_plane_for_its_sides_through_its_spine():
    """Arms at heights 2% of the size apart: no exact mirror plane, but a rough one across x, through the spine;
    with the spine lying along x instead (a side-view cut-out), the only rough plane crosses it: none."""
    vertices = figure((0.52, 0.48), spine_along=1)
    bounds = column_bounds(vertices)
    assert mirror_plane(vertices, bounds, 0.02, TUNING) is None
    spine = np.array([[0.0, -1.0, 0.0], [0.0, 1.0, 0.0]])
    arms = [np.array([[0.0, 0.52, 0.0], [1.0, 0.52, 0.0]]), np.array([[0.0, 0.48, 0.0], [-1.0, 0.48, 0.0]])]
    sides = sided_symmetry(vertices, bounds, 2.0, [spine, *arms], TUNING)
    assert sides.plane == (0, 0.0) and mirror_chain_pairs([spine, *arms], sides) == [(1, 2)]
    lying = figure((0.52, 0.48), spine_along=0)
    along_x = np.array([[-1.0, 0.0, 0.0], [1.0, 0.0, 0.0]])
    assert sided_symmetry(lying, column_bounds(lying), 2.0, [along_x, *arms], TUNING) is None


def test_a_roughly_symmetric_body_s_twins_mirror_where_it_mirrors_best_not_across_its_spine():
    """Points filling a body and two arms, mirrored across x = 0 but for one hand bent down 5% of the size, and a
    traced spine leaning 1.5% of the size to one side (as a posed body's may): the plane for its sides runs through
    the spine, but twins mirror across the body's middle, where most of it mirrors, within ``rough_step``."""
    random = np.random.default_rng(0)
    half = np.concatenate([random.uniform([0.0, -1.0, -0.1], [0.2, 0.5, 0.1], (400, 3)),
                           random.uniform([0.2, 0.45, -0.05], [1.0, 0.55, 0.05], (200, 3))])
    vertices = np.concatenate([half, half * [-1, 1, 1]])
    vertices[vertices[:, 0] < -0.8, 1] -= 0.1
    bounds = column_bounds(vertices)
    assert mirror_plane(vertices, bounds, 0.02, TUNING) is None
    spine = np.array([[0.03, -1.0, 0.0], [0.03, 0.5, 0.0]])
    arms = [np.array([[0.0, 0.5, 0.0], [1.0, 0.5, 0.0]]), np.array([[0.0, 0.5, 0.0], [-1.0, 0.4, 0.0]])]
    sides = sided_symmetry(vertices, bounds, 2.0, [spine, *arms], TUNING)
    assert sides.plane == (0, 0.03) and not sides.exact
    assert sides.twin_plane[0] == 0 and abs(sides.twin_plane[1]) <= TUNING.rough_step * 2.0


def test_copies_of_a_split_chain_keep_their_own_parts_to_the_end():
    """Two arms seen one behind the other (depths 0.5 and 3.5), and past the front one's wrist the rays hit only
    the back one: the front arm's copy keeps its depth instead of running into the back arm, so the two arms end
    apart and each carries its own hand."""
    node_layers = [layers((0, 4))] * 4 + [layers((0, 1), (3, 4))] * 12 + [layers((3, 4))] * 3
    _, placed = placed_along_x(node_layers)
    tips = sorted(line[-1, 2] for line, _, _ in placed)
    np.testing.assert_allclose(tips, [0.5, 3.5])


def test_fingers_seen_edge_on_end_each_at_its_own_depth_not_in_the_longest_one():
    """Four fingers seen edge-on (depths 0.5, 2.5, 4.5, 6.5), and past the shorter ones' tips the rays hit only the
    longest finger, curling a little off its line (3.05 to 3.6): that finger's copy, the nearest, steps into it and
    the others keep their depths. Every copy stepping in ran three fingers' tips into one point in the fourth (a
    trooper's hands, a cow's ears ending between them)."""
    node_layers = ([layers((0, 7))] * 4 + [layers((0, 1), (2, 3), (4, 5), (6, 7))] * 8
                   + [layers((3.05, 3.6))] * 3)
    _, placed = placed_along_x(node_layers)
    tips = sorted(line[-1, 2] for line, _, _ in placed)
    np.testing.assert_allclose(tips, [0.5, 3.325, 4.5, 6.5])


def test_split_legs_run_down_the_middle_of_each_leg_not_at_their_feet_depth():
    """A splayed leg pair seen from the side: merged with the body, then each leg apart (depths 2 to 4 and their
    mirror), ending in a foot turned out (3.5 to 4.5). Each leg's copy runs down the middle of its leg wherever the
    legs are apart, not at its foot's depth all the way up; it keeps its depth only where they merge."""
    node_layers = ([layers((-4, 4))] * 4 + [layers((-4, -2), (2, 4))] * 10
                   + [layers((-4.5, -3.5), (3.5, 4.5))] * 3)
    _, placed = placed_along_x(node_layers, mirror=(0.0, 0.05))
    legs = sorted((line for line, _, widths in placed if widths.any()), key=lambda line: line[-1, 2])
    assert len(legs) == 2
    for leg, sign in zip(legs, (-1, 1)):
        np.testing.assert_allclose(leg[-3:, 2], 4.0 * sign)
        np.testing.assert_allclose(leg[-13:-3, 2], 3.0 * sign)


def test_a_stubby_leg_standing_on_the_ground_with_the_others_is_a_leg():
    """A body (radius 1) on two thin legs whose feet stand on the ground (y = -3.2), and a stubby leg as long as it
    is thick whose foot stands there too: under prune it is a bump, but it stands where the kept legs stand, so it
    stays; without the ground, or off the ground, it goes."""
    nodes = [(0.0, 0.0, 1.0)]
    chains = []
    for part in ([(x, y, 0.2) for y in np.linspace(-1.2, -3.0, 6)] for x in (-0.5, -1.5)):
        chains.append([0] + list(range(len(nodes), len(nodes) + len(part))))
        nodes += part

    def kept(stub, ground=((-5.0, -3.2), (5.0, 5.0), 0.1)):
        points = np.array(nodes + stub)
        branch = [[0] + list(range(len(nodes), len(nodes) + len(stub)))]
        links = prune_spurs(points[:, :2], points[:, 2], chains + branch, Pruning(1.35, pair_prune=0.74, ground=ground))
        return len(nodes) + len(stub) - 1 in links

    stubby = [(1.2, -0.8, 1.4), (2.0, -1.4, 1.4), (2.5, -1.8, 1.4)]  # its foot reaches y = -3.2
    assert kept(stubby)
    assert not kept(stubby, ground=None)
    assert not kept([(x, y + 0.5, r) for x, y, r in stubby])


def test_stubby_legs_off_two_bases_standing_on_the_ground_are_legs_together():
    """A body seen from the side (rump and chest, radius 1, at x = ±2) with a thin tail and neck, and under each a
    leg as long as it is thick standing on the ground (y = -3.2): every leg is a bump under prune and none of the
    kept leaves stands there, but the two legs stand there together, so both stay. Two such stubs off one base (a
    forked fin) do not: a pair off one base is judged by the pairing rules."""
    def kept_legs(legs_at, mirror=None):
        nodes = [(-2.0, 0.0, 1.0), (2.0, 0.0, 1.0), (0.0, 0.0, 1.0)]  # rump, chest, the belly between
        chains = [[0, 2, 1]]
        for base, direction in ((0, -1.0), (1, 1.0)):  # a thin tail and a thin neck, off the ground
            chains.append([base] + list(range(len(nodes), len(nodes) + 6)))
            nodes += [(direction * (2.0 + 0.5 * k), 0.5 * k, 0.2) for k in range(1, 7)]
        feet = []
        for base, x, r, foot in legs_at:
            chains.append([base] + list(range(len(nodes), len(nodes) + 3)))
            low = -3.2 + foot  # the foot's disc reaches the ground, y = -3.2
            nodes += [(x, -0.8, r), (x, 0.5 * (low - 0.8), r), (x, low, foot)]
            feet.append(len(nodes) - 1)
        points = np.array(nodes)
        links = prune_spurs(points[:, :2], points[:, 2], chains,
                            Pruning(1.35, pair_prune=0.74, ground=((-9.0, -3.2), (9.0, 9.0), 0.1), mirror=mirror))
        return [foot in links for foot in feet]

    assert kept_legs([(0, -2.0, 1.4, 1.4), (1, 2.0, 1.4, 1.4)]) == [True, True]
    # feet 2.8 apart, legs 2.2 and 3.0 wide: too close for the wider, so for both
    assert kept_legs([(0, -1.4, 1.4, 0.8), (1, 1.4, 2.2, 0.8)]) == [False, False]
    assert kept_legs([(0, -3.5, 1.4, 1.4), (0, -0.5, 1.4, 1.4)]) == [False, False]
    # across a mirror in the view, twin spurs pair by the mirror rules alone (here: off two bases, none)
    assert kept_legs([(0, -2.0, 1.4, 1.4), (1, 2.0, 1.4, 1.4)], mirror=lambda p: p * [-1.0, 1.0]) == [False, False]


def test_an_axis_jumping_from_a_disc_into_a_corner_is_no_limb():
    """A body's disc (radius 1) with a long arm each way, and an axis branch jumping from the disc straight to a
    node by the outline's bottom edge (y = -2.1) whose half-width (0.1) is the corner's: by its nodes it sticks out
    ten widths, a limb. Where it leaves the disc the body is 2.2 wide (the outline is 1.1 away): a bump, pruned."""
    points = np.array([(0.0, 0.0), (-2.0, 0.0), (-3.0, 0.0), (-4.0, 0.0), (2.0, 0.0), (3.0, 0.0), (4.0, 0.0),
                       (0.0, -2.0), (0.0, -2.05)])
    radius = np.array([1.0, 0.3, 0.3, 0.3, 0.3, 0.3, 0.3, 0.1, 0.0])
    chains = [[0, 1, 2, 3], [0, 4, 5, 6], [0, 7, 8]]
    outline = loop_edges([np.array([(-5.0, -2.1), (5.0, -2.1), (5.0, 1.2), (-5.0, 1.2)])])
    assert 8 in prune_spurs(points, radius, chains, Pruning(1.35))
    assert 8 not in prune_spurs(points, radius, chains, Pruning(1.35, outline=outline))
    assert 3 in prune_spurs(points, radius, chains, Pruning(1.35, outline=outline))


def test_a_straight_leg_gets_its_knee_where_it_narrows():
    """A straight leg 0.4 long cut into four bones of 0.1: evenly, its joints would fall at 0.1, 0.2 and 0.3; its
    width narrows to 0.6 of the thigh's and calf's at 0.23 (the knee), where a joint goes instead."""
    line = straight(0.4, 81)
    along = line[:, 0]
    widths = 0.03 - 0.012 * np.exp(-((along - 0.23) / 0.02) ** 2)
    joints = chain_joints(line, cutting(4), widths, leaf=True)
    assert len(joints) == 5
    assert np.abs(joints[:, 0] - 0.23).min() < 0.006
    even = chain_joints(line, cutting(4), np.full(len(line), 0.03), leaf=True)
    assert np.abs(even[:, 0] - 0.23).min() > 0.02
