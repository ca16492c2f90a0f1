"""Skinning inside Blender (bpy from PyPI, headless): every vertex weighted, whatever bone heat does, and the copies
of a vertex that seams split weighted alike.

The generated characters are skinned with their own true skeletons. Seams are made as UV unwrapping and flat shading
make them: the body split where its parts meet, a flat-shaded (UV-split) skirt whose faces, each its own piece, would
hide behind the body and make bone heat fail on the split mesh. Accessories (plates around the waist, an eye and a
tooth inside the head, a sliver and a speck of collapsed faces) sit on the body. Bone heat's failures are forced with
real geometry: half-bands the body hides from the bones running through them, and a flat-shaded bead of debris on a
bone, which need every stage of the repair ladder. Quaternius' fox from ../shared fails in Blender as the skirt
would; CesiumMan and rignet_smith cracked open at their seams.
"""
import math

import numpy as np
import pytest

from conftest import shared_path
from meshes import combine, cylinder

bpy = pytest.importorskip("bpy")
import bmesh  # noqa: E402  (Blender's own module, importable once bpy is)
from mathutils import Vector  # noqa: E402
from mathutils.bvhtree import BVHTree  # noqa: E402
from mathutils.interpolate import poly_3d_calc  # noqa: E402

from rigger import samples  # noqa: E402
from rigger.blender import skinning  # noqa: E402
from rigger.blender.armature import build_armature  # noqa: E402
from rigger.blender.meshdata import mesh_vertices, world_points  # noqa: E402
from rigger.blender.samples import build_character  # noqa: E402
from rigger.core.accessories import CONTACT  # noqa: E402
from rigger.core.polyline import segment_distances  # noqa: E402
from rigger.core.skeleton import Skeleton  # noqa: E402

import rigdata  # noqa: E402
from skinning import seam_gap  # noqa: E402  (bench/skinning.py: the benchmark's own seam measure)

NEAR_FRACTION = 0.05  # a vertex's dominant bone is at most this fraction of the model's size farther than its nearest
NEAREST_SHARE = 0.9  # at least this share of vertices is dominated by their nearest bone


def character_with_rig(name, subdivisions=1):
    return build_character(name, subdivisions), build_armature(samples.ground_truth_bones(name), f"{name}_rig")


def bone_names(armature):
    return [bone.name for bone in armature.data.bones if bone.use_deform]


def bone_ends(armature, names):
    """World-space heads and tails (B, 3) of the named bones in rest pose, read from the armature here rather than
    through the skinning code under test."""
    bones = [armature.data.bones[name] for name in names]
    ends = world_points(np.array([(bone.head_local, bone.tail_local) for bone in bones]), armature.matrix_world)
    return ends[:, 0], ends[:, 1]


def assert_skinned(obj, armature, report, checked=slice(None), nearest_share=NEAREST_SHARE):
    """Every vertex weighted, weights normalised, one Armature modifier last, and the dominant bone of each
    ``checked`` vertex near it."""
    names = bone_names(armature)
    table = rigdata.vertex_weights(obj, names)
    assert report.unweighted == 0
    assert (table.max(axis=1) > 0).all(), f"{(table.max(axis=1) == 0).sum()} vertices unweighted"
    np.testing.assert_allclose(table.sum(axis=1), 1.0, atol=1e-5)
    points = world_points(mesh_vertices(obj.data), obj.matrix_world)
    size = np.ptp(points, axis=0).max()
    points = points[checked]
    distances = segment_distances(points, *bone_ends(armature, names))
    dominant = table[checked].argmax(axis=1)
    gap = distances[np.arange(len(points)), dominant] - distances.min(axis=1)
    assert gap.max() <= NEAR_FRACTION * size, f"a vertex's dominant bone is {gap.max() / size:.3f} sizes too far"
    assert (dominant == distances.argmin(axis=1)).mean() >= nearest_share
    modifiers = [m for m in obj.modifiers if m.type == 'ARMATURE']
    assert len(modifiers) == 1 and modifiers[0].object == armature and obj.modifiers[-1] == modifiers[0]
    assert modifiers[0].name == skinning.MODIFIER_NAME and obj.parent == armature


