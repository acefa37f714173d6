"""Recording a run (``cbrs run --record``, ``sim.recording``): size, rate, captions, the path map,
the formats, and the exit codes of runs that fail."""

from __future__ import annotations

import itertools
import json
import subprocess
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from click.testing import CliRunner
from PIL import Image, ImageSequence

import cbrs.cli_actions
from cbrs.cli import cli
from cbrs.sim import recording
from cbrs.sim.recording import (
    CAPTION_HEIGHT,
    FRAME_INTERVAL,
    PATH_MAP_SIZE,
    Recorder,
    RecordingError,
    check_target,
    find_ffmpeg,
    path_map_name,
)
from cbrs.sim.world import HomeWorld, open_world

SERVE = "RobotArmServeACup"
FIND_CUP = "svc:FindCupOnTable_CytonDualArm01"  # the first step; nothing stands in for it


@dataclass(frozen=True)
class Event:
    topic: str
    message: dict[str, Any]


def progress(kind: str, step: int, component: str, **extra: Any) -> Event:
    message = {"event": kind, "task": "req:Demo", "step": step, "component": "svc:" + component, **extra}
    return Event("/cbrs/task_progress", message)


def frames_of(gif: Path) -> list[np.ndarray]:
    with Image.open(gif) as image:
        return [np.asarray(frame.convert("RGB")) for frame in ImageSequence.Iterator(image)]


def durations_of(gif: Path) -> list[int]:
    """Milliseconds each frame of a GIF is shown."""
    with Image.open(gif) as image:
        return [int(frame.info["duration"]) for frame in ImageSequence.Iterator(image)]


# -- a whole recorded run through the CLI ------------------------------------------------------------


@dataclass(frozen=True)
class Recorded:
    gif: Path
    found: dict[str, Any]
    output: str


@pytest.fixture(scope="module")
def served(tmp_path_factory: pytest.TempPathFactory) -> Recorded:
    gif = tmp_path_factory.mktemp("record") / "serve.gif"
    done = CliRunner().invoke(cli, ["--store", ":memory:", "run", SERVE, "--json", "--record", str(gif)])
    assert done.exit_code == 0, done.output
    return Recorded(gif, json.loads(done.output), done.output)


def test_the_gif_is_at_least_640x480_with_a_frame_every_half_simulated_second(served: Recorded) -> None:
    assert served.gif.read_bytes()[:6] in (b"GIF87a", b"GIF89a")
    with Image.open(served.gif) as image:
        assert image.size[0] >= 640 and image.size[1] >= 480
    shown = durations_of(served.gif)
    frames = len(shown)
    sim_seconds = served.found["sim_seconds"]
    assert sim_seconds > 10
    assert frames >= sim_seconds / FRAME_INTERVAL
    # Played at a steady rate: twice real time, each frame held at least until the next is due.
    assert sum(shown) / 1000 >= (sim_seconds - 0.5) / recording.PLAYBACK_SPEED
    assert shown[-1] >= 1000 * recording.LAST_HOLD


