"""Shared helpers for the semantics, planning and LLM tests (imported, not a conftest).

- :func:`encoder`: one SentenceEncoder per test session, caching into a session temp dir
  (the user's cache is never touched by tests);
- :func:`house`: a small hand-made scene graph whose right answers a person can check;
- :class:`TableScorer`: a relation scorer from explicit tables, so planner logic is tested
  without learned weights.
"""

from __future__ import annotations

import functools
import os
import tempfile
from collections.abc import Sequence

import numpy as np

from sgtool.scenegraph.graph import (
    DoorNode,
    ObjectNode,
    RegionNode,
    RobotState,
    RoomNode,
    SceneGraph,
)

# Every encoder created in a test session (also the process-wide default one) caches into
# this folder, never into the user's ~/.cache/sgtool.
if "SGTOOL_TEST_CACHE" not in os.environ:
    os.environ["SGTOOL_TEST_CACHE"] = tempfile.mkdtemp(prefix="sgtool-test-cache-")
os.environ["SGTOOL_CACHE"] = os.environ["SGTOOL_TEST_CACHE"]


@functools.lru_cache(maxsize=1)
def encoder():
    """The process-wide default encoder (so planners built without one share it)."""
    from sgtool.semantics.encoder import default_encoder

    return default_encoder()


class TableScorer:
    """rooms/objects score tables keyed by category name; anything else scores ``default``."""

    name = "table"

    def __init__(self, rooms: dict[str, float], objects: dict[str, float],
                 default: float = 0.0) -> None:
        self.room_table = rooms
        self.object_table = objects
        self.default = default
        self.calls = 0

    def rooms(self, names: Sequence[str], query: str) -> np.ndarray:
        self.calls += 1
        return np.array([self.room_table.get(n, self.default) for n in names], dtype=float)

    def objects(self, names: Sequence[str], query: str) -> np.ndarray:
        self.calls += 1
        return np.array([self.object_table.get(n, self.default) for n in names], dtype=float)


def house(extra_objects: Sequence[ObjectNode] = (), robot_room: str = "room:1",
          distances: dict[str, float] | None = None) -> SceneGraph:
    """Kitchen (room:1), bathroom (room:2), living room (room:3), an unexplored room (room:4)
    behind a closed door, a hallway frontier leading out.

    Layout along x: kitchen around x=0, bathroom x=6, living room x=12, room:4 at x=18.
    The robot stands in the kitchen at (0, 0).
    """
    rooms = (
        RoomNode("room:1", "kitchen", (0.0, 0.0), True, neighbours=("room:2",)),
        RoomNode("room:2", "bathroom", (6.0, 0.0), True, neighbours=("room:1", "room:3")),
        RoomNode("room:3", "living_room", (12.0, 0.0), True, neighbours=("room:2", "room:4")),
        RoomNode("room:4", "unknown", (18.0, 0.0), False),
    )
    regions = (
        RegionNode("region:1.1", "room:1", (0.0, 0.0)),
        RegionNode("region:2.1", "room:2", (6.0, 0.0)),
        RegionNode("region:3.1", "room:3", (12.0, 0.0)),
        RegionNode("frontier:1", "room:1", (1.0, 3.0), "frontier", "unexplored area", 1.0),
        RegionNode("frontier:2", "room:3", (12.0, 5.0), "frontier", "leading out", 2.0),
    )
    objects = (
        ObjectNode("obj:10", "fridge", "region:1.1", "room:1", (1.0, -1.0, 0.0),
                   state="closed", affordances=("open",)),
        ObjectNode("obj:11", "bottom_cabinet", "region:1.1", "room:1", (-1.0, -1.0, 0.0),
                   state="closed", affordances=("open",)),
        ObjectNode("obj:12", "countertop", "region:1.1", "room:1", (0.0, 1.0, 0.0),
                   affordances=("explore",)),
        ObjectNode("obj:13", "chair", "region:1.1", "room:1", (0.5, 0.5, 0.0)),
        ObjectNode("obj:14", "chair", "region:1.1", "room:1", (0.7, 0.5, 0.0)),
        ObjectNode("obj:20", "sink", "region:2.1", "room:2", (6.0, 1.0, 0.0),
                   affordances=("explore",)),
        ObjectNode("obj:21", "bottom_cabinet", "region:2.1", "room:2", (6.5, -1.0, 0.0),
                   state="closed", affordances=("open",)),
        ObjectNode("obj:30", "sofa", "region:3.1", "room:3", (12.0, 1.0, 0.0),
                   affordances=("explore",)),
        ObjectNode("obj:31", "coffee_table", "region:3.1", "room:3", (12.5, 0.0, 0.0),
                   affordances=("explore",)),
        *extra_objects,
    )
    doors = (DoorNode("door:1", (15.0, 0.0), "closed", ("room:3", "room:4")),)
    if distances is None:
        distances = {}
        for group in (rooms, regions, objects, doors):
            for n in group:
                distances[n.id] = float(abs(n.position[0]) + abs(n.position[1]))
    return SceneGraph(
        robot=RobotState((0.0, 0.0), 0.0, robot_room, "region:1.1"),
        rooms=rooms, regions=regions, objects=objects, doors=doors, distances=distances,
    )


