"""The add-on inside Blender (bpy from PyPI, headless): registration, generated properties, operators, panel.

Skinning and overlays have their own modules (test_skinning.py, test_overlays.py); here they are exercised through
the operators on the project's generated characters, whose Skin-modifier construction gives the true skeleton.
"""
import contextlib
import io
import json
import types

import numpy as np
import pytest

from characters import strictly_inside_fraction
from conftest import activate
from rigdata import vertex_weights

bpy = pytest.importorskip("bpy")

import rigger  # noqa: E402
from rigger.blender.headless import empty_scene  # noqa: E402
from rigger.blender.meshdata import evaluated_arrays  # noqa: E402
from rigger.blender.samples import build_character  # noqa: E402

CHARACTERS = ("humanoid", "quadruped", "octopus", "tree", "snake")


@pytest.fixture(scope="module")
def registered():
    rigger.register()
    yield
    rigger.unregister()


@pytest.fixture
def scene(registered, scene):
    """conftest's fresh empty scene, made after the add-on is registered."""
    return scene


def reports_of(operator, **kwargs):
    """(result, printed reports) of calling ``operator``: headless Blender prints reports to stdout."""
    printed = io.StringIO()
    with contextlib.redirect_stdout(printed):
        result = operator(**kwargs)
    return result, printed.getvalue()


# registration


def test_register_adds_the_operators_settings_and_panel_and_unregister_removes_them():
    rigger.register()
    try:
        assert hasattr(bpy.types.Scene, "rigger")
        assert hasattr(bpy.ops.rigger, "rig") and hasattr(bpy.ops.rigger, "clear_overlays")
        assert "RIGGER_PT_main" in dir(bpy.types)
        settings = bpy.context.scene.rigger
        assert settings.method == "silhouette"
        assert settings.methods.silhouette.resolution == 384
    finally:
        rigger.unregister()
    assert not hasattr(bpy.types.Scene, "rigger")
    assert not hasattr(bpy.types.Object, "rigger_armature")
    assert "RIGGER_PT_main" not in dir(bpy.types)
    rigger.register()  # and again: nothing of the first round is left over to clash with
    rigger.unregister()


def test_generated_properties_follow_the_declarations(registered):
    from rigger.api import method_registry
    method = method_registry().lookup("silhouette")
    group = bpy.context.scene.rigger.methods.silhouette
    for param in method.params:
        rna = group.bl_rna.properties[param.name]
        assert rna.name == param.label and rna.description == param.description
        if param.type in ("float", "int"):
            assert (rna.hard_min, rna.hard_max) == pytest.approx((param.min, param.max))
            assert rna.default == pytest.approx(param.default)
        if param.type == "enum":
            assert [item.identifier for item in rna.enum_items] == list(param.items)


def test_float_parameters_reach_the_method_as_typed_not_as_single_precision(registered):
    from rigger.api import method_registry
    from rigger.blender.properties import param_values
    group = bpy.context.scene.rigger.methods.silhouette
    group.outline_spacing = 0.1  # the declared maximum: as a float32 it reads 0.10000000149
    values = param_values(method_registry().lookup("silhouette"), group)
    assert values["outline_spacing"] == 0.1 and values["bone_length"] == 0.1


# operators


@pytest.fixture(scope="module")
def rigged(registered):
    """Every test character rigged and skinned through ``rigger.rig_skin``: name → (mesh object, reports)."""
    empty_scene()
    results = {}
    for name in CHARACTERS:
        obj = build_character(name, subdivisions=1)
        activate(obj)
        results[name] = (obj, *reports_of(bpy.ops.rigger.rig_skin))
    return results