def stage_names(report):
    return [stage.name for stage in report.stages]


def assert_seams_weighted_alike(obj, armature):
    """Vertices at one position (a seam's copies) carry exactly the same weights; there are such vertices."""
    positions = mesh_vertices(obj.data)
    place = np.unique(positions, axis=0, return_inverse=True)[1].ravel()
    assert len(np.unique(place)) < len(positions), "the mesh has no seam to test"
    gap = seam_gap(rigdata.vertex_weights(obj, bone_names(armature)), place)
    assert gap == 0, f"a seam's copies differ by {gap:.3f} in one bone's weight"


def split_between_bones(obj, skeleton):
    """Split ``obj``'s surface along the edges between faces nearest to different bones, as UV islands split a
    character where its parts meet; returns how many vertices the split added."""
    before = len(obj.data.vertices)
    work = bmesh.new()
    work.from_mesh(obj.data)
    work.faces.ensure_lookup_table()
    centres = np.array([face.calc_center_median() for face in work.faces])
    part = segment_distances(centres, skeleton.heads, skeleton.tails).argmin(axis=1)
    seams = [edge for edge in work.edges if len(edge.link_faces) == 2
             and part[edge.link_faces[0].index] != part[edge.link_faces[1].index]]
    bmesh.ops.split_edges(work, edges=seams)
    work.to_mesh(obj.data)
    work.free()
    return len(obj.data.vertices) - before


# generated characters


@pytest.mark.parametrize("name", list(samples.CHARACTERS))
def test_every_character_skinned_with_its_own_rig(scene, name):
    obj, armature = character_with_rig(name)
    report = skinning.skin(obj, armature)
    assert_skinned(obj, armature, report)
    assert stage_names(report) == ["bone heat"] and report.stages[0].weighted == report.vertices
    assert report.level == "INFO" and not report.warnings and not report.messages
    assert report.bones == len(samples.ground_truth_bones(name)) and report.vertices == len(obj.data.vertices)
    assert report.summary().startswith(f"Skinned {name!r} to '{name}_rig'")


def test_modifiers_stay_and_the_armature_goes_last_weights_on_the_original_vertices(scene):
    obj, armature = character_with_rig("humanoid")
    obj.modifiers.new("Smooth", 'SUBSURF').levels = 1
    depsgraph = bpy.context.evaluated_depsgraph_get()
    before = mesh_vertices(obj.evaluated_get(depsgraph).data)
    report = skinning.skin(obj, armature)
    assert [m.type for m in obj.modifiers] == ['SUBSURF', 'ARMATURE']
    assert report.vertices == len(obj.data.vertices) < len(before)
    assert_skinned(obj, armature, report)
    # in rest pose the armature moves nothing; posing a bone moves the mesh there
    depsgraph = bpy.context.evaluated_depsgraph_get()
    rest = mesh_vertices(obj.evaluated_get(depsgraph).data)
    np.testing.assert_allclose(rest, before, atol=1e-5)
    armature.pose.bones["forearm.L"].rotation_mode = 'XYZ'
    armature.pose.bones["forearm.L"].rotation_euler = (1.0, 0.0, 0.0)
    bpy.context.view_layer.update()
    posed = mesh_vertices(obj.evaluated_get(bpy.context.evaluated_depsgraph_get()).data)
    moved = np.linalg.norm(posed - rest, axis=1) > 1e-3
    assert moved.any() and (rest[moved, 0] > 0.3).all()  # only the left forearm and hand (x > 0.3) move