class ChatServer:
    """A chat-completions endpoint on 127.0.0.1 that plays back a script.

    Each request consumes the next script item:
    ``{"text": str}`` a normal answer; ``{"status": int}`` an HTTP error (its body's
    ``type`` and ``message`` given by the item's, when it has them);
    ``{"sleep": s, "text": str}`` an answer after ``s`` seconds (for timeouts);
    ``{"raw": bytes}`` a 200 response with this body (malformed JSON);
    ``{"drop": True}`` the connection closed without a response.
    When the script is exhausted, ``responder(request) -> item`` answers if given, else
    the server answers HTTP 500. Requests are kept in :attr:`requests` (decoded JSON).
    """

    def __init__(self, script: list[dict] | None = None, model: str = "scripted-model",
                 responder=None) -> None:
        import json
        import threading
        import time
        from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer

        self.script = list(script or [])
        self.requests: list[dict] = []
        self.auth: list[str] = []  # each request's Authorization header
        self.model = model
        self.responder = responder
        self.errors: list[str] = []
        server = self

        class Handler(BaseHTTPRequestHandler):
            def log_message(self, *args: object) -> None:  # keep test output clean
                pass

            def _send(self, status: int, body: bytes) -> None:
                try:
                    self.send_response(status)
                    self.send_header("Content-Type", "application/json")
                    self.send_header("Content-Length", str(len(body)))
                    self.end_headers()
                    self.wfile.write(body)
                except (BrokenPipeError, ConnectionResetError):
                    pass  # the client gave up (timeout test)

            def do_POST(self) -> None:  # noqa: N802
                n = int(self.headers.get("Content-Length", "0"))
                req = json.loads(self.rfile.read(n) or b"{}")
                server.requests.append(req)
                server.auth.append(self.headers.get("Authorization", ""))
                if server.script:
                    item = server.script.pop(0)
                elif server.responder is not None:
                    try:
                        item = server.responder(req)
                    except Exception as e:  # a bug in a test responder: say so, loudly
                        server.errors.append(repr(e))
                        item = {"status": 599}
                else:
                    item = {"status": 500}
                if item.get("drop"):
                    self.close_connection = True
                    return
                if "sleep" in item:
                    time.sleep(item["sleep"])
                if "status" in item:
                    err = {"error": {"message": item.get("message", "scripted failure"),
                                     "type": item.get("type", "server_error")}}
                    self._send(int(item["status"]), json.dumps(err).encode())
                    return
                if "raw" in item:
                    self._send(200, item["raw"])
                    return
                text = item["text"]
                body = {
                    "id": f"chatcmpl-{len(server.requests)}",
                    "object": "chat.completion",
                    "created": 0,
                    "model": server.model,
                    "choices": [{"index": 0, "finish_reason": "stop",
                                 "message": {"role": "assistant", "content": text}}],
                    "usage": {"prompt_tokens": 100 + len(server.requests),
                              "completion_tokens": len(text.split()),
                              "total_tokens": 100 + len(server.requests) + len(text.split())},
                }
                self._send(200, json.dumps(body).encode())

        self.httpd = ThreadingHTTPServer(("127.0.0.1", 0), Handler)
        self.httpd.daemon_threads = True
        self.thread = threading.Thread(target=self.httpd.serve_forever, args=(0.02,),
                                       daemon=True)
        self.thread.start()

    @property
    def base_url(self) -> str:
        host, port = self.httpd.server_address[:2]
        return f"http://{host}:{port}/v1"

    def close(self) -> None:
        self.httpd.shutdown()
        self.httpd.server_close()

    def __enter__(self) -> ChatServer:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def answer(command: str, analysis: str = "Looking around.",
           reasoning: str = "Closest lead.") -> dict:
    """A well-formed MoMa-LLM answer as a script item."""
    return {"text": f"Analysis: {analysis}\nReasoning: {reasoning}\nCommand: {command}"}
