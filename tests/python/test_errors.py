# SPDX-License-Identifier: GPL-3.0-or-later
"""Bad input raises sonomap.InputError (a ValueError) naming the file, line and key, the
option or the array cell, as the command line would report it."""
import os
import re
import tempfile

import numpy as np

import sonomap
from testing import run, scene_file

WALL = scene_file("wall.yaml")


def raises(call, *fragments):
    try:
        call()
    except ValueError as e:  # sonomap.InputError is one
        message = str(e)
        for fragment in fragments:
            assert re.search(fragment, message), (fragment, message)
        return e
    raise AssertionError("no error raised")


def test_out_of_range_value_in_the_file_names_file_line_and_key():
    with open(WALL) as f:
        text = f.read()
    line = text[:text.index("fx: 50")].count("\n") + 1
    with tempfile.TemporaryDirectory() as tmp:
        bad = os.path.join(tmp, "bad.yaml")
        with open(bad, "w") as f:
            f.write(text.replace("fx: 50", "fx: 0"))
        e = raises(lambda: sonomap.Scenario(bad),
                   rf"bad\.yaml:{line}: key 'sensor\.intrinsics\.fx'", "out of range")
    assert isinstance(e, sonomap.InputError)


def test_out_of_range_override_names_file_key_and_override():
    e = raises(lambda: sonomap.Scenario(WALL, ["sensor.intrinsics.fx=0"]),
               r"wall\.yaml: key 'sensor\.intrinsics\.fx'", "out of range", "set by .*fx=0")
    assert isinstance(e, sonomap.InputError)


def test_misspelt_override_names_the_key():
    raises(lambda: sonomap.Scenario(WALL, ["sensor.nosie.model=kinect"]), "nosie")


def test_bad_run_key_names_the_key():
    raises(lambda: sonomap.Scenario(WALL, ["raster.azimuth_bins=0"]), r"raster\.azimuth_bins")
    raises(lambda: sonomap.Scenario(WALL, ["metrics.ghost_tolerance=-1"]), r"metrics\.ghost_tolerance")
    raises(lambda: sonomap.Scenario(WALL, ["noequals"]), "noequals", "key=value")


def test_missing_file():
    raises(lambda: sonomap.Scenario(os.path.join(os.path.dirname(WALL), "absent.yaml")), "absent.yaml")


def test_bad_mapper_and_setting():
    scene = sonomap.Scenario(WALL)
    raises(lambda: scene.mapper("no_such_mapper"), "no_such_mapper")
    raises(lambda: scene.mapper("vdb_gpdf", settings={"voxel": -1}), "voxel")
    raises(lambda: scene.mapper("vdb_gpdf", settings={"no_such_key": 1}), "no_such_key")
    raises(lambda: scene.mapper("tsdf", voxel=100.0), "voxel")


def test_bad_circle_arrays_name_the_cell():
    scene = sonomap.Scenario(WALL)
    frame = scene[0]
    raises(lambda: scene.score(frame, np.ones(359)), r"shape \(360\)", r"\(359\)")
    bad = np.ones(360)
    bad[7] = -0.5
    raises(lambda: scene.score(frame, bad), r"circle\[7\]", ">= 0")
    bad[7] = np.inf
    raises(lambda: scene.score(frame, bad), r"circle\[7\]")
    raises(lambda: scene.score(frame, np.ones(360), np.ones((3, 360))), "cylinder", r"\(19, 360\)")


def test_bad_sweep_options_name_the_option():
    raises(lambda: sonomap.Sweep(room="5x0x3"), "--room")
    raises(lambda: sonomap.Sweep(mode="loud"), "mode")
    raises(lambda: sonomap.Sweep(rt60=-1.0), "rt60")


run(globals())
