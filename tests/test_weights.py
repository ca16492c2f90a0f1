"""The compiled fallback weighting (rigger.weights, no bpy): the rule against a brute-force reference, its
invariants, determinism, continuity, the facing penalty and input checks."""
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from rigger import weights


def reference(points, heads, tails, normals=None, bones_per_point=4, power=4.0, facing_penalty=1.0):
    """The documented rule, brute force over every bone: (bones, weights) as ``weights.bone_weights`` returns."""
    axis = tails - heads
    length_squared = (axis * axis).sum(-1)
    t = np.clip(np.divide(((points[:, None] - heads) * axis).sum(-1), length_squared,
                          out=np.zeros((len(points), len(heads))), where=length_squared > 0), 0.0, 1.0)
    toward = heads + t[..., None] * axis - points[:, None]
    keys = np.linalg.norm(toward, axis=-1)
    if normals is not None:
        unit = normals / np.linalg.norm(normals, axis=1, keepdims=True)
        keys = keys + facing_penalty * np.maximum((toward * unit[:, None]).sum(-1), 0.0)
    used = min(bones_per_point, len(heads))
    bones = np.full((len(points), bones_per_point), -1)
    table = np.zeros((len(points), bones_per_point))
    for row, key in enumerate(keys):
        order = np.lexsort((np.arange(len(key)), key))[:used + 1]
        nearest = key[order[0]]
        ratio = np.array([1.0 if k == nearest else (nearest / k) ** power for k in key[order]])
        share = ratio[:used] - (ratio[used] if len(order) > used else 0.0)
        if share.sum() <= 0:
            share = (key[order[:used]] == nearest).astype(float)
        positive = share > 0
        bones[row, :positive.sum()] = order[:used][positive]
        table[row, :positive.sum()] = share[positive] / share.sum()
    return bones, table


def random_rig(seed, n_points, n_bones):
    rng = np.random.default_rng(seed)
    heads = rng.uniform(-1, 1, (n_bones, 3))
    tails = heads + rng.normal(scale=0.3, size=(n_bones, 3))
    points = rng.uniform(-1.2, 1.2, (n_points, 3))
    normals = rng.normal(size=(n_points, 3))
    return points, heads, tails, normals


@pytest.mark.parametrize("n_bones, bones_per_point", [(1, 4), (2, 1), (3, 4), (5, 5), (40, 4), (300, 3), (300, 8)])
@pytest.mark.parametrize("with_normals", [False, True])
def test_matches_the_brute_force_rule(n_bones, bones_per_point, with_normals):
    points, heads, tails, normals = random_rig(n_bones, 400, n_bones)
    normals = normals if with_normals else None
    result = weights.bone_weights(points, heads, tails, normals, bones_per_point=bones_per_point)
    expected_bones, expected_weights = reference(points, heads, tails, normals, bones_per_point)
    assert result.bones.shape == result.weights.shape == (400, bones_per_point)
    assert result.bones.dtype == np.int32 and result.weights.dtype == np.float64
    np.testing.assert_array_equal(result.bones, expected_bones)
    np.testing.assert_allclose(result.weights, expected_weights, rtol=1e-9, atol=1e-12)


@pytest.mark.parametrize("power, penalty", [(1.0, 0.0), (2.5, 0.3), (12.0, 4.0)])
def test_power_and_penalty_follow_the_rule(power, penalty):
    points, heads, tails, normals = random_rig(7, 300, 25)
    result = weights.bone_weights(points, heads, tails, normals, power=power, facing_penalty=penalty)
    expected_bones, expected_weights = reference(points, heads, tails, normals, 4, power, penalty)
    np.testing.assert_array_equal(result.bones, expected_bones)
    np.testing.assert_allclose(result.weights, expected_weights, rtol=1e-9, atol=1e-12)


finite = st.floats(-10, 10, allow_nan=False, width=64)


@settings(max_examples=150)
@given(points=arrays(np.float64, st.tuples(st.integers(0, 12), st.just(3)), elements=finite),
       heads=arrays(np.float64, (6, 3), elements=finite), tails=arrays(np.float64, (6, 3), elements=finite),
       count=st.integers(1, 8))
def test_rows_are_normalised_sorted_and_padded(points, heads, tails, count):
    result = weights.bone_weights(points, heads, tails, bones_per_point=count)
    carried = result.bones >= 0
    assert carried[:, 0].all()
    np.testing.assert_allclose(result.weights.sum(axis=1), 1.0, atol=1e-12)
    assert (result.weights[carried] > 0).all() and (result.weights[~carried] == 0).all()
    assert (np.diff(result.weights, axis=1) <= 1e-15).all()  # non-increasing along each row
    assert (np.diff(carried.astype(int), axis=1) <= 0).all()  # -1 only after the carried bones
    for row, mask in zip(result.bones, carried):
        assert len(set(row[mask].tolist())) == mask.sum() <= min(count, 6)