def test_the_mesh_keeps_its_place_when_transformed_and_parented(scene):
    obj = build_character("quadruped", subdivisions=1)
    holder = bpy.data.objects.new("holder", None)
    scene.collection.objects.link(holder)
    holder.location, holder.rotation_euler, holder.scale = (1.0, 2.0, -1.0), (0.3, -0.2, 0.5), (2.0, 2.0, 2.0)
    obj.parent = holder
    obj.location, obj.rotation_euler, obj.scale = (0.5, 0.0, 0.2), (0.0, 0.4, 0.0), (1.0, 1.5, 1.0)
    bpy.context.view_layer.update()
    world = np.array(obj.matrix_world)
    skeleton = samples.ground_truth_bones("quadruped").transformed(world)  # the rig sits where the mesh is seen
    armature = build_armature(skeleton, "rig")
    for each in scene.objects:
        each.select_set(each == holder)
    bpy.context.view_layer.objects.active = holder
    report = skinning.skin(obj, armature)
    bpy.context.view_layer.update()
    np.testing.assert_allclose(np.array(obj.matrix_world), world, atol=1e-5)
    assert bpy.context.view_layer.objects.active == holder
    assert list(bpy.context.view_layer.objects.selected) == [holder]
    assert_skinned(obj, armature, report)
    assert report.level == "INFO"


def test_hidden_and_unlinked_objects_are_skinned_too(scene):
    obj, armature = character_with_rig("snake")
    obj.hide_viewport = True  # Blender's weight operators refuse hidden objects in their poll
    scene.collection.objects.unlink(armature)
    report = skinning.skin(obj, armature)
    assert_skinned(obj, armature, report)
    assert report.level == "INFO"


def test_skinning_again_replaces_the_modifier_and_groups(scene):
    obj, armature = character_with_rig("snake")
    first = skinning.skin(obj, armature)
    weights = rigdata.vertex_weights(obj, bone_names(armature))
    obj.vertex_groups.new(name="user paint")
    second = skinning.skin(obj, armature)
    assert_skinned(obj, armature, second)
    assert sorted(g.name for g in obj.vertex_groups) == sorted(bone_names(armature) + ["user paint"])
    np.testing.assert_allclose(rigdata.vertex_weights(obj, bone_names(armature)), weights, atol=1e-6)
    assert first.summary().split(":")[0] == second.summary().split(":")[0]

    # a new armature with other bone names: the old groups go, the new ones come, still one modifier
    other = build_armature(samples.ground_truth_bones("snake"), "other")
    bpy.ops.object.mode_set(mode='OBJECT')
    for bone in other.data.bones:
        bone.name = f"new_{bone.name}"
    third = skinning.skin(obj, other)
    assert_skinned(obj, other, third)
    assert sorted(g.name for g in obj.vertex_groups) == sorted(bone_names(other) + ["user paint"])


def test_bad_input_is_a_clear_value_error(scene):
    obj, armature = character_with_rig("snake", subdivisions=0)
    camera = bpy.data.objects.new("camera", bpy.data.cameras.new("camera"))
    empty_mesh = bpy.data.objects.new("empty", bpy.data.meshes.new("empty"))
    bare = bpy.data.objects.new("bare", bpy.data.armatures.new("bare"))
    scene.collection.objects.link(bare)
    cases = [((camera, armature), "camera object 'camera'"), ((None, armature), "NoneType"),
             ((armature, obj), "armature object"), ((obj, camera), "armature object to skin to"),
             ((empty_mesh, armature), "no vertices"), ((obj, bare), "has no bones")]
    for (mesh_obj, armature_obj), message in cases:
        with pytest.raises(ValueError, match=message):
            skinning.skin(mesh_obj, armature_obj)
    for bone in armature.data.bones:
        bone.use_deform = False
    with pytest.raises(ValueError, match="no deforming bones"):
        skinning.skin(obj, armature)
    assert not obj.modifiers and not obj.vertex_groups and obj.parent is None


# forced failures, reproduced with real geometry


def surface_of_revolution(mesh, profile, segments):
    """A bmesh of ``mesh`` plus quads through rings of (radius, height) around the Z axis, one band per profile step,
    facing outwards where the profile descends; returns it and the new faces."""
    work = bmesh.new()
    work.from_mesh(mesh)
    rings = [[work.verts.new((radius * math.cos(2 * math.pi * s / segments),
                              radius * math.sin(2 * math.pi * s / segments), height)) for s in range(segments)]
             for radius, height in profile]
    faces = [work.faces.new((ring[s], next_ring[s], next_ring[(s + 1) % segments], ring[(s + 1) % segments]))
             for ring, next_ring in zip(rings, rings[1:]) for s in range(segments)]
    return work, faces


