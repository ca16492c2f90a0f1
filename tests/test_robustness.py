"""The robustness benchmark's noise (bench/robustness.py)."""
import numpy as np
import pytest

import rigger
from bodyplan import load
from conftest import shared_path
from robustness import BRIDGE, bridges, noisy


def test_noise_moves_the_copies_of_a_vertex_together_and_repeats_with_its_seed():
    """Vertices split at a seam (the same position twice) move as one, so the noisy surface stays closed; the noise
    has the standard deviation asked for, and one seed gives one result."""
    rng = np.random.default_rng(5)
    positions = rng.uniform(-1.0, 1.0, (2000, 3))
    vertices = np.vstack([positions, positions[:500]])  # the first 500 positions split at a seam
    moved = noisy(vertices, 0.01, seed=3)
    np.testing.assert_array_equal(moved[:500], moved[2000:])
    assert abs(np.std(moved[:2000] - positions) - 0.01) < 0.001
    np.testing.assert_array_equal(moved, noisy(vertices, 0.01, seed=3))
    assert not np.array_equal(moved, noisy(vertices, 0.01, seed=4))


def test_a_stubby_quadrupeds_legs_stay_four_under_noise():
    """rignet_15446, a stubby dinosaur, seen from the side: its hind legs' long two-toed feet cross four parts at
    more nodes than the legs cross two once noise adds nodes there, and each hind leg got two chains side by side:
    six legs, no body plan."""
    shared_path("models")  # skips without ../shared
    vertices, triangles, _, _ = load("rignet_15446")
    size = np.ptp(vertices, axis=0).max()
    skeleton = rigger.rig_mesh(noisy(vertices, 0.0005 * size, 1), triangles)
    assert skeleton.body_plan.kind == "quadruped"
    assert skeleton.body_plan.parts["legs"] == 4


@pytest.mark.parametrize("model, sigma, seed", [
    ("rignet_2982", 0.0005, 0),  # the head's stretch followed one ear: a bone from that ear's tip to the other's
    ("Quaternius_Husky", 0.001, 1),  # the hind legs' fork piece ended at one hip: a bone from hip to hip
    ("rignet_8338", 0.001, 3),  # a front leg's copy stepped into the other foot: bones from foot to foot
    ("rignet_17872", 0.001, 3),  # a hidden leg's copy began at the other hip: two legs more, toes across
    ("Quaternius_Husky", 0.001, 0),  # the head's chain ran on into one ear, whose twin its rays just missed
])
def test_no_bone_bridges_twin_parts_under_noise(model, sigma, seed):
    """Noise nobody would see (a share of the size, per vertex position) once left bones joining twin parts through
    the air, across the mirror plane; twins now keep to their sides, what they hang from ends on the plane, a
    hidden limb running from one side to the other gives way to its twin's image, and a chain on the plane ends
    before a pair of parts beside it even where its rays miss one of them."""
    shared_path("models")  # skips without ../shared
    vertices, triangles, _, _ = load(model)
    size = np.ptp(vertices, axis=0).max()
    skeleton = rigger.rig_mesh(noisy(vertices, sigma * size, seed), triangles)
    assert bridges(skeleton, BRIDGE * size) == 0