@pytest.mark.parametrize("name", CHARACTERS)
def test_rig_and_skin_every_character(rigged, name):
    obj, result, printed = rigged[name]
    assert result == {'FINISHED'}, printed
    armature = obj.rigger_armature
    bones = armature.data.bones
    assert len(bones) >= 1
    assert sum(bone.parent is None for bone in bones) == 1  # one rooted tree
    assert armature.matrix_world == armature.matrix_world.Identity(4)

    vertices, triangles = evaluated_arrays(obj)
    points = np.concatenate([np.array([bone.head_local for bone in bones]),
                             np.array([bone.tail_local for bone in bones])])
    inside = strictly_inside_fraction(vertices, triangles, points)
    assert inside >= 0.9, f"only {inside:.0%} of {len(points)} bone ends inside the mesh"

    weights = vertex_weights(obj, [bone.name for bone in bones if bone.use_deform])
    assert (weights.max(axis=1) > 0).all(), "vertices left unweighted"
    assert any(m.type == 'ARMATURE' and m.object == armature for m in obj.modifiers)


def test_bones_connect_where_a_head_meets_its_parents_tail(rigged):
    obj = rigged["humanoid"][0]
    for bone in obj.rigger_armature.data.bones:
        if bone.parent is not None:
            meets = (bone.head_local - bone.parent.tail_local).length < 1e-5
            assert bone.use_connect == meets, bone.name


def test_rolls_follow_one_rule_so_mirrored_limbs_mirror(rigged):
    """Each bone's Z axis is world up made perpendicular to the bone (the front, -Y, for near-vertical bones): a rule
    that commutes with mirroring in X, so left and right limbs get mirrored rolls."""
    for bone in rigged["humanoid"][0].rigger_armature.data.bones:
        axes = np.array(bone.matrix_local)[:3, :3]
        along = axes[:, 1]
        reference = np.array([0.0, -1.0, 0.0]) if abs(along[2]) > 0.95 else np.array([0.0, 0.0, 1.0])
        expected = reference - (reference @ along) * along
        np.testing.assert_allclose(axes[:, 2], expected / np.linalg.norm(expected), atol=1e-4, err_msg=bone.name)


def test_the_rig_follows_the_objects_transform_and_modifiers(scene):
    obj = build_character("humanoid", subdivisions=0)
    obj.modifiers.new("Smooth", 'SUBSURF').levels = 1
    obj.location = (3.0, -2.0, 1.0)
    obj.rotation_euler = (0.0, 0.0, np.pi / 2)
    obj.scale = (2.0, 2.0, 2.0)
    activate(obj)
    assert bpy.ops.rigger.rig() == {'FINISHED'}
    armature = obj.rigger_armature
    heads = np.array([bone.head_local for bone in armature.data.bones])
    vertices, triangles = evaluated_arrays(obj)
    assert len(vertices) > len(obj.data.vertices)  # the modifier was applied
    assert strictly_inside_fraction(vertices, triangles, heads) >= 0.9
    # the humanoid, 1.8 m tall along its own Z, is now 3.6 m tall and stands at z = 1
    assert heads[:, 2].max() - heads[:, 2].min() > 2.0
    assert bpy.context.view_layer.objects.active == armature


def test_a_character_turned_off_the_worlds_axes_rigs_as_it_stands_square(scene):
    """Turned 30° about Z (to face a camera, say), the humanoid shows the world's axes neither its front nor its
    side; it is rigged along its own axes: the same bones as standing square, turned with it."""
    obj = build_character("humanoid", subdivisions=0)
    activate(obj)
    assert bpy.ops.rigger.rig() == {'FINISHED'}
    square = {bone.name: np.array(bone.head_local) for bone in obj.rigger_armature.data.bones}
    obj.rotation_euler = (0.0, 0.0, np.pi / 6)
    bpy.context.view_layer.update()
    activate(obj)
    assert bpy.ops.rigger.rig() == {'FINISHED'}
    turned = {bone.name: np.array(bone.head_local) for bone in obj.rigger_armature.data.bones}
    assert turned.keys() == square.keys() and any(name.endswith(".L") for name in turned)
    rotation = np.array(obj.matrix_world)[:3, :3]
    for name, head in square.items():
        np.testing.assert_allclose(turned[name], rotation @ head, atol=1e-4)