def add_faceted_skirt(obj):
    """A skirt flaring from a ledge at the humanoid's waist, its faces split apart as a flat-shaded, UV-seamed export
    leaves them. Each face hides behind the body from every bone, so each is a piece with no heat source: Blender's
    heat system is singular. Welded, the skirt hangs from the ledge, which reaches inside the body and gets heat."""
    segments = 6
    work, faces = surface_of_revolution(obj.data, [(0.06, 1.0), (0.2, 1.0), (0.3, 0.75)], segments)
    skirt = faces[segments:]
    bmesh.ops.split_edges(work, edges=list({edge for face in skirt for edge in face.edges}))
    work.to_mesh(obj.data)
    work.free()


def test_a_character_split_along_seams_gets_one_weight_per_place_from_bone_heat(scene):
    """Bone heat on the split mesh gave a seam's two sides different weights (up to 0.94 of a bone's weight apart):
    posed, the body opened along its seams. Welded first, each place gets one set of weights."""
    obj, armature = character_with_rig("humanoid")
    added = split_between_bones(obj, samples.ground_truth_bones("humanoid"))
    report = skinning.skin(obj, armature)
    assert stage_names(report) == ["bone heat"] and report.stages[0].weighted == report.vertices
    assert report.welded == added > 100 and report.stages[0].note == f"{added} seam vertices welded"
    assert report.level == "INFO" and f"{added} seam vertices welded" in report.summary()
    assert_skinned(obj, armature, report)
    assert_seams_weighted_alike(obj, armature)
    assert skinning.TEMPORARY_NAME not in bpy.data.objects and skinning.TEMPORARY_NAME not in bpy.data.meshes


def test_a_uv_split_skirt_is_weighted_by_bone_heat_on_the_welded_mesh(scene):
    """Each face of the skirt, its own piece, hides behind the body from every bone: on the split mesh Blender's
    heat system is singular. Welded, the skirt hangs from a ledge that reaches inside the body and gets heat."""
    obj, armature = character_with_rig("humanoid")
    body = len(obj.data.vertices)
    add_faceted_skirt(obj)
    report = skinning.skin(obj, armature)
    assert report.bone_heat_result == "FINISHED" and not report.messages
    assert stage_names(report) == ["bone heat"] and report.stages[0].weighted == report.vertices
    assert_skinned(obj, armature, report, checked=slice(body))  # the skirt takes its weights from the hips
    assert_seams_weighted_alike(obj, armature)
    assert report.level == "INFO"


def add_accessories(obj):
    """Armour plates around the humanoid's waist (each its own loose part, hidden behind the body from every bone),
    an eye inside the head, a tooth inside its lower front, and two kinds of debris exported meshes carry: a sliver
    (a face whose corners lie on one line) and a speck (faces collapsed to one point). No bone runs through any of
    them. Returns the vertex indices of each, by name."""
    segments = 6
    first = len(obj.data.vertices)
    work, faces = surface_of_revolution(obj.data, [(0.2, 1.0), (0.3, 0.75)], segments)
    bmesh.ops.split_edges(work, edges=list({edge for face in faces for edge in face.edges}))
    for face in faces:  # shrink each plate so that no welding joins it to the next
        centre = face.calc_center_median()
        for vertex in face.verts:
            vertex.co = centre + 0.9 * (vertex.co - centre)
    work.verts.index_update()
    parts = {"plates": np.arange(first, len(work.verts))}
    for name, centre in (("eye", (0.03, -0.06, 1.68)), ("tooth", (0.0, -0.07, 1.61))):
        sphere = bmesh.ops.create_icosphere(work, subdivisions=1, radius=0.02)["verts"]
        bmesh.ops.translate(work, verts=sphere, vec=centre)
        work.verts.index_update()
        parts[name] = np.array([vertex.index for vertex in sphere])
    work.faces.new([work.verts.new((-0.5, 0.5, 0.5 + 0.01 * k)) for k in range(3)])
    speck = [work.verts.new((0.5, 0.5, 0.5)) for _ in range(4)]
    work.faces.new(speck[:3])
    work.faces.new(speck[1:])
    work.verts.index_update()
    parts["speck"] = np.array([vertex.index for vertex in speck])
    work.to_mesh(obj.data)
    work.free()
    return parts


