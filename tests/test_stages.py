"""Typed stages (rigger.core.stages): each checks its arrays, maps itself to the world and says how it is drawn."""
import numpy as np
import pytest

from rigger.core.stages import (ISOLATED, JUNCTION, SLEEVE, TERMINAL, AxisGraph, Chains, ClassedFaces, Frame, Joints,
                                Lines, MirrorPlane, Outline, Placement, Points, PrunedBranches, Triangulation)

QUARTER_TURN = np.array([[0.0, 1.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])  # rows: the frame's axes in the world


def frame(depth=0.5):
    """Looking along z at the plane z = depth, u = x, v = y."""
    return Frame(np.zeros(3), np.array([1.0, 0, 0]), np.array([0, 1.0, 0]), np.array([0, 0, 1.0]), depth, np.eye(3))


def test_planar_stages_lie_on_their_frames_plane_and_map_with_it():
    square = np.array([[0, 0], [2, 0], [2, 2], [0, 2]], dtype=float)
    outline = Outline(frame(), [square])
    drawn = outline.drawing()
    assert isinstance(drawn, Lines)
    np.testing.assert_array_equal(drawn.points, np.column_stack([square, np.full(4, 0.5)]))
    assert sorted(map(tuple, drawn.edges.tolist())) == [(0, 1), (1, 2), (2, 3), (3, 0)]

    placed = outline.mapped(Placement(2.0, QUARTER_TURN))  # the method worked at twice the size, turned
    np.testing.assert_array_equal(placed.loops[0], square / 2)
    np.testing.assert_array_equal(placed.frame.u, [0, 1, 0])  # x of the frame is y of the world
    np.testing.assert_array_equal(placed.frame.axes, QUARTER_TURN)
    assert placed.frame.depth == 0.25
    np.testing.assert_allclose(placed.drawing().points, (drawn.points / 2) @ QUARTER_TURN)


def test_a_triangulation_draws_its_used_vertices_with_a_palette_in_edge_priority():
    vertices = np.array([[0, 0], [1, 0], [0, 1], [1, 1], [9, 9]], dtype=float)  # the last is used by no triangle
    stage = Triangulation(frame(), vertices, np.array([[0, 1, 2], [1, 3, 2]], dtype=np.int32),
                          np.array([JUNCTION, SLEEVE]))
    drawn = stage.drawing()
    assert isinstance(drawn, ClassedFaces) and len(drawn.points) == 4
    assert [code for code, _, _ in drawn.palette] == [SLEEVE, ISOLATED, TERMINAL, JUNCTION]
    assert {name for _, name, _ in drawn.palette} == {"terminal", "sleeve", "junction", "isolated"}


def test_graphs_draw_each_link_once_without_self_links_or_unused_points():
    graph = PrunedBranches(frame(0.0), np.array([[0.0, 0], [1, 0], [2, 0], [9, 9]]), np.ones(4),
                           np.array([[0, 1], [1, 0], [1, 1], [1, 2]]))
    drawn = graph.drawing()
    assert len(drawn.points) == 3 and sorted(map(tuple, drawn.edges.tolist())) == [(0, 1), (1, 2)]
    mapped = graph.mapped(Placement(4.0))
    assert type(mapped) is PrunedBranches and mapped.radius.tolist() == [0.25] * 4
    assert AxisGraph(frame(), np.zeros((0, 2)), np.zeros(0), np.zeros((0, 2), int)).drawing() is None


def test_chains_joints_and_the_mirror_plane_map_to_the_world():
    line = np.array([[0.0, 0, 0], [2, 0, 0]])
    chains = Chains([line]).mapped(Placement(2.0, QUARTER_TURN))
    np.testing.assert_array_equal(chains.lines[0], [[0, 0, 0], [0, 1, 0]])
    assert isinstance(Joints(line).drawing(), Points)
    plane = MirrorPlane(0, 2.0, np.array([1.0, 0, 0])).mapped(Placement(2.0, QUARTER_TURN))
    assert (plane.axis, plane.offset) == (0, 1.0)
    np.testing.assert_array_equal(plane.normal, [0, 1, 0])
    np.testing.assert_allclose(plane.reflect(np.array([[5.0, 0.5, 3.0]])), [[5.0, 1.5, 3.0]])
    assert plane.drawing() is None and frame().drawing() is None


@pytest.mark.parametrize("make, message", [
    (lambda: Outline(frame(), [np.full((4, 2), np.nan)]), "Outline: loop 0 has non-finite values"),
    (lambda: Outline(frame(), [np.zeros((2, 2))]), r"Outline: loop 0 has shape \(2, 2\), not \(K, 2\) with K >= 3"),
    (lambda: Outline(np.eye(3), []), "Outline: 'frame' is a ndarray, not a Frame"),
    (lambda: Triangulation(frame(), np.zeros((3, 2)), np.array([[0, 1, 5]]), np.array([SLEEVE])),
     r"'triangles' indexes outside 0..2"),
    (lambda: Triangulation(frame(), np.zeros((3, 2)), np.array([[0, 1, 2]]), np.array([7])), "'classes'"),
    (lambda: Triangulation(frame(), np.zeros((3, 2)), np.array([[0, 1, 1]]), np.array([SLEEVE])),
     "a triangle repeats a vertex"),
    (lambda: AxisGraph(frame(), np.zeros((2, 2)), np.ones(2), np.array([[0, 1]]) + 0.5), "not \\(K, 2\\) integers"),
    (lambda: AxisGraph(frame(), np.zeros((2, 2)), np.ones(3), np.zeros((0, 2), int)), "'radius'"),
    (lambda: Chains({"a": np.zeros((2, 3))}), "Chains: 'lines' is a dict"),
    (lambda: Chains([np.zeros((2, 2))]), "Chains: line 0 has shape"),
    (lambda: Joints([[0.0, 1.0, 2.0], [1.0]]), "Joints: 'points' is not a regular array of numbers"),
    (lambda: Frame(np.zeros(3), *np.eye(3), float("nan"), np.eye(3)), "'depth' is nan"),
    (lambda: Frame(np.zeros(3), np.eye(3)[0], np.eye(3)[1], np.zeros(3), 0.0, np.eye(3)), "'direction' is not a unit"),
    (lambda: Frame(np.zeros(3), *np.eye(3), 0.0, 2 * np.eye(3)), "'axes' are not orthonormal"),
    (lambda: MirrorPlane(3, 0.0, np.array([1.0, 0, 0])), "'axis' is 3"),
    (lambda: MirrorPlane(True, 0.0, np.array([1.0, 0, 0])), "'axis' is True"),
    (lambda: MirrorPlane(0, 0.0, np.array([2.0, 0, 0])), "'normal' is not a unit vector"),
    (lambda: AxisGraph(frame(), np.zeros((3, 0)), np.ones(3), np.zeros((0, 2), int)), r"shape \(3, 0\)"),
    (lambda: Lines(np.zeros((2, 3)), np.array([[0, 2]])), "Lines: 'edges' indexes outside 0..1"),
    (lambda: Points(np.zeros((0, 3))), "Points: no points to draw"),
    (lambda: ClassedFaces(np.zeros((3, 3)), np.array([[0, 1, 2]]), np.array([5]), ((1, "a", (1, 1, 1)),)),
     "ClassedFaces: 'classes'"),
])
def test_a_stage_with_bad_arrays_is_refused_saying_what_is_wrong(make, message):
    with pytest.raises(ValueError, match=message):
        make()


def test_to_dict_gives_the_fields_with_nested_stages_as_dicts():
    outline = Outline(frame(), [np.zeros((3, 2))]).to_dict()
    assert set(outline) == {"frame", "loops"} and outline["frame"]["depth"] == 0.5
