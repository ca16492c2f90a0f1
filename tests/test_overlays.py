"""Stage overlays (rigger.blender.overlays): the evaluated geometry-node output sits where each stage says, in the
right materials, for any stage type (a test-only method's own included), and building, rebuilding, hiding and
clearing leave exactly the data they should."""
import pathlib

import numpy as np
import pytest
from scipy.spatial import cKDTree

bpy = pytest.importorskip("bpy")

import rigger  # noqa: E402
from rigger.blender import overlays, samples  # noqa: E402
from rigger.blender.headless import empty_scene  # noqa: E402
from rigger.blender.meshdata import mesh_vertices  # noqa: E402
from rigger.core.polyline import segment_distances  # noqa: E402
from rigger.core.registry import discover  # noqa: E402
from rigger.core.stages import (ISOLATED, JUNCTION, SLEEVE, TERMINAL, AxisGraph, Frame, MirrorPlane,  # noqa: E402
                                Stage, Triangulation)

KINDS = ["silhouette", "cdt", "axis", "merged", "pruned", "chains", "joints", "roles"]  # the drawn stages (roles:
# rig_mesh's bone roles)
LINE_KINDS = ("silhouette", "axis", "merged", "pruned", "chains")
TEST_METHODS = pathlib.Path(__file__).parent / "methods"
ICO_VERTICES = 42  # an ico sphere of SPHERE_SUBDIVISIONS = 2
pytestmark = pytest.mark.usefixtures("scene")  # every test starts from an empty scene


@pytest.fixture(scope="module")
def humanoid():
    """(vertices, triangles, stages) of the humanoid sample rigged by the silhouette method."""
    empty_scene()
    vertices, triangles = samples.character_arrays("humanoid", subdivisions=1)
    return vertices, triangles, rigger.rig_mesh(vertices, triangles).stages


def lift(frame, points):
    """Points (P, 2) of a view's plane in 3D, from the frame's fields."""
    return frame.origin + frame.depth * frame.direction + points[:, :1] * frame.u + points[:, 1:] * frame.v


def stage_segments(stages, kind):
    """(starts, ends) of the segments a line-like stage draws, in 3D."""
    stage = stages[kind]
    if kind == "silhouette":
        starts = np.concatenate([lift(stage.frame, loop) for loop in stage.loops])
        ends = np.concatenate([lift(stage.frame, np.roll(loop, -1, axis=0)) for loop in stage.loops])
        return starts, ends
    if kind == "chains":
        return (np.concatenate([chain[:-1] for chain in stage.lines]),
                np.concatenate([chain[1:] for chain in stage.lines]))
    points = lift(stage.frame, stage.points)
    return points[stage.links[:, 0]], points[stage.links[:, 1]]