def surface_blend(obj, table, body, points):
    """Weights at the point of ``obj``'s faces among vertices ``body`` nearest to each of ``points`` (its face's
    corner weights, rows of ``table``, blended by Blender's own barycentric interpolation), and how far it is."""
    positions = mesh_vertices(obj.data)
    inside = np.zeros(len(positions), dtype=bool)
    inside[body] = True
    obj.data.calc_loop_triangles()
    faces = [list(triangle.vertices) for triangle in obj.data.loop_triangles if inside[list(triangle.vertices)].all()]
    tree = BVHTree.FromPolygons(positions.tolist(), faces)
    blended, distances = [], []
    for point in points:
        location, _, face, distance = tree.find_nearest(Vector(point))
        corners = faces[face]
        shares = poly_3d_calc([Vector(positions[corner]) for corner in corners], location)
        blended.append(np.array(shares) @ table[corners])
        distances.append(distance)
    return np.array(blended), np.array(distances)


def test_accessories_move_as_one_piece_with_the_surface_they_sit_on(scene):
    """Bone heat on an ogre's tongue, which sees the throat, gave it the neck: turning the head pushed it out through
    the cheek. A loose part no bone runs through now moves as one piece with the body's surface nearest to it,
    whatever the stages before gave it (here the hidden plates make bone heat fail, and every part is repaired)."""
    obj, armature = character_with_rig("humanoid")
    body = len(obj.data.vertices)
    parts = add_accessories(obj)
    report = skinning.skin(obj, armature)
    assert stage_names(report) == ["bone heat", "island bone heat", "nearest bones", "surface weights"]
    assert report.stages[-1].weighted == report.vertices - body
    assert report.stages[-1].note == "10 loose parts no bone runs through"  # 6 plates, eye, tooth, sliver, speck
    assert f"{report.vertices - body} vertices of 10 loose parts no bone runs through moved" in report.summary()
    assert_skinned(obj, armature, report, checked=slice(body))
    table = rigdata.vertex_weights(obj, bone_names(armature))
    positions = mesh_vertices(obj.data)
    names = bone_names(armature)
    for part, bone in (("eye", "head_top"), ("tooth", "head")):  # above and below the head's joint (bones are
        # named after the joint they end at)
        rows = table[parts[part]]
        assert len({tuple(row) for row in rows}) == 1  # one piece
        blended, distances = surface_blend(obj, table, np.arange(body), positions[parts[part]])
        closeness = 1 / (distances + CONTACT * np.ptp(positions[parts[part]], axis=0).max())  # the contact counts most
        np.testing.assert_allclose(rows[0], closeness @ blended / closeness.sum(), atol=1e-5)
        assert names[rows[0].argmax()] == bone
    assert len({tuple(row) for row in table[parts["speck"]]}) == 1  # the coincident vertices get the same weights


def test_a_mesh_without_faces_has_no_accessories(scene):
    """Each point its own part, no bone through most: they would sit on a body without a face."""
    obj, armature = character_with_rig("humanoid")
    points = mesh_vertices(obj.data)[::7]
    cloud = mesh_object("cloud", points, np.zeros((0, 3), dtype=np.int64))
    cloud.matrix_world = obj.matrix_world
    report = skinning.skin(cloud, armature)
    assert skinning.SURFACE_STAGE not in stage_names(report) and report.unweighted == 0
    assert_skinned(cloud, armature, report)


