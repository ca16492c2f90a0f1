"""The silhouette method's tuning table: every tuned number, each with the reason for its value.

Lengths are in bone lengths (the ``bone_length`` parameter times the mesh's size) unless the line says otherwise.
The numbers that cutting chains into bones and mirror symmetry use come from ``core.joints.JointTuning`` and
``core.mirror.MirrorTuning``, declared there. ``python -m rigger methods --tuning`` prints the whole table. Guards
against rounding (1e-9 of a length, 1e-12 of a width) stay in the code: they are not tuned.
"""
from dataclasses import dataclass

from ...core.joints import JointTuning
from ...core.mirror import MirrorTuning
from ...core.tuning import tuned


@dataclass(frozen=True)
class Tuning(JointTuning, MirrorTuning):
    """Every tuned number of the silhouette method."""

    # 1. the view
    spread_samples: int = tuned(100_000, "triangles sampled to choose the view: a regular sample gives the variance")
    axis_snap: float = tuned(1e-6, "view_direction components this small beside its largest are zero (a 3D view's "
                                   "float32 noise)")
    min_view_resolution: int = tuned(64, "the coarsest grid any view gets (also the resolution parameter's minimum)")
    end_resolution: float = tuned(1 / 3, "the end-on view only looks for limbs, coarse features: it gets this share "
                                         "of the resolution")
    along_plane: float = tuned(1e-6, "a view whose direction has no larger component along the mirror plane's axis "
                                     "looks along the plane")
    # 4. merging and pruning
    keep_reach: float = tuned(0.25, "branches reaching this share of the mesh's size are kept however wide (a "
                                    "cow's neck and head)")
    pair_prune: float = tuned(0.55, "two twin branches sticking out more than this share of prune times their width "
                                    "are limbs (a dog's ears)")
    local_pair: float = tuned(1.5, "without a mirror plane, two branches off one base pair when their reach ratio "
                                   "times width ratio is at most this; with one, twins this alike pair when their "
                                   "tips' images miss each other by less than a width")
    straight_on: float = tuned(30.0, "degrees: a spur on the mirror plane going on from a chain on it through its "
                                     "base within this turn stays (a head on its neck) ...")
    straight_reach: float = tuned(0.5, "... when it reaches beyond the base's disc by this share of its radius")
    round_tip: float = tuned(0.7, "a branch ending in a blob this share of its base's width, off the base's disc, is "
                                  "a part (a head without a neck)")
    ground_reach: float = tuned(0.03, "a branch tip this close (share of the size) to a side of the outline stands on "
                                      "it, as legs stand on the ground")
    width_nodes: int = tuned(3, "a branch's width is its mean over this many nodes past the base's disc (a neck, "
                                "not the head it carries)")
    # 5. rooting
    contact: float = tuned(0.5, "a cycle narrowing to this share of its median width is two parts touching (a "
                                "curled tail's tip on the back): it is cut there")
    column_ratio: float = tuned(1.25, "a path whose widest node is at most this many times its median width is a "
                                      "column, rooted at its thicker end, not a body")
    end_divisor: int = tuned(4, "which end of a column is thicker is judged on its first and last 1/this of nodes")
    # 6. depth
    occlusion_ratio: float = tuned(2.5, "an interval this many times thicker than the part is wide is another part "
                                        "in front of it")
    sheet_thickness: float = tuned(0.2, "depth intervals thinner than this many half-widths are sheets, not parts")
    split_share: float = tuned(0.3, "a chain splits when this share of its outer nodes cross the same number (> 1) "
                                    "of parts")
    near_parent_divisor: int = tuned(3, "a chain's first 1/this of nodes (near its parent, often in the body) do not "
                                        "count for splitting")
    fork_share: float = tuned(0.8, "parts apart over this share of a chain's outer nodes fork where that stretch "
                                   "begins")
    round_part: float = tuned(1.5, "a part at most this many times as thick along the view as it is wide is one "
                                   "limb, not two side by side")
    part_thickness: float = tuned(0.8, "a separate part is at least this many of its half-widths thick along the "
                                       "view")
    part_alike: float = tuned(0.45, "a separate part is at least this share of the thickest one's thickness (not a "
                                    "nose beside a head)")
    copy_jump: float = tuned(1.0, "past the node where a split chain's parts are last apart, a copy steps to a part "
                                  "at most this many part widths away (not to the part another copy follows)")
    side_width_cost: float = tuned(0.1, "matching a side-view node, a width difference costs this much per unit of "
                                        "depth difference")
    # 8. islands
    speck: float = tuned(0.25, "islands whose axis is shorter than this get no bones (skinning gives them to the "
                               "nearest bone)")
    # 9. hidden limbs
    hidden_reach: float = tuned(0.6, "a perpendicular-view limb tip this far off the skeleton (seen that way) is "
                                     "missing from it")
    hidden_prune: float = tuned(2 / 3, "the perpendicular views prune at this share of prune: their limbs must also "
                                       "be hidden and off the skeleton")
    path_samples: int = tuned(256, "most points tested along a path from a hidden limb to a bone it may hang from")
    path_candidates: int = tuned(32, "paths from a hidden limb are tried to this many of the nearest bones at most")
    path_slack: float = tuned(0.15, "a path from a hidden limb to its bone may leave the mesh for this long in all "
                                    "(grazing its surface)")
    bridge_reach: float = tuned(1.0, "a hidden limb starting farther than this from its bone is extended back to it")
    share_reach: float = tuned(0.5, "limbs extended from one bone share the extension when their starts and "
                                    "meeting points lie this close (their starts: or this share of the longer "
                                    "extension, parting by under 30°)")