def test_the_rig_keeps_following_the_meshs_parent(scene):
    vehicle = bpy.data.objects.new("Vehicle", None)
    scene.collection.objects.link(vehicle)
    vehicle.location, vehicle.rotation_euler, vehicle.scale = (5.0, 0.0, 0.0), (0.0, 0.0, 0.5), (2.0, 2.0, 2.0)
    obj = build_character("snake", subdivisions=0)
    obj.parent = vehicle
    bpy.context.view_layer.update()
    before, _ = evaluated_arrays(obj)
    for _ in range(2):  # rigging again too
        activate(obj)
        assert bpy.ops.rigger.rig_skin() == {'FINISHED'}
        armature = obj.rigger_armature
        assert armature.parent == vehicle and obj.parent == armature
        np.testing.assert_allclose(np.array(armature.matrix_world), np.eye(4), atol=1e-6)
    vehicle.location.x += 10.0
    bpy.context.view_layer.update()
    np.testing.assert_allclose(evaluated_arrays(obj)[0], before + (10.0, 0.0, 0.0), atol=1e-4)


def test_rigging_again_replaces_the_previous_rig(scene):
    obj = build_character("snake", subdivisions=0)
    activate(obj)
    assert bpy.ops.rigger.rig_skin() == {'FINISHED'}
    first_groups = len(obj.vertex_groups)
    activate(obj)
    scene.rigger.methods.silhouette.bone_length = 0.05
    result, printed = reports_of(bpy.ops.rigger.rig)
    assert result == {'FINISHED'} and "replaced the previous rig" in printed
    assert [o.type for o in bpy.data.objects if o.type == 'ARMATURE'] == ['ARMATURE']
    assert len(bpy.data.armatures) == 1
    assert not any(m.type == 'ARMATURE' for m in obj.modifiers) and obj.parent is None
    assert first_groups and len(obj.vertex_groups) == 0 and "rigger_vertex_groups" not in obj


def test_rigging_again_carries_the_animation_over_to_the_new_rig(scene):
    """Keys set on the rig (an Euler turn of one bone), then Rig again with another bone length: the motion goes
    on, on the new bone of the same name, turning in the same mode, and the report says so; so do NLA strips."""
    obj = build_character("humanoid", subdivisions=0)
    activate(obj)
    assert bpy.ops.rigger.rig() == {'FINISHED'}
    bone = obj.rigger_armature.pose.bones["trunk.01"]
    bone.rotation_mode = 'XYZ'
    for frame, angle in ((1, 0.5), (10, 0.0)):
        bone.rotation_euler = (angle, 0.0, 0.0)
        bone.keyframe_insert("rotation_euler", frame=frame)
    motion = obj.rigger_armature.animation_data.action.name
    activate(obj)
    scene.rigger.methods.silhouette.bone_length = 0.12
    result, printed = reports_of(bpy.ops.rigger.rig)
    assert result == {'FINISHED'} and f"its animation '{motion}' goes on" in printed
    armature = obj.rigger_armature
    assert armature.animation_data.action.name == motion and [a.name for a in bpy.data.actions] == [motion]
    scene.frame_set(1)
    assert armature.pose.bones["trunk.01"].rotation_mode == 'XYZ'
    assert armature.pose.bones["trunk.01"].rotation_euler[0] == pytest.approx(0.5)

    action = armature.animation_data.action  # pushed down into an NLA strip, then rigged again: the strip goes on
    armature.animation_data.nla_tracks.new().strips.new("walk", 1, action)
    armature.animation_data.action = None
    activate(obj)
    result, printed = reports_of(bpy.ops.rigger.rig)
    tracks = obj.rigger_armature.animation_data.nla_tracks
    assert [strip.action.name for track in tracks for strip in track.strips] == [motion]
    scene.rigger.target = "game"  # other bone names: the motion is kept, and the report says it keys none of them
    activate(obj)
    result, printed = reports_of(bpy.ops.rigger.rig)
    assert f"its animation '{motion}' is kept, but keys none of the new bones" in printed


