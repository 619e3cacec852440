# SPDX-License-Identifier: GPL-3.0-or-later
"""The module wires the libraries as `sonomap run` does: a built-in mapper stepped from Python
and scored by Scenario.score gives run's frames.csv, frame for frame."""
import csv
import math
import os
import subprocess
import tempfile

import sonomap
from testing import SOURCE_DIR, run

SMOKE = os.path.join(SOURCE_DIR, "scenes", "smoke.yaml")
FRAMES = 2
COLUMNS = ["coverage", "rmse", "rmse_off_edges", "ghosts", "known"]


def run_frames_csv(out):
    subprocess.run([os.environ["SONOMAP_EXE"], "--quiet", "run", SMOKE, "--frames", str(FRAMES),
                    "--mapper", "vdb_gpdf", "--pictures", "-1", "--sweeps", "-1",
                    "--set", "edf.enabled=false", "--out", out], check=True)
    with open(os.path.join(out, "frames.csv")) as f:
        return list(csv.DictReader(f))


def test_module_scores_equal_run_s_frames_csv():
    with tempfile.TemporaryDirectory() as tmp:
        rows = run_frames_csv(os.path.join(tmp, "run"))
    scene = sonomap.Scenario(SMOKE, frames=FRAMES)
    mapper = scene.mapper("vdb_gpdf")
    assert len(rows) == FRAMES
    for frame, row in zip(scene, rows):
        mapper.integrate(frame)
        rasters = mapper.rasters(frame)
        scores = scene.score(frame, rasters.circle, rasters.cylinder)
        for raster in ("circle", "cylinder"):
            m = dict(scores[raster], known=scores[raster]["estimate_known"])
            for column in COLUMNS:
                written = row[f"{raster}_{column}"]
                value = m[column]
                if isinstance(value, float):  # run leaves an undefined metric empty
                    value = f"{value:.6f}" if math.isfinite(value) else ""
                value = str(value)
                assert value == written, (frame.index, raster, column, value, written)


run(globals())
