# SPDX-License-Identifier: GPL-3.0-or-later
"""Sweeps to numpy and to WAV: never above -1 dBFS, the WAV holds the samples rendered, and a
file sonomap did not write is never replaced."""
import os
import struct
import tempfile

import numpy as np

import sonomap
from testing import run

CEILING = 10.0 ** (-1.0 / 20.0)  # -1 dBFS
# The direct sound only, 50 ms of response: the BRIR synthesis (1200 of them) stays fast.
SWEEP = sonomap.Sweep(room="4x4x2.5", rt60=0.2, order=0, ir_length=0.05)
CIRCLE = np.full(360, np.nan)
CIRCLE[:90] = 0.8  # a near wall on the left quarter, the rest unknown (wooshes)


def wav_samples(path):
    """The float32 samples of a WAV's data chunk, read without sonomap."""
    with open(path, "rb") as f:
        data = f.read()
    assert data[:4] == b"RIFF" and data[8:12] == b"WAVE"
    pos = 12
    while pos < len(data):
        chunk, size = data[pos:pos + 4], struct.unpack("<I", data[pos + 4:pos + 8])[0]
        if chunk == b"fmt ":
            fmt_tag, channels, rate = struct.unpack("<HHI", data[pos + 8:pos + 16])
            assert fmt_tag == 3 and channels == 2, (fmt_tag, channels)  # IEEE float stereo
        if chunk == b"data":
            return rate, np.frombuffer(data[pos + 8:pos + 8 + size], dtype="<f4").reshape(-1, 2)
        pos += 8 + size + (size & 1)
    raise AssertionError("no data chunk")


def test_sweep_array_peaks_at_most_minus_one_dbfs():
    audio = SWEEP.render(CIRCLE)
    assert audio.dtype == np.float32 and audio.ndim == 2 and audio.shape[1] == 2
    # One 2 s turn at the sample rate, plus the tail of the last sound.
    assert audio.shape[0] >= 2.0 * SWEEP.sample_rate
    peak = np.abs(audio).max()
    assert 0.0 < peak <= CEILING, peak


def test_wav_holds_the_rendered_sweep():
    with tempfile.TemporaryDirectory() as tmp:
        wav = os.path.join(tmp, "sweep.wav")
        level = SWEEP.write(CIRCLE, wav)
        assert level["true_peak_dbtp"] <= -1.0, level
        rate, samples = wav_samples(wav)
        assert rate == SWEEP.sample_rate
        assert np.array_equal(samples, SWEEP.render(CIRCLE))
        assert os.path.exists(os.path.join(tmp, "sweep.events.csv"))
        SWEEP.write(CIRCLE, wav)  # its own earlier sweep may be replaced


def test_a_file_sonomap_did_not_write_is_left_alone():
    with tempfile.TemporaryDirectory() as tmp:
        wav = os.path.join(tmp, "mine.wav")
        with open(wav, "w") as f:
            f.write("my data")
        try:
            SWEEP.write(CIRCLE, wav)
        except sonomap.InputError as e:
            assert "mine.wav" in str(e), str(e)
        else:
            raise AssertionError("replaced a file sonomap did not write")
        with open(wav) as f:
            assert f.read() == "my data"
        assert sorted(os.listdir(tmp)) == ["mine.wav"]


run(globals())