def test_rigging_a_posed_rig_again_fits_the_mesh_at_rest(scene):
    from mathutils import Matrix
    obj = build_character("humanoid", subdivisions=0)
    activate(obj)
    assert bpy.ops.rigger.rig_skin() == {'FINISHED'}
    first = {bone.name: np.array(bone.head_local) for bone in obj.rigger_armature.data.bones}
    for pose_bone in obj.rigger_armature.pose.bones:  # the user poses the character 2 m up
        if pose_bone.parent is None:
            pose_bone.matrix = Matrix.Translation((0.0, 0.0, 2.0)) @ pose_bone.matrix
    bpy.context.view_layer.update()
    activate(obj)
    assert bpy.ops.rigger.rig() == {'FINISHED'}
    again = {bone.name: np.array(bone.head_local) for bone in obj.rigger_armature.data.bones}
    assert again.keys() == first.keys()  # the same mesh at rest, read without the old rig: the very same skeleton
    np.testing.assert_array_equal([again[name] for name in first], list(first.values()))


def test_the_armature_stays_editable_and_skin_uses_the_edited_bones(scene):
    obj = build_character("snake", subdivisions=0)
    activate(obj)
    assert bpy.ops.rigger.rig() == {'FINISHED'}
    armature = obj.rigger_armature
    assert bpy.context.view_layer.objects.active == armature
    bpy.ops.object.mode_set(mode='EDIT')
    armature.data.edit_bones[0].name = "renamed"
    bpy.ops.object.mode_set(mode='OBJECT')
    assert bpy.ops.rigger.skin() == {'FINISHED'}  # the active armature leads back to its mesh
    assert "renamed" in obj.vertex_groups


def test_several_selected_meshes_are_rigged_together_and_all_skinned(scene):
    body = build_character("humanoid", subdivisions=0)
    hat = build_character("snake", subdivisions=0)
    hat.scale = (0.2, 0.2, 0.2)
    hat.location = (0.0, 0.0, 1.9)
    activate(body, hat)
    assert bpy.ops.rigger.rig_skin() == {'FINISHED'}
    assert body.rigger_armature == hat.rigger_armature
    for obj in (body, hat):
        assert obj.vertex_groups and any(m.type == 'ARMATURE' for m in obj.modifiers)


def test_a_floor_and_a_crate_apart_box_selected_with_the_character_stay_out_of_its_rig(scene):
    body = build_character("humanoid", subdivisions=0)
    bpy.ops.mesh.primitive_plane_add(size=6.0)
    floor = bpy.context.active_object
    bpy.ops.mesh.primitive_cube_add(size=0.5, location=(3.0, 0.0, 0.25))
    crate = bpy.context.active_object
    activate(floor, body, crate)  # the floor active, as a box selection may leave it: the character is still the body
    result, printed = reports_of(bpy.ops.rigger.rig_skin)
    assert result == {'FINISHED'}
    assert "left out Plane (flat and larger than 'humanoid': a floor, a stage or a backdrop)" in printed
    assert "left out Cube (apart from 'humanoid')" in printed and "humanoid (0.9" in printed
    assert body.rigger_armature.name == "humanoid_rig"
    assert floor.rigger_armature is None and crate.rigger_armature is None
    assert not floor.modifiers and not crate.modifiers