def test_each_frame_is_captioned_with_the_step_and_the_captions_change(served: Recorded) -> None:
    frames = frames_of(served.gif)
    bands = [frame[:CAPTION_HEIGHT] for frame in frames]
    views = [frame[CAPTION_HEIGHT:] for frame in frames]
    # The band holds text: light pixels on the dark background, on every frame.
    assert all((band > 150).any(axis=2).sum() > 200 for band in bands)
    distinct = {band.tobytes() for band in bands}
    assert len(distinct) == len(bands)  # every frame says its own time, and the step changes
    assert not np.array_equal(views[0], views[len(views) // 2])  # the arms moved
    # The band's status colour: amber while a step runs, green at the end.
    last = bands[-1].reshape(-1, 3).astype(int)
    assert ((last[:, 1] > 180) & (last[:, 0] < 150) & (last[:, 2] < 150)).sum() > 20


def test_the_path_map_is_written_beside_the_recording(served: Recorded) -> None:
    path = served.gif.with_name("serve-path.png")
    assert path.is_file()
    with Image.open(path) as image:
        assert image.size == PATH_MAP_SIZE
        pixels = np.asarray(image.convert("RGB"))
    assert len(np.unique(pixels.reshape(-1, 3), axis=0)) > 50
    dark = (pixels.sum(axis=2) < 200).mean()  # the walls
    assert 0.01 < dark < 0.3
    red = (pixels[:, :, 0] > 180) & (pixels[:, :, 1] < 60) & (pixels[:, :, 2] < 60)  # the cup's start, end and move
    assert red.sum() > 100


# -- the recorder on a world driven directly ----------------------------------------------------------


@pytest.fixture
def world() -> Iterator[HomeWorld]:
    with open_world(seed=0) as built:
        yield built


def test_frames_come_inside_long_steps_and_captions_follow_the_events(world: HomeWorld, tmp_path: Path) -> None:
    with Recorder(world, title="req:Demo") as recorder:
        recorder.on_event(progress("step_started", 1, "Wait_Somebody"))
        world.step(2.2)  # one call, as a skill makes: the frames must come from inside it
        recorder.on_event(progress("step_succeeded", 1, "Wait_Somebody"))
        recorder.on_event(progress("step_started", 2, "Drive_P3DX01"))
        start = world.base_pose()
        assert world.base.follow([(start.x + 0.6, start.y)]).succeeded
        recorder.on_event(progress("step_failed", 2, "Drive_P3DX01", reason="x", failover="svc:Drive_P3DX02"))
        recorder.on_event(Event("/cbrs/task", {"task": "req:Demo", "status": "failed", "reason": "no luck"}))
    times = recorder.times
    assert times[0] == pytest.approx(0.3) and times == sorted(times)
    assert max(b - a for a, b in itertools.pairwise(times)) <= FRAME_INTERVAL + 1e-9
    assert sum(1 for t in times if 0.3 < t < 2.5) >= 4
    assert recorder.captions[0] == "Demo: starting"
    assert "step 1 Wait_Somebody: running" in recorder.captions
    assert "step 1 Wait_Somebody: succeeded" in recorder.captions
    assert "step 2 Drive_P3DX01: running" in recorder.captions
    assert "step 2 Drive_P3DX01: failed (failing over to Drive_P3DX02)" in recorder.captions
    assert recorder.captions[-1] == "Demo: task failed (no luck)"
    assert all(frame.size == (640, 480) for frame in recorder.frames)
    base = recorder.track["P3DX01"]
    assert base[-1][1] - base[0][1] == pytest.approx(0.6, abs=0.1)
    durations = recorder.durations()
    assert durations[-1] == recording.LAST_HOLD and min(durations) >= recording.CAPTION_HOLD / 10
    saved = recorder.save(tmp_path / "demo.gif")
    assert saved.frames == len(times) and saved.path_map == tmp_path / "demo-path.png"
    assert saved.path_map.is_file()


def test_recording_does_not_change_the_run(tmp_path: Path) -> None:
    def drive(record: bool) -> dict[str, Any]:
        with open_world(seed=2) as built:
            recorder = Recorder(built)
            if record:
                recorder.start()
            built.step(0.37)
            start = built.base_pose()
            built.base.follow([(start.x + 0.4, start.y + 0.2)])
            built.step(0.01)
            recorder.stop()
            assert built.step.__func__ is HomeWorld.step  # type: ignore[attr-defined]
            return {"time": built.time, "steps": built.steps, "poses": built.snapshot()}

    assert drive(True) == drive(False)


def test_unknown_suffix_and_missing_video_writer_are_usage_errors(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path
) -> None:
    runner = CliRunner()
    bad = runner.invoke(cli, ["--store", ":memory:", "run", SERVE, "--record", str(tmp_path / "run.avi")])
    assert bad.exit_code == 2
    assert "'run.avi' must end in .gif, .mp4 or .webm" in bad.output and "--record" in bad.output
    monkeypatch.setattr(recording, "find_ffmpeg", lambda: None)
    for suffix in (".mp4", ".webm"):
        bad = runner.invoke(cli, ["--store", ":memory:", "run", SERVE, "--record", str(tmp_path / f"run{suffix}")])
        assert bad.exit_code == 2, bad.output
        assert f"writing {suffix} needs ffmpeg" in bad.output and "pip install '.[video]'" in bad.output
    assert not list(tmp_path.iterdir())  # refused before anything ran or was written
    with pytest.raises(RecordingError, match="must end in"):
        check_target(Path("x.png"))
    check_target(Path("x.GIF"))
    assert path_map_name(Path("out/run.gif")) == Path("out/run-path.png")


@pytest.fixture(scope="module")
def demo() -> Recorder:
    """A second of the home recorded once; each video test writes it in its own format."""
    with open_world(seed=0) as built, Recorder(built, title="Demo") as recorder:
        recorder.on_event(progress("step_started", 1, "Wait_Somebody"))
        built.step(1.0)
        recorder.on_event(progress("step_succeeded", 1, "Wait_Somebody"))
    return recorder


@pytest.mark.skipif(find_ffmpeg() is None, reason="no ffmpeg: pip install '.[video]' to test video recordings")
@pytest.mark.parametrize("suffix", [".mp4", ".webm"])
def test_videos_are_written_with_ffmpeg(demo: Recorder, tmp_path: Path, suffix: str) -> None:
    target = tmp_path / f"demo{suffix}"
    demo.save(target)
    ffmpeg = find_ffmpeg()
    assert ffmpeg is not None
    first = subprocess.run(
        [ffmpeg, "-v", "error", "-i", str(target), "-frames:v", "1", "-f", "image2pipe", "-c:v", "png", "-"],
        capture_output=True,
        check=True,
    ).stdout
    png = tmp_path / "first.png"
    png.write_bytes(first)
    with Image.open(png) as image:
        assert image.size == (640, 480)
    counted = subprocess.run(
        [ffmpeg, "-v", "error", "-i", str(target), "-map", "0:v:0", "-f", "null", "-", "-stats"],
        capture_output=True,
        text=True,
        check=True,
    )
    assert "frame=" in counted.stderr
    assert (tmp_path / "demo-path.png").is_file()


# -- exit codes --------------------------------------------------------------------------------------


def test_a_failed_run_exits_1_and_still_leaves_its_recording(tmp_path: Path) -> None:
    gif = tmp_path / "failed.gif"
    done = CliRunner().invoke(cli, ["--store", ":memory:", "run", SERVE, "--fail", FIND_CUP, "--record", str(gif)])
    assert done.exit_code == 1, done.output
    assert "RobotArmServeACup: failed" in done.output and f"recording written to {gif}" in done.output
    bands = [frame[:CAPTION_HEIGHT].reshape(-1, 3).astype(int) for frame in frames_of(gif)]
    red = [((b[:, 0] > 200) & (b[:, 1] < 140) & (b[:, 2] < 140)).sum() for b in bands]
    assert red[-1] > 20  # the verdict is written in red


def test_demo_exits_1_when_a_scenario_fails(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(cbrs.cli_actions, "DEMO_RUNS", ((SERVE, (FIND_CUP,)),))
    done = CliRunner().invoke(cli, ["--store", ":memory:", "demo"])
    assert done.exit_code == 1, done.output
    assert f"{SERVE} (fail {FIND_CUP})" in done.output and "1 of 1 runs did not succeed." in done.output
    assert "The world graph after the last run" in done.output  # the whole tour is printed first
