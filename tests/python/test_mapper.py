# SPDX-License-Identifier: GPL-3.0-or-later
"""Built-in mappers frame by frame: their circles in an empty square room against the closed
form (square_room.yaml, exact depth)."""
import numpy as np

import sonomap
from square_room import square_room_circle
from testing import run, scene_file

SCENE = sonomap.Scenario(scene_file("square_room.yaml"))
TRUTH = square_room_circle(360)
# The camera sees 2 atan(320 / 525) = 62.7 degrees of the circle: at most 64 one-degree bins.
FOV_BINS = 64


def mapped_circle(name, **kwargs):
    mapper = SCENE.mapper(name, **kwargs)
    assert mapper.name == name
    frame = SCENE[0]
    mapper.integrate(frame)
    rasters = mapper.rasters(frame)
    assert rasters.circle.shape == (360,) and rasters.cylinder.shape == (19, 360)
    return rasters.circle


def test_the_built_in_mappers_are_offered():
    assert sonomap.mapper_names()[:4] == ["vdb_gpdf", "tsdf", "open3d", "depth_only"]


def test_depth_only_reads_the_walls():
    circle = mapped_circle("depth_only")
    known = ~np.isnan(circle)
    # A memoryless mapper knows what one image shows: more than half the view, never more.
    assert FOV_BINS // 2 < np.count_nonzero(known) <= FOV_BINS
    # The view's two edge bins (heading 30 degrees, half view 31.35 degrees: bins 31 and 328)
    # are seen in part, and the nearest return of part of a wedge is no nearer than the
    # wedge's exact minimum.
    edges = [31, 328]
    assert known[edges].all() and (circle[edges] >= TRUTH[edges]).all()
    # Exact returns on the walls: inside the view a bin's nearest return is within the pixel
    # spacing at 3.2 m (3.2 / 525 = 6 mm) of the wedge's exact minimum.
    inside = known.copy()
    inside[edges] = False
    error = np.abs(circle[inside] - TRUTH[inside])
    assert error.max() < 0.01, error.max()


def test_the_maps_read_the_walls_within_half_a_voxel_diagonal():
    for name, settings in (("vdb_gpdf", {"carving": False}), ("tsdf", None), ("open3d", None)):
        circle = mapped_circle(name, voxel=0.05, settings=settings)
        known = ~np.isnan(circle)
        assert FOV_BINS // 2 < np.count_nonzero(known) <= FOV_BINS + 2, name
        # Surface samples of a 5 cm map lie within half a voxel diagonal (4.3 cm) of the wall.
        error = np.abs(circle[known] - TRUTH[known])
        assert error.max() < 0.0433, (name, error.max())


def test_mapper_config_records_the_settings():
    mapper = SCENE.mapper("tsdf", voxel=0.1)
    assert float(mapper.config["voxel"]) == 0.1


run(globals())