def test_rig_builds_the_overlays_the_panel_toggles_and_clear_removes(scene):
    from rigger.blender.overlays import COLLECTION_NAME, KIND_KEY, OWNER_KEY
    obj = build_character("humanoid", subdivisions=0)
    activate(obj)
    toggle = scene.rigger.overlays.add()  # a script may set a stage's toggle before its first rig
    toggle.name, toggle.shown = "cdt", False
    assert bpy.ops.rigger.rig() == {'FINISHED'}
    made = {o[KIND_KEY]: o for o in bpy.data.collections[COLLECTION_NAME].objects}
    assert set(made) == {"silhouette", "cdt", "axis", "merged", "pruned", "chains", "joints", "roles"}
    toggles = scene.rigger.overlays
    assert set(toggles.keys()) == set(made)  # one toggle per stage drawn, labelled after its stage type
    labels = [toggles[name].label for name in ("axis", "merged", "cdt")]
    assert labels == ["Chordal Axis", "Merged Axis", "Triangulation"]
    assert made["cdt"].hide_get() and made["merged"].hide_get() and not made["joints"].hide_get()
    assert not toggles["merged"].shown and toggles["joints"].shown
    depsgraph = bpy.context.evaluated_depsgraph_get()
    joints = made["joints"].evaluated_get(depsgraph).to_mesh()
    assert len(joints.polygons) > 0  # the node group drew spheres
    made["joints"].evaluated_get(depsgraph).to_mesh_clear()

    toggles["joints"].shown = False
    assert made["joints"].hide_get()
    toggles["cdt"].shown = True
    assert not made["cdt"].hide_get()
    assert bpy.ops.rigger.rig() == {'FINISHED'}  # rigging again keeps the toggles as they are
    made = {o[KIND_KEY]: o for o in bpy.data.collections[COLLECTION_NAME].objects}
    assert made["joints"].hide_get() and not made["cdt"].hide_get() and len(toggles) == 8
    drawn = len(bpy.data.collections[COLLECTION_NAME].objects)
    obj.name = "Hero"  # renamed, rigged again: the overlays drawn under the old name go with the old rig
    activate(obj)
    assert bpy.ops.rigger.rig() == {'FINISHED'}
    owners = {o[OWNER_KEY] for o in bpy.data.collections[COLLECTION_NAME].objects}
    assert owners == {"Hero"} and len(bpy.data.collections[COLLECTION_NAME].objects) == drawn
    assert bpy.ops.rigger.clear_overlays() == {'FINISHED'}
    assert COLLECTION_NAME not in bpy.data.collections
    assert not [o for o in bpy.data.objects if KIND_KEY in o] and len(toggles) == 0
    assert not bpy.ops.rigger.clear_overlays.poll()


def poll_message(operator):
    """The message ``operator``'s poll gives when it refuses (bpy raises it as a RuntimeError), or None."""
    if operator.poll():
        return None
    with pytest.raises(RuntimeError) as refused:
        operator()
    return str(refused.value).split(".poll() ", 1)[1]


def test_polls_explain_why_an_operator_cannot_run(scene):
    assert poll_message(bpy.ops.rigger.rig) == "Select a mesh object"
    camera = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
    scene.collection.objects.link(camera)
    activate(camera)
    assert poll_message(bpy.ops.rigger.rig) == "Camera is not a mesh; select a mesh object"
    assert poll_message(bpy.ops.rigger.skin) == "Camera is not a mesh; select a mesh object"
    obj = build_character("snake", subdivisions=0)
    activate(obj)
    assert poll_message(bpy.ops.rigger.rig) is None
    assert "has no armature yet: rig it first" in poll_message(bpy.ops.rigger.skin)
    bpy.context.view_layer.objects.active = None  # selected, but not active
    assert poll_message(bpy.ops.rigger.rig) == "Make one of the selected meshes active (click it)"
    activate(obj)
    bpy.ops.object.mode_set(mode='EDIT')
    assert poll_message(bpy.ops.rigger.rig) == "Switch to Object Mode first"
    bpy.ops.object.mode_set(mode='OBJECT')
    assert poll_message(bpy.ops.rigger.clear_overlays) == "There are no overlays to clear"


def test_a_head_on_two_stubs_is_no_humanoid(scene):
    """Suzanne, Blender's monkey head: seen from above, a ball with ears, so a body chain runs from its middle to the
    back of the head, and features of the face read as two legs under it with the chin for a tail much longer than
    them. No plan fits that: the rig stays plain and the report says why."""
    bpy.ops.mesh.primitive_monkey_add()
    obj = bpy.context.active_object
    activate(obj)
    result, printed = reports_of(bpy.ops.rigger.rig)
    assert result == {'FINISHED'} and "below its hips farther than they reach: not a body plan Rigger knows" in printed
    assert obj.rigger_armature["rigger_target"] == "plain"