def distance_to_segments(points, starts, ends):
    """Distance from every point to the nearest of the segments."""
    nearest = np.empty(len(points))
    for chunk in np.array_split(np.arange(len(points)), max(1, len(points) // 256)):
        nearest[chunk] = segment_distances(points[chunk], starts, ends).min(axis=1)
    return nearest


def evaluated(obj):
    """Vertices (N, 3) and the material name of every face of the object's evaluated (geometry-node) mesh."""
    mesh = obj.evaluated_get(bpy.context.evaluated_depsgraph_get()).data
    index = np.empty(len(mesh.polygons), dtype=np.int32)
    mesh.polygons.foreach_get("material_index", index)
    names = np.array([material.name if material else "" for material in mesh.materials] or [""])
    return mesh_vertices(mesh), names[index]


def default_radius(stages):
    """LINE_SCALE times the largest extent of everything drawn."""
    cdt, axis = stages["cdt"], stages["axis"]
    axis_used = np.unique(np.concatenate([stages[kind].links.ravel() for kind in ("axis", "merged", "pruned")]))
    points = np.concatenate([
        *(lift(axis.frame, loop) for loop in stages["silhouette"].loops),
        lift(cdt.frame, cdt.vertices[np.unique(cdt.triangles)]),
        lift(axis.frame, axis.points[axis_used]),
        *stages["chains"].lines,
        stages["joints"].points,
    ])
    return overlays.LINE_SCALE * float(np.max(points.max(axis=0) - points.min(axis=0)))


def data_counts():
    return {name: len(getattr(bpy.data, name))
            for name in ("objects", "meshes", "node_groups", "materials", "collections")}


def test_every_stage_of_the_silhouette_method_gets_its_object(humanoid):
    stages = humanoid[2]
    objects = overlays.build_overlays(stages, "Body")
    assert list(objects) == KINDS
    collection = bpy.data.collections[overlays.COLLECTION_NAME]
    assert collection in bpy.context.scene.collection.children_recursive
    for kind, obj in objects.items():
        assert obj.name == f"Rigger {kind}: Body"
        assert obj.data.name == obj.name
        assert list(obj.users_collection) == [collection]
        assert obj.hide_select and obj.show_in_front and obj.hide_render
        assert obj.visible_get() == stages[kind].shown  # the merged axis starts hidden
        assert len(obj.data.polygons) == (len(stages["cdt"].triangles) if kind == "cdt" else 0)
        overlays.set_overlay_visible(kind, True)
        assert len(evaluated(obj)[1]) > 0, f"{kind}: the geometry nodes drew no faces"


@pytest.mark.parametrize("kind", LINE_KINDS)
def test_tubes_follow_the_stage_at_the_line_radius(humanoid, kind):
    stages = humanoid[2]
    radius = default_radius(stages)
    obj = overlays.build_overlays(stages, "Body", visible={kind: True})[kind]
    vertices, materials = evaluated(obj)
    starts, ends = stage_segments(stages, kind)
    distance = distance_to_segments(vertices, starts, ends)
    # Tube rings lie at the radius around the line: none farther, the ends and straight runs exactly there.
    assert distance.max() <= radius * 1.001 + 1e-6
    assert distance.max() >= radius * 0.99
    # Every stage point is drawn: a tube ring passes around it.
    covered = cKDTree(vertices).query(np.concatenate([starts, ends]))[0]
    assert covered.max() <= radius * 1.01
    assert set(materials) == {f"Rigger {kind}"}


def test_plane_stages_lie_on_the_silhouette_plane_at_its_depth(humanoid):
    stages = humanoid[2]
    frame = stages["frame"]
    radius = default_radius(stages)
    objects = overlays.build_overlays(stages, "Body")
    for kind in ("silhouette", "cdt", "axis", "merged", "pruned"):
        vertices = evaluated(objects[kind])[0]
        depth = (vertices - frame.origin) @ frame.direction
        assert np.abs(depth - frame.depth).max() <= radius * 1.001 + 1e-6, kind
    # The chains leave the plane: they are placed in depth inside the mesh.
    chains = np.concatenate(stages["chains"].lines)
    assert np.ptp((chains - frame.origin) @ frame.direction) > 10 * radius


def test_joint_spheres_are_centred_on_the_joints(humanoid):
    stages = humanoid[2]
    joints = stages["joints"].points
    obj = overlays.build_overlays(stages, "Body", scale=0.01)["joints"]
    vertices, materials = evaluated(obj)
    assert vertices.shape == (len(joints) * ICO_VERTICES, 3)
    spheres = vertices.reshape(len(joints), ICO_VERTICES, 3)
    np.testing.assert_allclose(spheres.mean(axis=1), joints, atol=1e-5)
    distance = np.linalg.norm(spheres - joints[:, None, :], axis=2)
    np.testing.assert_allclose(distance, overlays.JOINT_SCALE * 0.01, rtol=1e-3)
    assert set(materials) == {"Rigger joints"}


def test_scale_sets_the_line_radius(humanoid):
    stages = humanoid[2]
    obj = overlays.build_overlays(stages, "Body", scale=0.02)["silhouette"]
    distance = distance_to_segments(evaluated(obj)[0], *stage_segments(stages, "silhouette"))
    assert 0.02 * 0.99 <= distance.max() <= 0.02 * 1.001


def test_triangulation_materials_match_the_classes_present(humanoid):
    stages = humanoid[2]
    classes = stages["cdt"].classes
    names = {code: name for code, name, _ in Triangulation.palette}
    present = {names[code] for code in np.unique(classes)}
    obj = overlays.build_overlays(stages, "Body")["cdt"]
    _, materials = evaluated(obj)
    assert set(materials) == {f"Rigger {name}" for name in present} | {f"Rigger {name} faces" for name in present}
    for code, name in names.items():
        assert np.count_nonzero(materials == f"Rigger {name} faces") == np.count_nonzero(classes == code)
    faces = bpy.data.materials["Rigger junction faces"]
    edges = bpy.data.materials["Rigger junction"]
    assert faces.diffuse_color[3] == pytest.approx(overlays.FACE_ALPHA)
    assert edges.diffuse_color[3] == 1.0
    assert tuple(faces.diffuse_color)[:3] == pytest.approx(tuple(edges.diffuse_color)[:3])


def test_each_edge_is_drawn_once_in_the_colour_of_its_highest_class():
    """A junction and a sleeve share an edge (the junction draws it); a terminal and an isolated triangle stand
    alone. Every edge is a tube of TUBE_SIDES faces per segment."""
    vertices = np.array([[0, 0], [1, 0], [0, 1], [1, 1], [3, 0], [4, 0], [3, 1], [6, 0], [7, 0], [6, 1]], dtype=float)
    cdt = Triangulation(plane_at(0.5), vertices, np.array([[0, 1, 2], [1, 3, 2], [4, 5, 6], [7, 8, 9]]),
                        np.array([JUNCTION, SLEEVE, TERMINAL, ISOLATED]))
    objects = overlays.build_overlays({"cdt": cdt}, "Patch", scale=0.05)
    assert list(objects) == ["cdt"]
    vertices, materials = evaluated(objects["cdt"])
    sides = overlays.TUBE_SIDES
    expected = {"Rigger junction": 3 * sides, "Rigger sleeve": 2 * sides, "Rigger terminal": 3 * sides,
                "Rigger isolated": 3 * sides, "Rigger junction faces": 1, "Rigger sleeve faces": 1,
                "Rigger terminal faces": 1, "Rigger isolated faces": 1}
    names, counts = np.unique(materials, return_counts=True)
    assert dict(zip(names.tolist(), counts.tolist())) == expected
    assert np.abs(vertices[:, 2] - 0.5).max() <= overlays.FACE_EDGE_SCALE * 0.05 * 1.001


def plane_at(depth):
    """The frame of a view along z whose plane lies at z = ``depth``."""
    return Frame(np.zeros(3), np.array([1.0, 0, 0]), np.array([0, 1.0, 0]), np.array([0, 0, 1.0]), depth, np.eye(3))


def test_graph_links_are_drawn_once_and_self_links_dropped():
    axis = AxisGraph(plane_at(0.0), np.array([[0.0, 0.0], [1.0, 0.0], [2.0, 0.0], [9.0, 9.0]]), np.ones(4),
                     np.array([[0, 1], [1, 0], [1, 1], [1, 2]]))
    obj = overlays.build_overlays({"frame": plane_at(0.0), "axis": axis}, "Graph", scale=0.1)["axis"]
    assert len(obj.data.vertices) == 3  # the unused point is left out
    assert sorted(tuple(edge.vertices) for edge in obj.data.edges) == [(0, 1), (1, 2)]
    vertices, _ = evaluated(obj)
    assert vertices[:, 0].min() == pytest.approx(0.0, abs=1e-6) and vertices[:, 0].max() == pytest.approx(2.0)


def test_rebuilding_replaces_the_owners_objects_and_shares_groups_and_materials(humanoid):
    stages = humanoid[2]
    overlays.build_overlays(stages, "Body")
    once = data_counts()
    overlays.build_overlays(stages, "Body")
    assert data_counts() == once
    names = [data.name for kind in ("objects", "meshes", "node_groups", "materials")
             for data in getattr(bpy.data, kind)]
    assert not [name for name in names if name[-4:-3] == "." and name[-3:].isdigit()]

    overlays.build_overlays(stages, "Other")
    twice = data_counts()
    assert twice["objects"] == once["objects"] + len(KINDS) + len(stages["roles"].texts)  # a text per role label
    assert twice["meshes"] == once["meshes"] + len(KINDS)
    assert {key: twice[key] for key in ("node_groups", "materials", "collections")} == \
        {key: once[key] for key in ("node_groups", "materials", "collections")}

    without_joints = {key: value for key, value in stages.items() if key != "joints"}
    assert list(overlays.build_overlays(without_joints, "Body")) == [kind for kind in KINDS if kind != "joints"]
    assert "Rigger joints: Body" not in bpy.data.objects and "Rigger joints: Other" in bpy.data.objects


def test_visibility_at_build_and_toggled_per_stage(humanoid):
    stages = humanoid[2]
    body = overlays.build_overlays(stages, "Body", visible={"axis": False, "merged": True})
    other = overlays.build_overlays(stages, "Other")
    assert not body["axis"].visible_get() and body["axis"].hide_viewport and body["axis"].hide_get()
    assert all(obj.visible_get() for kind, obj in body.items() if kind != "axis")
    assert not other["merged"].visible_get()  # as its stage type says when not asked

    assert overlays.set_overlay_visible("chains", False) == 2
    assert not body["chains"].visible_get() and not other["chains"].visible_get()
    assert body["chains"].hide_viewport and other["chains"].hide_get()
    for kind in ("axis", "chains", "merged"):
        overlays.set_overlay_visible(kind, True)
    assert all(obj.visible_get() and not obj.hide_viewport for obj in [*body.values(), *other.values()])
    assert overlays.set_overlay_visible("bones", True) == 0  # no such overlay: nothing to do
    # Shown again, the object evaluates as before.
    assert len(evaluated(body["axis"])[1]) > 0


def test_clear_leaves_nothing_behind(humanoid):
    before = data_counts()
    overlays.clear_overlays()  # nothing to clear yet
    overlays.build_overlays(humanoid[2], "Body")
    overlays.build_overlays(humanoid[2], "Other")
    overlays.clear_overlays()
    assert data_counts() == before
    leftovers = [data.name for kind in ("objects", "meshes", "node_groups", "materials", "collections")
                 for data in getattr(bpy.data, kind) if data.name.startswith("Rigger")]
    assert leftovers == []
    overlays.clear_overlays()
    assert data_counts() == before


def test_stages_without_drawings_draw_nothing_and_a_rebuild_still_replaces(humanoid):
    stages = humanoid[2]
    undrawn = {"frame": stages["frame"], "plane": MirrorPlane(0, 0.0, np.array([1.0, 0, 0]))}
    before = data_counts()
    assert overlays.build_overlays(undrawn, "Body") == {}
    assert data_counts() == before
    # A rebuild from such stages still removes the owner's earlier overlays.
    overlays.build_overlays(stages, "Body")
    assert overlays.build_overlays(undrawn, "Body") == {}
    assert not [obj for obj in bpy.data.objects if obj.name.startswith("Rigger")]


class Broken(Stage):
    """A stage whose drawing fails."""

    def drawing(self):
        return {}["points"]


class Sketchy(Stage):
    """A stage that draws something the overlays do not know."""

    def drawing(self):
        return np.zeros((2, 3))


def test_what_is_not_a_stage_or_fails_to_draw_is_skipped_with_a_warning(humanoid):
    stages = {**humanoid[2], "raw": np.zeros(3), "broken": Broken(), "sketchy": Sketchy()}
    with pytest.warns(RuntimeWarning) as record:
        objects = overlays.build_overlays(stages, "Body")
    assert list(objects) == KINDS
    assert sorted(str(warning.message) for warning in record) == [
        "Rigger overlay 'broken' skipped: drawing its Broken failed: KeyError: 'points'",
        "Rigger overlay 'raw' skipped: a ndarray, not a rigger.core.stages.Stage",
        "Rigger overlay 'sketchy' skipped: its drawing is a ndarray, not Lines, Points, ClassedFaces or Labels"]


def test_a_test_only_package_method_s_own_stage_type_gets_its_overlay():
    """The test method ``slices`` (a package under tests/methods) returns a stage type of its own, ``Rings``, and
    ``Joints``: both are drawn, the rings as tubes around each slab in the stage's colour, with nothing in the
    Blender layer knowing the type."""
    empty_scene()
    method = discover(TEST_METHODS).methods["slices"]
    vertices, triangles = samples.character_arrays("snake", subdivisions=0)
    skeleton = rigger.rig_mesh(vertices, triangles, method=method, slabs=5)
    objects = overlays.build_overlays(skeleton.stages, "Snake", scale=0.01)
    assert list(objects) == ["rings", "centres", "roles"]
    rings = skeleton.stages["rings"]
    drawn, materials = evaluated(objects["rings"])
    assert set(materials) == {"Rigger rings"}
    assert tuple(bpy.data.materials["Rigger rings"].diffuse_color)[:3] == pytest.approx(rings.colour)
    across = [axis for axis in range(3) if axis != rings.axis]
    nearest = np.argmin(np.abs(drawn[:, rings.axis][:, None] - rings.centres[:, rings.axis][None]), axis=1)
    distance = np.linalg.norm((drawn - rings.centres[nearest])[:, across], axis=1)
    assert np.abs(distance - rings.radii[nearest]).max() <= 0.02  # on the rings, within the tube's radius
    np.testing.assert_allclose(evaluated(objects["centres"])[0].reshape(5, -1, 3).mean(axis=1),
                               skeleton.stages["centres"].points, atol=1e-5)


@pytest.mark.parametrize("arguments", [
    {"stages": [], "owner": "Body"},
    {"owner": ""},
    {"owner": 3},
    {"scale": 0.0},
    {"scale": float("nan")},
    {"scale": True},
])
def test_bad_arguments_raise(humanoid, arguments):
    call = {"stages": humanoid[2], "owner": "Body", **arguments}
    with pytest.raises(ValueError):
        overlays.build_overlays(call.pop("stages"), call.pop("owner"), **call)
    assert not [obj for obj in bpy.data.objects if obj.name.startswith("Rigger")]


def test_role_labels_are_text_objects_beside_each_bone(humanoid):
    """The roles stage draws a sphere per bone and a text object with its role beside it, a child of the stage's
    object, shown and hidden with it; clearing removes the texts' curves too."""
    stages = humanoid[2]
    curves_before = len(bpy.data.curves)
    roles = overlays.build_overlays(stages, "Body")["roles"]
    texts = sorted((obj for obj in bpy.data.objects if obj.parent == roles), key=lambda obj: obj.name)
    assert [text.data.body for text in texts] == list(stages["roles"].texts)
    assert all(text.type == 'FONT' and text[overlays.KIND_KEY] == "roles" and text.hide_select for text in texts)
    bpy.context.view_layer.update()
    beside = np.array([text.matrix_world.translation for text in texts]) - stages["roles"].points
    assert (beside[:, 0] > 0).all() and np.abs(beside[:, 1:]).max() < 1e-6  # just right of each bone's middle
    assert len(evaluated(roles)[1]) > 0  # the spheres
    assert overlays.set_overlay_visible("roles", False) == 1 + len(texts)
    assert not any(text.visible_get() for text in texts)
    overlays.clear_overlays()
    assert len(bpy.data.curves) == curves_before
