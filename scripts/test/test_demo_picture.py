"""m2wr_tools.analysis.picture: beam geometry, scale bar, and that a picture is written."""
import math

import numpy as np
import pytest

from m2wr_tools.analysis import picture
from m2wr_tools.analysis.scene import Outline


def test_beams_go_from_the_sensor_to_each_finite_return():
    ranges = [1.0, math.inf, 2.0]
    segments = picture.beam_segments((1.0, 2.0), math.pi / 2, -math.pi / 2, math.pi / 2, ranges)
    assert segments.shape == (2, 2, 2)
    np.testing.assert_allclose(segments[:, 0], [[1.0, 2.0], [1.0, 2.0]])
    # beam 0 points along the sensor's -90 deg (world +x here), beam 2 along +90 (world -x)
    np.testing.assert_allclose(segments[:, 1], [[2.0, 2.0], [-1.0, 2.0]], atol=1e-12)


def test_scale_length_is_a_round_tenth():
    assert picture.scale_length(21.0) == 5.0
    assert picture.scale_length(9.0) == 1.0
    assert picture.scale_length(3.0) == 0.5
    assert picture.scale_length(100.0) == 10.0


def test_draw_writes_a_png(tmp_path):
    path = str(tmp_path / "run.png")
    t = np.linspace(0.0, 10.0, 50)
    outlines = [Outline("wall", "polygon", points=((2.9, -2), (3.1, -2), (3.1, 2), (2.9, 2))),
                Outline("post", "circle", (0.0, 3.0), 0.25)]
    beams = picture.beam_segments((0.0, 0.0), 0.0, -1.0, 0.5, [2.9, 3.0, np.inf, 3.5, 4.0])
    picture.draw(path, outlines, t, 0.2 * t, np.zeros_like(t), np.zeros_like(t), beams=beams,
                 collisions=[(1.0, 0.0)], title="fixture")
    with open(path, "rb") as png:
        head = png.read(32)
    assert head[:8] == b"\x89PNG\r\n\x1a\n"
    width, height = int.from_bytes(head[16:20], "big"), int.from_bytes(head[20:24], "big")
    assert width > 500 and height > 500


def test_draw_copes_with_an_empty_run(tmp_path):
    path = str(tmp_path / "empty.png")
    picture.draw(path, [], [], [], [], [])
    assert (tmp_path / "empty.png").stat().st_size > 0