def test_a_mesh_without_faces_is_reported_not_raised(scene):
    mesh = bpy.data.meshes.new("points")
    mesh.from_pydata([(0, 0, 0), (1, 0, 0), (0, 1, 0)], [(0, 1)], [])
    obj = bpy.data.objects.new("points", mesh)
    scene.collection.objects.link(obj)
    activate(obj)
    with pytest.raises(RuntimeError, match="has no faces"):  # bpy.ops turns an ERROR report into RuntimeError
        bpy.ops.rigger.rig()
    assert [o.name for o in bpy.data.objects] == ["points"]


def test_a_mesh_with_a_nan_vertex_is_reported_and_nothing_is_created(scene):
    obj = build_character("snake", subdivisions=0)
    obj.data.vertices[0].co = (float("nan"), 0.0, 0.0)
    activate(obj)
    with pytest.raises(RuntimeError, match="not finite|NaN"):
        bpy.ops.rigger.rig()
    assert obj.rigger_armature is None and len(bpy.data.armatures) == 0


def test_registering_again_replaces_the_registration_instead_of_breaking_it(registered):
    rigger.register()  # a script registering while the add-on is enabled
    assert hasattr(bpy.types.Scene, "rigger") and hasattr(bpy.types.Object, "rigger_armature")
    assert "RIGGER_OT_rig" in dir(bpy.types) and "RIGGER_PT_main" in dir(bpy.types)
    assert bpy.context.scene.rigger.method == "silhouette"


def test_skin_refuses_an_armature_the_user_deleted_and_rigging_again_makes_a_new_one(scene):
    obj = build_character("snake", subdivisions=0)
    activate(obj)
    assert bpy.ops.rigger.rig() == {'FINISHED'}
    activate(obj.rigger_armature)
    assert bpy.ops.object.delete() == {'FINISHED'}  # out of the scene, yet kept alive by the mesh's pointer
    activate(obj)
    assert "snake's armature was deleted, but still holds the mesh: Rig makes a new one and lets go of the old" \
        in poll_message(bpy.ops.rigger.skin)
    assert bpy.ops.rigger.rig_skin() == {'FINISHED'}
    assert [o for o in bpy.data.objects if o.type == 'ARMATURE'] == [obj.rigger_armature]
    assert obj.parent == obj.rigger_armature and obj.rigger_armature.name in scene.objects


def test_the_armature_goes_into_a_collection_the_view_layer_shows(scene):
    from rigger.blender.armature import build_armature
    from rigger.core.skeleton import Skeleton
    excluded, shown = (bpy.data.collections.new(name) for name in ("Excluded", "Shown"))
    for collection in (excluded, shown):
        scene.collection.children.link(collection)
    obj = build_character("snake", subdivisions=0, collection=excluded)  # the mesh's first collection...
    shown.objects.link(obj)
    bpy.context.view_layer.layer_collection.children["Excluded"].exclude = True  # ...is excluded from the view
    activate(obj)
    assert bpy.ops.rigger.rig() == {'FINISHED'}
    assert list(obj.rigger_armature.users_collection) == [shown]

    # an armature that cannot be made is not left behind half made
    with pytest.raises(RuntimeError):
        build_armature(Skeleton(["bone"], [(0, 0, 0)], [(0, 0, 1)], [-1]), "stray", collection=excluded)
    assert "stray" not in bpy.data.objects and "stray" not in bpy.data.armatures


def test_linked_duplicates_rigged_together_each_follow_their_own_bones(scene):
    left = build_character("snake", subdivisions=0)
    right = left.copy()  # a linked duplicate: the same mesh data, so the same vertex weights
    scene.collection.objects.link(right)
    right.location.x += 0.9  # side by side, a hand's breadth apart: one character of two parts
    activate(left, right)
    result, printed = reports_of(bpy.ops.rigger.rig_skin)
    assert result == {'FINISHED'} and "got its own copy" in printed
    assert left.data != right.data
    middles = {bone.name: (bone.head_local + bone.tail_local) / 2 for bone in left.rigger_armature.data.bones}
    for obj in (left, right):
        vertices = np.array([obj.matrix_world @ vertex.co for vertex in obj.data.vertices])
        strongest = [obj.vertex_groups[max(vertex.groups, key=lambda element: element.weight).group].name
                     for vertex in obj.data.vertices]
        bones = np.array([middles[name] for name in strongest])
        # each vertex's strongest bone lies in its own copy (0.33 at most off its middle), not in the other one
        assert np.abs(bones[:, 0] - vertices[:, 0]).max() < 0.45, obj.name


