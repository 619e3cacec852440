# SPDX-License-Identifier: GPL-3.0-or-later
"""Frames as numpy: depth, points, poses and intrinsics of a wall 2 m ahead (wall.yaml)."""
import math

import numpy as np

import sonomap
from testing import run, scene_file

SCENE = sonomap.Scenario(scene_file("wall.yaml"))


def test_scenario_as_loaded():
    assert SCENE.name == "wall" and SCENE.seed == 3 and len(SCENE) == 2
    assert SCENE.has_truth and SCENE.ground_z == 0.0


def test_wall_two_metres_ahead_reads_two_metres_at_the_centre_pixel():
    depth = SCENE[0].depth
    assert depth.dtype == np.float32 and depth.shape == (49, 65)
    # Pixel (u, v) = (32, 24) is the principal point: its ray is the optical axis, which meets
    # the wall's near face x = 2.0 at z-depth 2.0 (no noise; the ray tracer works in float,
    # whose spacing at 2 m is 2.4e-7 m).
    assert abs(depth[24, 32] - 2.0) < 1e-6, depth[24, 32]


def test_no_return_is_nan():
    frame = SCENE[0]
    # The wall spans y in [-0.5, 0.5]: at 2 m, column u sees y = -(u - 32) * 2 / 50, so the
    # columns |u - 32| > 12.5 look past it into empty space.
    assert np.isnan(frame.depth[24, 0]) and np.isnan(frame.depth[24, 64])
    assert abs(frame.depth[24, 32 - 12] - 2.0) < 1e-6
    assert np.isnan(frame.depth[:, : 32 - 13]).all()
    # One point per valid pixel, every one on the wall's face z = 2 (the optical axis is world x).
    valid = np.count_nonzero(~np.isnan(frame.depth))
    assert frame.points.shape == (valid, 3)
    assert np.allclose(frame.points[:, 2], 2.0, atol=1e-6)


def test_intrinsics_are_the_scenario_s():
    assert SCENE[1].intrinsics == {"fx": 50.0, "fy": 50.0, "cx": 32.0, "cy": 24.0,
                                   "width": 65, "height": 49}


def test_poses():
    frame = SCENE[1]
    assert frame.index == 1 and math.isclose(frame.time, 0.1)
    # The body stands at (0, 0, 1) facing +x; the camera (no mounting) looks along body x with
    # its optical axes x right (world -y), y down (world -z), z forward (world +x).
    body = np.eye(4)
    body[2, 3] = 1.0
    assert np.allclose(frame.world_T_body, body) and np.allclose(frame.world_T_body_true, body)
    camera = np.array([[0, 0, 1, 0], [-1, 0, 0, 0], [0, -1, 0, 1], [0, 0, 0, 1]], dtype=float)
    assert np.allclose(frame.world_T_camera, camera, atol=1e-12)
    assert frame.heading == 0.0
    # The centre pixel's point, placed with the pose, is on the wall in front of the body.
    centre = np.array([0.0, 0.0, 2.0, 1.0])
    assert np.allclose(frame.world_T_camera @ centre, [2.0, 0.0, 1.0, 1.0])


def test_frames_by_index_and_iteration():
    assert [f.index for f in SCENE] == [0, 1]
    assert SCENE[-1].index == 1
    try:
        SCENE[2]
    except IndexError as e:
        assert "frame 2" in str(e)
    else:
        raise AssertionError("frame 2 of 2 did not raise")


def test_frames_and_seed_arguments():
    short = sonomap.Scenario(scene_file("wall.yaml"), frames=1, seed=9)
    assert len(short) == 1 and short.seed == 9


run(globals())
