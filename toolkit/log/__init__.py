"""The sgtool log contract: MCAP files with Foxglove protobuf sensor channels and sgtool
JSON record channels (see :mod:`sgtool.log.schemas`)."""

from sgtool.log.frame import CameraIntrinsics, Frame
from sgtool.log.reader import ChannelInfo, Decoded, LogReader
from sgtool.log.schemas import LOG_SCHEMA_VERSION
from sgtool.log.writer import LogWriter

__all__ = [
    "LOG_SCHEMA_VERSION",
    "CameraIntrinsics",
    "ChannelInfo",
    "Decoded",
    "Frame",
    "LogReader",
    "LogWriter",
]
