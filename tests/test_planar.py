import numpy as np
import pytest

from pushjax import planar


def test_rotation_matrix_and_rotate_agree_and_broadcast():
    yaw = np.array([0.0, np.pi / 2, 1.0])
    vectors = np.array([[1.0, 0.0], [1.0, 0.0], [0.3, -2.0]])
    expected = np.einsum("nij,nj->ni", planar.rotation_matrix(yaw), vectors)
    np.testing.assert_allclose(planar.rotate(vectors, yaw), expected)
    np.testing.assert_allclose(planar.rotate([1.0, 0.0], np.pi / 2), [0.0, 1.0], atol=1e-15)
    assert planar.rotation_matrix(0.3).shape == (2, 2)


def test_rotate_back_is_the_inverse():
    rng = np.random.default_rng(0)
    vectors, yaw = rng.normal(size=(5, 2)), rng.normal(size=5)
    np.testing.assert_allclose(planar.rotate(planar.rotate(vectors, yaw), -yaw), vectors)


@pytest.mark.parametrize("yaw", [0.0, 0.7, -2.5])
def test_centre_of_mass_of_a_pose(yaw):
    centroid = np.array([0.01, -0.02])
    pose = np.array([0.1, 0.2, yaw])
    expected = pose[:2] + np.array([[np.cos(yaw), -np.sin(yaw)], [np.sin(yaw), np.cos(yaw)]]) @ centroid
    np.testing.assert_allclose(planar.centre_of_mass(centroid, pose), expected)
    np.testing.assert_allclose(planar.centre_of_mass(centroid, np.stack([pose, pose])), [expected, expected])
