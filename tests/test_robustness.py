"""The robustness benchmark's noise (bench/robustness.py)."""
import numpy as np

from robustness import noisy


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