def test_the_report_is_plain_json_whatever_numbers_a_method_records(scene):
    from rigger.blender.pipeline import rig_object
    from rigger.blender.scenefiles import rig_report
    from rigger.core.registry import RigMethod
    from rigger.core.skeleton import Skeleton

    class NumpyTimed(RigMethod):
        name = "numpy_timed"

        def rig(self, mesh):
            low, high = mesh.vertices.min(axis=0), mesh.vertices.max(axis=0)
            return Skeleton(["spine"], [low], [high], [-1], timings={"think": np.float32(0.5), "count": np.int64(3)})

    result = rig_object(build_character("snake", subdivisions=0), NumpyTimed)
    report = json.loads(json.dumps(rig_report(result, None)))
    assert report["timings"]["method.think"] == 0.5 and report["timings"]["method.count"] == 3.0
    assert report["method"] == "numpy_timed" and [bone["name"] for bone in report["bones"]] == ["spine"]
    assert report["target"] == "plain"


def test_an_unknown_target_is_refused_before_anything_is_made(scene):
    from rigger.blender.pipeline import rig_object

    obj = build_character("snake", subdivisions=0)
    before = set(bpy.data.objects)
    with pytest.raises(ValueError, match="unknown target 'nope'"):
        rig_object(obj, target="nope")
    assert set(bpy.data.objects) == before


def test_a_mesh_far_from_the_origin_fails_saying_why(scene):
    """Ten million units from the origin Blender's 32-bit coordinates are a unit apart: a character two metres tall
    collapses onto a few slices and was rigged as such without a word (a character a metre tall failed as "mesh is a
    line"). The error says where the mesh lies, and to move it."""
    from mathutils import Matrix

    from rigger.blender.pipeline import rig_object

    obj = build_character("humanoid", subdivisions=0)
    obj.data.transform(Matrix.Translation((1e7, 0.0, 0.0)))
    before = set(bpy.data.objects)
    with pytest.raises(ValueError, match=r"^the mesh lies 1e\+07 from the origin, where Blender's coordinates are "
                                         r"1.19 apart: too coarse for a mesh .* across; move it near the origin$"):
        rig_object(obj)
    assert set(bpy.data.objects) == before


def test_operators_are_undoable_and_scriptable_by_name(registered):
    from rigger.blender.operators import CLASSES
    assert sorted(cls.bl_idname for cls in CLASSES) == [
        "rigger.clear_overlays", "rigger.direction_from_view", "rigger.rig", "rigger.rig_skin", "rigger.skin"]
    assert all(cls.bl_options == {'REGISTER', 'UNDO'} for cls in CLASSES)


class RecordingLayout:
    """Stands in for bpy.types.UILayout (which only exists while Blender draws a region): records what is drawn."""

    def __init__(self, log=None, buttons=None):
        self.log = [] if log is None else log
        self.buttons = {} if buttons is None else buttons  # operator id -> the properties its button was given

    def _nested(self, *args, **kwargs):
        return RecordingLayout(self.log, self.buttons)

    box = column = row = grid_flow = _nested

    def prop(self, data, name, **kwargs):
        self.log.append(("prop", name))

    def operator(self, idname, **kwargs):
        self.log.append(("operator", idname))
        return self.buttons.setdefault(idname, types.SimpleNamespace())  # its operator properties, for the caller

    def label(self, text="", **kwargs):
        self.log.append(("label", text))


