"""Live Rerun: ``--rerun`` parsing and its one-line refusals, and ``sgtool replay LOG
--rerun serve`` serving a web viewer over HTTP while it runs (and until Ctrl-C)."""

from __future__ import annotations

import os
import signal
import socket
import subprocess
import sys
import time
import urllib.request
from pathlib import Path

import pytest
from click.testing import CliRunner
from support.paths import GOLDEN

from sgtool.analysis.rerun_live import DEFAULT_CONNECT, LiveTarget, parse_target, viewer_address
from sgtool.cli import cli
from sgtool.errors import SgtoolError


def test_parse_target():
    assert parse_target("spawn") == LiveTarget("spawn")
    assert parse_target("connect") == LiveTarget("connect", url=DEFAULT_CONNECT)
    url = "rerun+http://10.0.0.2:9876/proxy"
    assert parse_target(f"connect:{url}") == parse_target(url) == LiveTarget("connect", url=url)
    assert parse_target("serve") == LiveTarget("serve")
    assert parse_target("serve:8000:8001") == LiveTarget("serve", web_port=8000,
                                                         grpc_port=8001)
    for bad in ("show", "serve:http", "serve:70000", "spawn:now"):
        with pytest.raises(SgtoolError, match="--rerun"):
            parse_target(bad)
    assert viewer_address(url) == ("10.0.0.2", 9876)
    assert viewer_address("rerun+http://example.org/proxy") == ("example.org", 9876)


def test_headless_view_names_serve(tmp_path, monkeypatch):
    from support.logfixtures import write_log

    monkeypatch.delenv("DISPLAY", raising=False)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    log = write_log(tmp_path / "run.mcap", n=2)
    r = CliRunner().invoke(cli, ["view", str(log)])
    assert r.exit_code == 2 and "--rerun serve" in r.output
    r = CliRunner().invoke(cli, ["view", str(log), "--rerun", "spawn"])
    assert r.exit_code == 2 and "--rerun serve" in r.output


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


@pytest.mark.parametrize("command", [["view", "{log}"], ["replay", "{log}"],
                                     ["record", "-o", "{out}", "--frames", "5"]])
def test_connect_without_a_viewer_is_refused_before_any_work(tmp_path, command):
    """No viewer on the port: one line and exit 2 before the work starts (no traceback
    after it, no recording left waiting for a viewer), and no output file."""
    from support.logfixtures import write_log

    log = write_log(tmp_path / "run.mcap", n=2)
    url = f"rerun+http://127.0.0.1:{free_port()}/proxy"
    args = [a.format(log=log, out=tmp_path / "rec.mcap") for a in command]
    r = CliRunner().invoke(cli, [*args, "--rerun", f"connect:{url}"])
    assert r.exit_code == 2, r.output
    assert f"no Rerun viewer answers at {url}" in r.output and "Traceback" not in r.output
    assert not (tmp_path / "rec.mcap").exists()


