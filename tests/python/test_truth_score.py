# SPDX-License-Identifier: GPL-3.0-or-later
"""Exact ground truth against the closed form of a square room, and the metrics of circles
whose scores are known by hand (square_room.yaml)."""
import math

import numpy as np

import sonomap
from square_room import square_room_circle
from testing import run, scene_file


def test_truth_circle_of_a_square_room_is_the_closed_form():
    scene = sonomap.Scenario(scene_file("square_room.yaml"))
    truth = scene.truth(scene[0])
    assert truth.circle.shape == (360,)
    expected = square_room_circle(360)
    assert np.abs(truth.circle - expected).max() < 1e-5, np.abs(truth.circle - expected).max()
    # The walls are vertical and span the whole obstacle band: every cylinder row is the circle.
    rows = scene.raster["rows"]
    assert truth.cylinder.shape == (rows, 360) and rows == 19
    assert np.abs(truth.cylinder - expected[None, :]).max() < 1e-5


def test_truth_scored_against_itself_is_perfect():
    scene = sonomap.Scenario(scene_file("square_room.yaml"))
    frame = scene[0]
    truth = scene.truth(frame)
    scores = scene.score(frame, truth.circle, truth.cylinder)
    for raster, cells in (("circle", 360), ("cylinder", 19 * 360)):
        m = scores[raster]
        assert m["rmse"] == 0.0 and m["coverage"] == 1.0 and m["ghosts"] == 0, (raster, m)
        assert m["cells"] == m["truth_occupied"] == m["known_in_both"] == cells


def test_constant_circle_in_four_bins():
    # Four 90-degree bins around the room's centre, facing +x: each wedge reaches a wall's
    # normal, so every bin's truth is the half side, 2 m. A constant 1.5 m circle is 0.5 m off
    # everywhere (RMSE 0.5), and 0.5 m closer than the walls is a ghost in every bin.
    scene = sonomap.Scenario(scene_file("square_room.yaml"), [
        "raster.azimuth_bins=4", "body.keyframes.0={time: 0, position: [0, 0, 1.2], yaw: 0}"])
    frame = scene[0]
    assert np.array_equal(scene.truth(frame).circle, [2.0, 2.0, 2.0, 2.0])
    m = scene.score(frame, np.full(4, 1.5))["circle"]
    assert math.isclose(m["rmse"], 0.5, abs_tol=1e-7) and m["coverage"] == 1.0 and m["ghosts"] == 4
    assert "cylinder" not in scene.score(frame, np.full(4, 1.5))


def test_constant_circle_with_unknown_bins():
    scene = sonomap.Scenario(scene_file("square_room.yaml"))
    frame = scene[0]
    truth = square_room_circle(360)
    estimate = np.full(360, 2.0)
    estimate[180:] = np.nan  # half the circle unknown
    m = scene.score(frame, estimate)["circle"]
    expected_rmse = math.sqrt(np.mean((2.0 - truth[:180]) ** 2))
    assert math.isclose(m["rmse"], expected_rmse, abs_tol=1e-5), (m["rmse"], expected_rmse)
    assert m["coverage"] == 0.5 and m["estimate_known"] == 180 and m["known_in_both"] == 180
    # A ghost: more than the tolerance (0.10 m) closer than the truth.
    assert m["ghosts"] == int(np.count_nonzero(truth[:180] - 2.0 > scene.metrics["ghost_tolerance"]))


run(globals())