def add_hidden_halves(obj):
    """Two half-bands around the humanoid's waist, out of the body (the back one a little wider, so that no welding
    joins them): the spine and the hips run through the box of each, but the body hides them from every bone, so
    Blender's heat system is singular."""
    work = bmesh.new()
    work.from_mesh(obj.data)
    for half in (0, 1):
        widen = 1.0 + 0.05 * half
        rings = [[work.verts.new((widen * radius * math.cos(math.pi * (half + step / 2)),
                                  widen * radius * math.sin(math.pi * (half + step / 2)), height)) for step in range(3)]
                 for radius, height in ((0.2, 1.0), (0.3, 0.75))]
        for step in range(2):
            work.faces.new((rings[0][step], rings[1][step], rings[1][step + 1], rings[0][step + 1]))
    work.to_mesh(obj.data)
    work.free()


def test_loose_parts_hidden_from_every_bone_are_repaired_part_by_part_then_by_distance(scene):
    obj, armature = character_with_rig("humanoid")
    add_hidden_halves(obj)
    bead = add_bead(obj, samples.ground_truth_bones("humanoid").heads[0])  # on a bone: one point no heat reaches
    report = skinning.skin(obj, armature)
    assert any(skinning.FAILURE_MESSAGE in message for message in report.stages[0].messages)
    assert stage_names(report) == ["bone heat", "island bone heat", "nearest bones"]
    heat, islands, nearest = report.stages
    assert heat.weighted == 0  # the hidden halves make the heat system singular
    assert islands.weighted == report.vertices - len(bead) and nearest.weighted == len(bead)
    assert islands.note == "3 of 4 loose parts tried"  # the bead has no faces left
    assert_skinned(obj, armature, report)
    assert report.level == "WARNING" and f"nearest bones {len(bead)}" in report.summary()
    table = rigdata.vertex_weights(obj, bone_names(armature))
    assert len({tuple(row) for row in table[bead]}) == 1  # the coincident vertices get the same weights


def add_bead(obj, centre, size=2e-6):
    """A flat-shaded bead of debris, far smaller than the weld distance: a tetrahedron whose faces each have their
    own corners (12 vertices at 4 places, 4 normals), the first at ``centre``. Welded, it is one vertex there without
    a face, which only the nearest-bones fallback weights when a bone runs through it. Returns its vertex indices."""
    work = bmesh.new()
    work.from_mesh(obj.data)
    corners = np.array([(0, 0, 0), (2, 0, 0), (0, 2, 0), (0, 0, 2)]) * size + np.array(centre)
    first = len(work.verts)
    for face in ((0, 1, 2), (0, 3, 1), (0, 2, 3), (1, 3, 2)):
        work.faces.new([work.verts.new(corners[corner]) for corner in face])
    work.to_mesh(obj.data)
    work.free()
    return np.arange(first, first + 12)


def test_every_repair_stage_weights_a_seams_copies_alike(scene):
    """A seam-split body beside hidden half-bands: bone heat fails on the whole, each part is weighted alone (the split
    body welded), and the bead on a bone goes to the nearest bones. The fallback's facing penalty took each
    copy's own face normal: a bead's copies were up to 0.74 of a bone's weight apart, for one point in space."""
    obj, armature = character_with_rig("humanoid")
    split_between_bones(obj, samples.ground_truth_bones("humanoid"))
    add_hidden_halves(obj)
    bead = add_bead(obj, samples.ground_truth_bones("humanoid").heads[0])
    report = skinning.skin(obj, armature)
    assert stage_names(report) == ["bone heat", "island bone heat", "nearest bones"]
    assert report.stages[0].weighted == 0 and report.stages[2].weighted == len(bead)
    assert_skinned(obj, armature, report, nearest_share=0.8)
    assert_seams_weighted_alike(obj, armature)
    table = rigdata.vertex_weights(obj, bone_names(armature))
    assert len({tuple(row) for row in table[bead]}) == 1


def mesh_object(name, vertices, triangles):
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata(vertices.tolist(), [], triangles.tolist())
    obj = bpy.data.objects.new(name, mesh)
    bpy.context.scene.collection.objects.link(obj)
    return obj


