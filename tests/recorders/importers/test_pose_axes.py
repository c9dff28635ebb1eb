"""The pose conventions' math and the advice text (sgtool.recorders.importers.pose_axes):
reading a pose written in any convention and writing it back gives it again, and the
advice names the flags to give relative to those given."""

from __future__ import annotations

import numpy as np
import pytest

from sgtool.recorders.importers.pose_axes import (
    CAMERA_AXES,
    ReadAs,
    from_optical,
    to_optical,
)

POSE = np.array([[0.0, -1.0, 0.0, 1.5], [1.0, 0.0, 0.0, -0.5], [0.0, 0.0, 1.0, 1.2],
                 [0.0, 0.0, 0.0, 1.0]])


@pytest.mark.parametrize("axes", list(CAMERA_AXES))
@pytest.mark.parametrize("inverse", [False, True])
def test_reading_undone_gives_the_pose_as_written(axes: str, inverse: bool) -> None:
    written = from_optical(POSE, axes, inverse)
    assert np.allclose(to_optical(written, axes, inverse), POSE)
    assert inverse or axes != "optical" or np.array_equal(written, POSE)


def test_the_optical_camera_axes_are_those_of_the_optical_frame() -> None:
    """An OpenGL camera looks along its -z: the optical frame's z (forward) in the world
    is the OpenGL pose's -z column; ROS's camera_link looks along its x."""
    assert np.allclose(to_optical(POSE, "opengl")[:3, 2], -POSE[:3, 2])
    assert np.allclose(to_optical(POSE, "body")[:3, 2], POSE[:3, 0])


def test_the_advice_names_flags_relative_to_those_given() -> None:
    assert ReadAs().fix("opengl", False) == "give --camera-axes opengl to read them so"
    assert ReadAs().fix("optical", True) == "give --world-to-camera to invert them"
    assert ReadAs("opengl").fix("optical", False) == (
        "read them with neither --camera-axes nor --world-to-camera instead of "
        "--camera-axes opengl")
    assert ReadAs("body", True).fix("opengl", True) == (
        "read them with --camera-axes opengl --world-to-camera instead of --camera-axes "
        "body --world-to-camera")
    assert ReadAs(bag=True).fix("optical", True) == "invert them"
    assert ReadAs(bag=True).fix("body", True) == \
        "invert them and read them with --camera-axes body"
    assert ReadAs("body", bag=True).fix("optical", True) == \
        "invert them and read them with --camera-axes optical"