def test_a_point_on_a_bone_gets_that_bone_and_a_joint_shares_equally():
    heads = np.array([[0.0, 0, 0], [1, 0, 0], [0, 2, 0]])
    tails = np.array([[1.0, 0, 0], [2, 0, 0], [0, 3, 0]])
    points = np.array([[0.3, 0, 0], [1.7, 0, 0], [0, 2.5, 0], [1, 0, 0]])
    result = weights.bone_weights(points, heads, tails)
    assert result.bones[:3, 0].tolist() == [0, 1, 2] and result.weights[:3, 0].tolist() == [1.0, 1.0, 1.0]
    assert (result.bones[:3, 1:] == -1).all()
    assert result.bones[3, :2].tolist() == [0, 1] and result.weights[3, :2].tolist() == [0.5, 0.5]


def test_ties_beyond_the_kept_bones_share_equally_among_the_lowest_indices():
    heads = np.concatenate([np.eye(3), -np.eye(3)])  # six bones pointing away, each exactly 1 from the origin
    result = weights.bone_weights([[0.0, 0.0, 0.0]], heads, heads * 2, bones_per_point=4)
    assert result.bones.tolist() == [[0, 1, 2, 3]]
    np.testing.assert_allclose(result.weights, [[0.25, 0.25, 0.25, 0.25]])


def test_a_bone_in_front_of_the_surface_loses_to_one_behind_it():
    """A vertex on the inside of a thigh, its normal towards the other leg: the other leg's bone is nearer, but it
    lies in front of the surface; its own bone, a little farther, lies behind."""
    heads = np.array([[1.0, 0, -1], [-1.2, 0, -1]])
    tails = heads + [0.0, 0.0, 2.0]
    point, normal = np.zeros((1, 3)), np.array([[1.0, 0.0, 0.0]])
    assert weights.bone_weights(point, heads, tails).bones[0, 0] == 0  # no normals: distance alone
    assert weights.bone_weights(point, heads, tails, normal, facing_penalty=0).bones[0, 0] == 0
    with_penalty = weights.bone_weights(point, heads, tails, normal)
    assert with_penalty.bones[0].tolist() == [1, 0, -1, -1]  # keys 1.2 and 1 + 1 = 2
    np.testing.assert_allclose(with_penalty.weights[0, :2], np.array([1, (1.2 / 2) ** 4]) / (1 + (1.2 / 2) ** 4))
    # a zero normal switches the penalty off for that point
    assert weights.bone_weights(point, heads, tails, np.zeros((1, 3))).bones[0, 0] == 0


def test_deterministic_and_independent_of_input_order():
    points, heads, tails, normals = random_rig(3, 500, 60)
    first = weights.bone_weights(points, heads, tails, normals)
    again = weights.bone_weights(points, heads, tails, normals)
    np.testing.assert_array_equal(first.bones, again.bones)
    np.testing.assert_array_equal(first.weights, again.weights)
    rng = np.random.default_rng(0)
    bone_order, point_order = rng.permutation(60), rng.permutation(500)
    shuffled = weights.bone_weights(points[point_order], heads[bone_order], tails[bone_order], normals[point_order])
    carried = shuffled.bones >= 0
    renamed = np.where(carried, bone_order[np.where(carried, shuffled.bones, 0)], -1)
    np.testing.assert_array_equal(renamed, first.bones[point_order])
    np.testing.assert_allclose(shuffled.weights, first.weights[point_order], rtol=1e-12)


def test_weights_vary_continuously_along_a_path():
    """A bone's weight reaches zero exactly when another bone overtakes it, so no weight jumps between nearby
    points, even where the set of nearest bones changes."""
    _, heads, tails, _ = random_rig(11, 1, 30)
    steps = np.linspace(0.0, 1.0, 20001)[:, None]
    path = np.array([-1.5, -1.2, -0.4]) + steps * np.array([3.0, 2.5, 0.9])
    result = weights.bone_weights(path, heads, tails, bones_per_point=3)
    table = result.dense(30)
    changes = set(map(tuple, np.sort(result.bones, axis=1)))
    assert len(changes) > 10  # the path crosses many changes of the nearest three bones
    assert np.abs(np.diff(table, axis=0)).max() < 0.01


def test_dense_table():
    result = weights.bone_weights([[0.2, 0, 0], [1.5, 0.1, 0]], [[0, 0, 0], [1, 0, 0]], [[1, 0, 0], [2, 0, 0]])
    table = result.dense(3)
    assert table.shape == (2, 3) and table[0].tolist() == [1.0, 0.0, 0.0]
    np.testing.assert_allclose(table.sum(axis=1), 1.0)
    for bad in (1, 0, 2.0, True):
        with pytest.raises(ValueError, match="bone_count"):
            result.dense(bad)


def test_no_points_gives_empty_rows():
    result = weights.bone_weights(np.zeros((0, 3)), [[0, 0, 0]], [[0, 0, 1]], bones_per_point=2)
    assert result.bones.shape == result.weights.shape == (0, 2)


