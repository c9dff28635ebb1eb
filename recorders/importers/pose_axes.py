"""The conventions a recording's camera poses come in, turned into sgtool's: the pose of
the camera's optical frame (x right, y down, z forward) in the world, camera-to-world.

Datasets write the camera's pose in the axes of other frames (OpenGL's, which NeRF and
Blender exports use; ROS's ``camera_link`` body frame) and some write the inverse
(world-to-camera extrinsics). ``sgtool import rgbd --camera-axes/--world-to-camera`` and
``sgtool import bag --camera-axes`` name the convention; :func:`to_optical` turns a pose
of it into sgtool's, and the importers' pose checks (:mod:`.scale_check`) name the flag
whose convention fits the depth when the poses as read do not.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from sgtool.errors import SgtoolError

# the optical frame (z forward, x right, y down) in a camera's body frame (ROS's
# camera_link: x forward, y left, z up)
BODY_T_OPTICAL = np.array([[0.0, 0.0, 1.0, 0.0], [-1.0, 0.0, 0.0, 0.0],
                           [0.0, -1.0, 0.0, 0.0], [0.0, 0.0, 0.0, 1.0]])
# the optical frame in OpenGL's camera frame (x right, y up, looking along -z)
OPENGL_T_OPTICAL = np.diag([1.0, -1.0, -1.0, 1.0])

# the axes a pose may be given in: the optical frame in them, and how they are described
CAMERA_AXES: dict[str, tuple[np.ndarray, str]] = {
    "optical": (np.eye(4), "x right, y down, z forward: OpenCV's, ROS's *_optical_frame"),
    "opengl": (OPENGL_T_OPTICAL, "x right, y up, z backward: OpenGL's, NeRF's, Blender's"),
    "body": (BODY_T_OPTICAL, "x forward, y left, z up: ROS's camera_link"),
}


def check_camera_axes(axes: str) -> None:
    """One line for a name not in :data:`CAMERA_AXES`."""
    if axes not in CAMERA_AXES:
        raise SgtoolError(f"--camera-axes {axes!r}: one of {', '.join(CAMERA_AXES)}")


def to_optical(pose: np.ndarray, axes: str = "optical",
               world_to_camera: bool = False) -> np.ndarray:
    """``pose`` (4x4) of the camera frame with ``axes``, camera-to-world unless
    ``world_to_camera``, as the camera-to-world pose of its optical frame."""
    p = np.asarray(pose, float)
    if world_to_camera:
        p = np.linalg.inv(p)
    return p if axes == "optical" else p @ CAMERA_AXES[axes][0]


def from_optical(pose: np.ndarray, axes: str = "optical",
                 world_to_camera: bool = False) -> np.ndarray:
    """:func:`to_optical` undone: the pose as a file in that convention writes it."""
    p = np.asarray(pose, float)
    if axes != "optical":
        p = p @ np.linalg.inv(CAMERA_AXES[axes][0])
    return np.linalg.inv(p) if world_to_camera else p


def convention_flags(axes: str, world_to_camera: bool) -> list[str]:
    """The flags of ``import rgbd`` that read poses of that convention."""
    return [f"--camera-axes {axes}"] * (axes != "optical") + \
        ["--world-to-camera"] * world_to_camera


def convention_text(axes: str, world_to_camera: bool) -> str:
    """How the poses were read, for notes: "" for sgtool's own convention."""
    parts = ([f"camera axes {axes} ({CAMERA_AXES[axes][1]})"] if axes != "optical" else []) \
        + (["inverted (world-to-camera)"] if world_to_camera else [])
    return ", ".join(parts)


@dataclass(frozen=True)
class ReadAs:
    """How an import read its poses (``--camera-axes``, ``--world-to-camera``; ``bag``:
    ``import bag``'s, which has no ``--world-to-camera``): the pose checks' advice is
    the flags that read them otherwise."""

    axes: str = "optical"
    inverse: bool = False
    bag: bool = False

    def fix(self, axes: str, inverse: bool) -> str:
        """The advice that reads the poses with ``axes``, inverted when ``inverse``."""
        if inverse != self.inverse and self.bag:  # no flag inverts a bag's transforms
            return "invert them" + (f" and read them with --camera-axes {axes}"
                                    if axes != self.axes else "")
        want = " ".join(convention_flags(axes, inverse))
        if (self.axes, self.inverse) == ("optical", False):
            return f"give {want} to " + ("invert them" if axes == "optical" else "read them so")
        return (f"read them with {want or 'neither --camera-axes nor --world-to-camera'} "
                f"instead of {' '.join(convention_flags(self.axes, self.inverse))}")


OPTICAL_C2W = ReadAs()  # sgtool's own convention, as a folder's import reads by default
