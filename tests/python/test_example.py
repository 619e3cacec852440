# SPDX-License-Identifier: GPL-3.0-or-later
"""The docs' example (examples/python/wedge_mapper.py) runs and scores sensibly on the smoke
scene: a Python mapper in the loop beside VDB-GPDF."""
import importlib.util
import inspect
import os

from testing import SOURCE_DIR, run

spec = importlib.util.spec_from_file_location(
    "wedge_mapper", os.path.join(SOURCE_DIR, "examples", "python", "wedge_mapper.py"))
wedge_mapper = importlib.util.module_from_spec(spec)
spec.loader.exec_module(wedge_mapper)


def test_wedge_mapper_beside_vdb_gpdf():
    scores = wedge_mapper.main(os.path.join(SOURCE_DIR, "scenes", "smoke.yaml"), frames=4)
    assert len(scores["wedges"]) == len(scores["vdb_gpdf"]) == 4
    for name, per_frame in scores.items():
        for s in per_frame:
            # The camera sees 62.7 degrees, 0.174 of the circle: a working map covers at least
            # half of that. Surfaces are 0.5 to 3 m away; an RMSE of 0.3 m means a broken map.
            assert s["coverage"] > 0.087 and s["rmse"] < 0.3, (name, s)


def test_docs_show_the_example_as_it_is():
    with open(os.path.join(SOURCE_DIR, "docs", "python.md")) as f:
        docs = f.read()
    for function in (wedge_mapper.wedge_circle, wedge_mapper.main):
        assert inspect.getsource(function) in docs, function.__name__


run(globals())