@pytest.mark.parametrize("arguments, keywords, message", [
    (([[0, 0]], [[0, 0, 0]], [[1, 0, 0]]), {}, r"points must have shape \(N, 3\)"),
    (([[0, 0, np.nan]], [[0, 0, 0]], [[1, 0, 0]]), {}, "points must be finite; row 0"),
    (([[0, 0, 0]], np.zeros((0, 3)), np.zeros((0, 3))), {}, "at least one bone"),
    (([[0, 0, 0]], [[0, 0, 0]], [[1, 0, 0], [2, 0, 0]]), {}, "same shape"),
    (([[0, 0, 0]], [[0, 0, 0]], [[np.inf, 0, 0]]), {}, "tails must be finite"),
    (([[0, 0, 0]], [["a", 0, 0]], [[1, 0, 0]]), {}, "heads must be a numeric array"),
    (([[0, 0, 0]], [[0, 0, 0]], [[1, 0, 0]], [[1, 0, 0], [0, 1, 0]]), {}, "normals must match"),
    (([[0, 0, 0]], [[0, 0, 0]], [[1, 0, 0]]), {"bones_per_point": 0}, "bones_per_point"),
    (([[0, 0, 0]], [[0, 0, 0]], [[1, 0, 0]]), {"bones_per_point": 2.0}, "bones_per_point"),
    (([[0, 0, 0]], [[0, 0, 0]], [[1, 0, 0]]), {"bones_per_point": True}, "bones_per_point"),
    (([[0, 0, 0]], [[0, 0, 0]], [[1, 0, 0]]), {"power": 0}, "power"),
    (([[0, 0, 0]], [[0, 0, 0]], [[1, 0, 0]]), {"power": np.nan}, "power"),
    (([[0, 0, 0]], [[0, 0, 0]], [[1, 0, 0]]), {"power": "4"}, "power"),
    (([[0, 0, 0]], [[0, 0, 0]], [[1, 0, 0]]), {"facing_penalty": -1}, "facing_penalty"),
    (([[0, 0, 0]], [[0, 0, 0]], [[1, 0, 0]]), {"facing_penalty": np.inf}, "facing_penalty"),
])
def test_bad_input_is_a_clear_value_error(arguments, keywords, message):
    with pytest.raises(ValueError, match=message):
        weights.bone_weights(*arguments, **keywords)


def test_vertex_normals_sum_the_area_weighted_normals_of_each_vertexs_triangles():
    """A unit square as two triangles (each cross product of length 1, twice its area), a triangle of the square's
    size standing on its edge, and a vertex without a triangle."""
    vertices = [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0), (0, 0, 2), (5, 5, 5)]
    triangles = [(0, 1, 2), (0, 2, 3), (0, 4, 1)]
    normals = weights.vertex_normals(vertices, triangles)
    np.testing.assert_allclose(normals, [(0, 2, 2), (0, 2, 1), (0, 0, 2), (0, 0, 1), (0, 2, 0), (0, 0, 0)])
    assert weights.vertex_normals(np.zeros((0, 3)), np.zeros((0, 3), int)).shape == (0, 3)
    with pytest.raises(ValueError, match=r"triangle 1 \[0, 2, 6\] indexes outside the 6 vertices"):
        weights.vertex_normals(vertices, [(0, 1, 2), (0, 2, 6)])
    with pytest.raises(ValueError, match="vertices must be finite"):
        weights.vertex_normals([(0, 0, np.nan)] * 3, [(0, 1, 2)])


def test_a_seams_copies_get_one_row_once_welded():
    """A closed box split along every edge (each face its own corners, as flat shading leaves it): each copy's own
    face normal sends the facing penalty different ways; the normals of the welded box do not."""
    corners = np.array([(x, y, z) for x in (0, 1) for y in (0, 1) for z in (0, 1)], dtype=float) - 0.5
    quads = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
    welded_triangles = np.array([(a, b, c) for a, b, c, d in quads] + [(a, c, d) for a, b, c, d in quads])
    split_of = welded_triangles.ravel()  # each corner of each triangle is its own vertex
    split_vertices = corners[split_of]
    split_triangles = np.arange(len(split_of)).reshape(-1, 3)
    heads, tails = np.array([(-2.0, 0.2, 0.0), (2.0, -0.3, 0.1)]), np.array([(-1.0, 0.2, 0.0), (1.0, -0.3, 0.4)])

    def largest_spread(normals):
        """The largest difference of one bone's weight between two copies of a corner."""
        table = weights.bone_weights(split_vertices, heads, tails, normals).dense(len(heads))
        return max(np.ptp(table[split_of == corner], axis=0).max() for corner in range(8))

    assert largest_spread(weights.vertex_normals(split_vertices, split_triangles)) > 0.1
    assert largest_spread(weights.vertex_normals(corners, welded_triangles)[split_of]) == 0