def test_bones_between_the_rings_of_low_poly_legs_move_some_of_their_own_leg(scene):
    """Two tubes side by side (legs) with a vertex ring every quarter of their length, each with a bone from 0.3
    to 0.45 of it, between two rings: bone heat gave those bones no vertex, so bending one moved nothing. Each now
    weighs on the rings beside it, hardly anywhere else on its leg and nowhere on the other leg, which is as near
    as its own rings are; the report says which bones they were."""
    tube, triangles = cylinder(0.1, 1.0, around=12, along=5)
    obj = mesh_object("legs", *combine((tube + [0.12, 0.0, 0.0], triangles), (tube - [0.12, 0.0, 0.0], triangles)))
    heads, tails, names, parents = [], [], [], []
    for side, x in (("L", 0.12), ("R", -0.12)):
        ends = np.array([[x, 0.0, 0.0], [x, 0.0, 0.3], [x, 0.0, 0.45], [x, 0.0, 1.0]])
        parents += [-1, len(names), len(names) + 1]
        names += [f"low.{side}", f"short.{side}", f"high.{side}"]
        heads += list(ends[:-1])
        tails += list(ends[1:])
    armature = build_armature(Skeleton(names, np.array(heads), np.array(tails), parents), "legs_rig")
    report = skinning.skin(obj, armature)
    assert_skinned(obj, armature, report)
    assert stage_names(report) == ["bone heat", skinning.IDLE_STAGE]
    assert sorted(report.stages[1].note.split(", ")) == ["short.L", "short.R"]
    assert report.level == "INFO" and "moved no vertex" in report.summary()
    table = rigdata.vertex_weights(obj, bone_names(armature))
    points = mesh_vertices(obj.data)
    for side, bones, on_leg in (("L", slice(0, 3), points[:, 0] > 0), ("R", slice(3, 6), points[:, 0] < 0)):
        short = names.index(f"short.{side}")
        assert table[on_leg, short].max() > 0.1
        assert table[on_leg & ((points[:, 2] < 0.1) | (points[:, 2] > 0.7)), short].max() < 1e-3
        assert table[~on_leg, bones].max() == 0.0


def shared_model(name):
    """A ../shared ground-truth model as a mesh object (its UV-seam copies kept) and an armature of its artist's
    skeleton; also the artist skeleton's head joint per bone and the rig."""
    vertices, triangles, rig = rigdata.load_ground_truth(shared_path("models", "gt", name))
    skeleton, head_joint = rigdata.armature_skeleton(rig)
    return mesh_object(name, vertices, triangles), build_armature(skeleton, f"{name}_rig"), head_joint, rig


def test_a_real_model_on_which_bone_heat_fails_unwelded_is_weighted_welded(scene):
    """Quaternius' fox (a glTF export, split along UV seams) with its artist skeleton: bone heat on the split mesh
    failed outright."""
    obj, armature, head_joint, rig = shared_model("Quaternius_Fox")
    report = skinning.skin(obj, armature)
    assert not report.messages and report.welded > 0
    assert stage_names(report) == ["bone heat", "surface weights"]  # its eyes and nose tip sit on the head
    assert report.stages[1].note == "3 loose parts no bone runs through"
    assert report.stages[0].weighted == report.vertices
    assert_skinned(obj, armature, report, nearest_share=0.8)
    assert_seams_weighted_alike(obj, armature)
    # the weights mostly agree with the artist's: the dominant bone starts at the artist's dominant joint
    ours = head_joint[rigdata.vertex_weights(obj, bone_names(armature)).argmax(axis=1)]
    artist = rigdata.dominant_joints(rig)
    assert (ours[artist >= 0] == artist[artist >= 0]).mean() > 0.7  # measured 0.74


@pytest.mark.parametrize("name", ["CesiumMan", "rignet_smith"])
def test_real_models_that_cracked_open_at_their_seams_get_one_weight_per_place(scene, name):
    """Bone heat on these UV-split models, with their artist skeletons, weighted a seam's copies up to a whole bone
    apart (one copy all on one bone, its twin on another); posed, they cracked open."""
    obj, armature, _, _ = shared_model(name)
    report = skinning.skin(obj, armature)
    assert report.welded > 0 and report.unweighted == 0
    assert_seams_weighted_alike(obj, armature)