def test_replay_serves_a_web_viewer_while_it_runs(tmp_path):
    web, grpc = free_port(), free_port()
    exe = Path(sys.executable).parent / "sgtool"
    env = {**os.environ, "HF_HUB_OFFLINE": "1", "MPLBACKEND": "Agg"}
    proc = subprocess.Popen(
        [str(exe), "replay", str(GOLDEN / "house10-start.mcap"), "--max-frames", "30",
         "--no-progress", "--rerun", f"serve:{web}:{grpc}"],
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env,
        # Ctrl-C as a terminal delivers it, whatever this process's handler (an ignored
        # signal stays ignored across exec)
        preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    try:
        status, deadline = None, time.monotonic() + 120  # a bound on waiting, not a check
        while status is None and time.monotonic() < deadline and proc.poll() is None:
            try:
                with urllib.request.urlopen(f"http://127.0.0.1:{web}/", timeout=5) as resp:
                    status, page = resp.status, resp.read()
            except OSError:
                time.sleep(0.5)
        assert status == 200 and page, proc.stderr.read() if proc.poll() is not None else ""
        proc.send_signal(signal.SIGINT)  # the served recording lives until Ctrl-C
        out, err = proc.communicate(timeout=120)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.communicate()
    assert f"web viewer at http://localhost:{web}/" in err
    assert proc.returncode in (0, 130), err


def test_live_replay_logs_refreshes_and_decisions_in_strict_mode():
    """Every archetype LiveReplay logs for a refresh and a decision is valid (strict mode
    raises on bad input), into a memory recording."""
    import rerun as rr

    from sgtool.analysis.rerun_live import LiveReplay
    from sgtool.planning.base import Action
    from sgtool.replayers.derived_log import ReplayOptions, replay

    rr.set_strict_mode(True)
    try:
        rec = rr.RecordingStream("test")
        rec.memory_recording()
        live = LiveReplay(rec)
        graphs = []

        def both(ref, stream):
            live.refresh(ref, stream)
            graphs.append(ref.graph)

        replay(GOLDEN / "house10-start.mcap", None, ReplayOptions(max_frames=30),
               on_refresh=both)
        live.decision(graphs[-1], Action("navigate", "room:0", reason="closest"))
        live.close()
    finally:
        rr.set_strict_mode(False)
    assert live.refreshes == len(graphs) + 1 >= 3


def test_live_frames_of_a_recording_in_strict_mode(tmp_path):
    """record --rerun: the observer shows every frame the recorder wrote, once, with valid
    archetypes (strict mode), and labels the segmentation by the instance table (the
    camera's annotation context, as `sgtool view` gives it)."""
    import rerun as rr
    from support.small_house import small_house

    from sgtool.analysis.rerun_live import LiveReplay
    from sgtool.recorders.sim import CameraConfig, RecordOptions, record_house

    shown = []
    rr.set_strict_mode(True)
    try:
        rec = rr.RecordingStream("test")
        rec.save(str(tmp_path / "live.rrd"))
        live = LiveReplay(rec)
        frame = live.frame

        def count(fr, instances=None):
            shown.append(fr.index)
            assert instances is not None and len(instances.instances) > 0
            frame(fr, instances)

        live.frame = count  # type: ignore[method-assign]
        rep = record_house(small_house(), tmp_path / "rec.mcap", RecordOptions(
            camera=CameraConfig(width=80, height=60), frames=12), observers=[live.observer()])
        live.close()
        rec.disconnect()
    finally:
        rr.set_strict_mode(False)
    assert len(shown) == rep.frames == 12 and shown == sorted(set(shown))
    assert len(live.path.points) == 12
    import rerun.chunk as chunk

    labelled = [ch for ch in chunk.RrdReader(tmp_path / "live.rrd").stream()
                if ch.is_static and ch.entity_path == "/world/camera/image"
                and any("AnnotationContext" in str(c) for c in ch.to_record_batch().schema.names)]
    assert labelled


def test_a_stream_that_cannot_finish_is_one_line():
    """The final flush waits at most FLUSH_S and any error of Rerun's (a lost viewer, the
    timeout) is one line naming the viewer, not a traceback."""
    from sgtool.analysis.rerun_live import FLUSH_S, LiveReplay

    class Stuck:
        waited: float | None = None

        def log(self, *a, **k) -> None:
            pass

        def flush(self, timeout_sec: float) -> None:
            Stuck.waited = timeout_sec
            raise TimeoutError("flush timed out\nmore detail")

    live = LiveReplay(Stuck(), LiveTarget("connect", url="rerun+http://10.0.0.9:9876/proxy"))
    with pytest.raises(SgtoolError) as e:
        live.finish(print)
    assert Stuck.waited == FLUSH_S
    assert str(e.value) == ("--rerun: the stream to rerun+http://10.0.0.9:9876/proxy did not "
                            f"finish within {FLUSH_S:g} s or lost its viewer (flush timed out)")


def _times(rrd: Path, entity: str) -> list[tuple[int, int]]:
    """(frame, sim_time in ns) of every row of ``entity`` in an .rrd file."""
    import rerun.chunk as chunk

    got = []
    for ch in chunk.RrdReader(rrd).stream():
        if ch.is_static or ch.entity_path != entity:
            continue
        batch = ch.to_record_batch()
        frames = batch.column("frame").to_pylist()
        times = batch.column("sim_time").cast("int64").to_pylist()  # ns
        got += list(zip(frames, times, strict=True))
    return sorted(got)


def test_a_live_replay_shares_the_timelines_of_view(tmp_path):
    """replay --rerun shares the recording id of `sgtool view` of the same log, so its
    refreshes sit at the frame and time `view` shows them at: the maps of both on the same
    (frame, sim_time) pairs, not one on refresh counts or absolute time."""
    from sgtool.analysis.rerun_live import LiveReplay, log_clock
    from sgtool.analysis.rerun_view import new_stream, recording_id
    from sgtool.analysis.view_run import write_rerun
    from sgtool.replayers.derived_log import ReplayOptions, replay

    log = GOLDEN / "house10-start.mcap"
    derived = tmp_path / "derived.mcap"
    replay(log, derived, ReplayOptions(max_frames=30))
    write_rerun(derived, tmp_path / "view.rrd", voxels=False)
    rec = new_stream(recording_id(log))
    rec.save(str(tmp_path / "live.rrd"))
    live = LiveReplay(rec, None, *log_clock(log))
    replay(log, None, ReplayOptions(max_frames=30), on_refresh=live.refresh)
    live.close()
    rec.disconnect()
    view = _times(tmp_path / "view.rrd", "/world/map/occupancy")
    assert len(view) >= 3 and view[0][0] > 0
    assert _times(tmp_path / "live.rrd", "/world/map/occupancy") == view


def test_two_live_recordings_to_one_output_never_share_an_id(tmp_path, monkeypatch):
    """record --rerun twice to one output (other options, --force): a viewer left open
    keeps them apart (the log's bytes do not exist while it is recorded, so the id cannot
    come from them; it came from the command's words, the same both times)."""
    import rerun as rr

    from sgtool.analysis import rerun_live

    ids = []

    def stream(target, recording_id):  # noqa: ANN001, ANN202
        ids.append(recording_id)
        rec = rr.RecordingStream("test", recording_id=recording_id)
        rec.save(str(tmp_path / f"live{len(ids)}.rrd"))
        return rec, None

    monkeypatch.setattr(rerun_live, "check_target", lambda target: None)
    monkeypatch.setattr(rerun_live, "open_stream", stream)
    url = f"rerun+http://127.0.0.1:{free_port()}/proxy"
    for size in ("32x24", "40x30"):
        r = CliRunner().invoke(cli, ["record", "--seed", "3", "--rooms", "4-4", "--frames", "3",
                                     "--resolution", size, "--quiet", "--force", "-o",
                                     str(tmp_path / "two.mcap"), "--rerun", f"connect:{url}"])
        assert r.exit_code == 0, r.output
    assert len(ids) == 2 and ids[0] != ids[1]
