#!/usr/bin/env python3
# SPDX-License-Identifier: GPL-3.0-or-later
"""A mapper in Python, scored beside VDB-GPDF against the exact ground truth (docs/python.md):
the nearest return per azimuth wedge of the current depth image, no memory.
    PYTHONPATH=build/python python3 examples/python/wedge_mapper.py scenes/smoke.yaml 10"""
import sys

import numpy as np

import sonomap


def wedge_circle(frame, raster, ground_z):
    """Per azimuth bin, the nearest horizontal range of this frame's returns in the obstacle band."""
    k = frame.intrinsics
    v, u = np.nonzero(~np.isnan(frame.depth))  # pixels with a return
    z = frame.depth[v, u].astype(np.float64)
    camera = np.stack([(u - k["cx"]) * z / k["fx"], (v - k["cy"]) * z / k["fy"], z], axis=1)
    world = camera @ frame.world_T_camera[:3, :3].T + frame.world_T_camera[:3, 3]
    dx, dy = (world[:, :2] - frame.world_T_body[:2, 3]).T
    distance, height = np.hypot(dx, dy), world[:, 2] - ground_z
    keep = (height >= raster["band_min"]) & (height <= raster["band_max"]) & (distance <= raster["max_range"])
    azimuth = np.degrees(np.arctan2(dy[keep], dx[keep]) - frame.heading) % 360.0
    bins = (azimuth * raster["azimuth_bins"] / 360.0).astype(int) % raster["azimuth_bins"]
    circle = np.full(raster["azimuth_bins"], np.inf)
    np.minimum.at(circle, bins, distance[keep])
    return np.where(np.isinf(circle), np.nan, circle)  # NaN: unknown


def main(scenario="scenes/smoke.yaml", frames=10):
    scene = sonomap.Scenario(scenario, frames=frames)
    gpdf = scene.mapper("vdb_gpdf")
    scores = {"wedges": [], "vdb_gpdf": []}
    for frame in scene:
        gpdf.integrate(frame)
        wedges = wedge_circle(frame, scene.raster, scene.ground_z)
        scores["wedges"].append(scene.score(frame, wedges)["circle"])
        scores["vdb_gpdf"].append(scene.score(frame, gpdf.rasters(frame).circle)["circle"])
    for name, per_frame in scores.items():
        coverage = np.mean([s["coverage"] for s in per_frame])
        rmse = np.nanmean([s["rmse"] for s in per_frame])
        print(f"{name:9} circle mean coverage {coverage:.3f}, mean RMSE {rmse:.3f} m")
    return scores


if __name__ == "__main__":
    main(*sys.argv[1:2], *map(int, sys.argv[2:3]))