def drawn_panel():
    """The Rigger panel drawn into a ``RecordingLayout``, which it returns."""
    from rigger.blender.panel import RIGGER_PT_main
    panel = types.SimpleNamespace(layout=RecordingLayout())
    RIGGER_PT_main.draw(panel, bpy.context)
    return panel.layout


def test_the_panel_shows_method_parameters_actions_and_overlay_toggles(scene):
    from rigger.blender.panel import RIGGER_PT_main
    assert (RIGGER_PT_main.bl_space_type, RIGGER_PT_main.bl_region_type) == ('VIEW_3D', 'UI')
    assert RIGGER_PT_main.bl_category == "Rigger"
    log = drawn_panel().log
    props = [name for kind, name in log if kind == "prop"]
    assert props[0] == "method"
    assert {"resolution", "bone_length", "view"} <= set(props)
    assert "shown" not in props and ("label", "Rig a mesh to see its stages") in log  # no stages drawn yet
    assert [name for kind, name in log if kind == "operator"] == [
        "rigger.rig", "rigger.skin", "rigger.rig_skin", "rigger.clear_overlays"]
    activate(build_character("snake", subdivisions=0))
    assert bpy.ops.rigger.rig() == {'FINISHED'}
    assert [name for kind, name in drawn_panel().log if kind == "prop"].count("shown") == len(scene.rigger.overlays) > 0


def test_the_direction_view_offers_to_look_along_the_3d_view(scene):
    settings = scene.rigger
    settings.method = "silhouette"
    settings.methods.silhouette.view = "DIRECTION"
    layout = drawn_panel()
    assert ("operator", "rigger.direction_from_view") in layout.log
    assert layout.buttons["rigger.direction_from_view"].param == "view_direction"
    assert bpy.ops.rigger.direction_from_view.poll() is False  # no 3D view headless


def test_from_view_sets_the_direction_the_view_looks_along(scene):
    """The operator run as the sidebar runs it, in a 3D view turned to look along +X (view_rotation maps the
    camera's -Z there; an unturned view looks along -Z); asked to fill a parameter that is not a vector, it cancels
    with a report."""
    from mathutils import Quaternion

    from rigger.blender.operators import RIGGER_OT_direction_from_view, looking_along
    np.testing.assert_allclose(looking_along(Quaternion()), (0.0, 0.0, -1.0))
    scene.rigger.method = "silhouette"
    view = types.SimpleNamespace(view_rotation=Quaternion((0.0, 1.0, 0.0), -np.pi / 2))
    context = types.SimpleNamespace(scene=scene, space_data=types.SimpleNamespace(type='VIEW_3D', region_3d=view))
    reports = []
    operator = types.SimpleNamespace(param="view_direction", report=lambda kind, text: reports.append(text))
    assert RIGGER_OT_direction_from_view.execute(operator, context) == {'FINISHED'}
    np.testing.assert_allclose(scene.rigger.methods.silhouette.view_direction, (1.0, 0.0, 0.0), atol=1e-6)
    operator.param = "resolution"  # not a vector
    assert RIGGER_OT_direction_from_view.execute(operator, context) == {'CANCELLED'}
    assert reports == ["silhouette has no direction parameter 'resolution'"]


def test_a_method_draw_hook_that_raises_is_shown_in_the_panel_not_raised():
    from rigger.blender.panel import draw_method
    from rigger.core.registry import RigMethod

    class Faulty(RigMethod):
        name = "faulty"

        def rig(self, mesh):
            raise AssertionError

        def draw(self, layout, props):
            raise KeyError("oops")

    layout = RecordingLayout()
    draw_method(layout, Faulty, props=None)
    assert ("label", "faulty.draw failed: KeyError: 'oops'") in layout.log


def test_the_problem_panel_registers_once_however_often_it_is_asked():
    from rigger.blender import problem
    problem.register("first")
    problem.register("second")
    try:
        assert problem.RIGGER_PT_problem.is_registered and problem.RIGGER_PT_problem.message == "second"
    finally:
        assert problem.unregister() is True
    assert problem.unregister() is False
