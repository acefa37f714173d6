"""Recording a run for a person to watch: frames at a steady simulated rate, captioned with the plan
step in progress, saved as a GIF or a video, plus a top-down map of where everything went.

Skills step the physics themselves, many seconds inside one executor tick, so frames taken only on
the executor's events would skip whole drives. The recorder therefore sits on the world's stepping:
it splits every ``step(seconds)`` call into whole physics steps up to the next sample time, samples
the movable bodies every ``PATH_INTERVAL`` and renders a frame every ``FRAME_INTERVAL``. The number
of physics steps is exactly the one asked for, so a recorded run ends in the same state as an
unrecorded one. The world has no stepping hook, so ``start`` replaces ``world.step`` and the step
callables the base and the arms were given at construction; ``stop`` puts them back.

Only numpy, Pillow and pybullet are needed to record; matplotlib loads when the map is drawn and an
``ffmpeg`` executable (imageio-ffmpeg's, or one on PATH) when a video is written.
"""

from __future__ import annotations

import importlib
import itertools
import math
import shutil
import subprocess
from collections.abc import Callable, Collection, Mapping, Sequence
from dataclasses import dataclass, field
from functools import lru_cache
from pathlib import Path
from typing import Any, Protocol

import numpy as np
import pybullet as p
from numpy.typing import NDArray
from PIL import Image, ImageDraw, ImageFont

from cbrs.sim.cameras import render
from cbrs.sim.world import HomeWorld

__all__ = [
    "FORMATS",
    "FRAME_INTERVAL",
    "HEIGHT",
    "PATH_INTERVAL",
    "PLAYBACK_SPEED",
    "VIDEO_INSTALL",
    "WIDTH",
    "Caption",
    "Recorder",
    "Recording",
    "RecordingError",
    "check_target",
    "draw_path_map",
    "find_ffmpeg",
    "path_map_name",
]

WIDTH, HEIGHT = 640, 480
"""Size of every frame, caption band included."""
CAPTION_HEIGHT = 46
"""The band at the top of each frame that says which step is running; the view fills the rest."""
FRAME_INTERVAL = 0.5
"""Simulated seconds between frames (more frames come at the end of every step)."""
PATH_INTERVAL = 0.1
"""Simulated seconds between samples of the bodies' positions for the path map."""
PLAYBACK_SPEED = 2.0
"""Simulated seconds shown per second of playback: a 40 s run plays in about 20 s."""
CAPTION_HOLD = 0.5
"""A frame whose caption is new stays up at least this long (s), so steps that take no simulated
time (perception, planning) can still be read."""
LAST_HOLD = 2.0
"""The last frame, with the verdict, stays up this long (s)."""
VIDEO_FPS = 8
FORMATS = (".gif", ".mp4", ".webm")
VIDEO_INSTALL = (
    "pip install '.[video]' in the cbrs checkout (imageio-ffmpeg, which ships an ffmpeg binary) or put ffmpeg on PATH"
)
PATH_MAP_SIZE = (800, 720)
"""Pixels of the path map (width, height)."""

# The view: a free camera looking down from the south at PITCH degrees; it frames the table and the
# torso and widens (never narrows) to take in whatever has moved, so the action stays in the picture.
PITCH = -58.0
FOV = 50.0
PAD = 0.6
"""Metres of floor kept around what is framed."""
EASE = 0.5
"""Fraction of the way to the wanted framing the camera moves per frame: zooms out smoothly."""
MOVED = 0.05
"""A body counts as moved once it is this far (m) from where it was when recording started."""
PERSON_NEAR = 2.5
"""The person is framed once the base has driven this close to them (m): they are who it is going to."""
_STATUS_COLOURS = {
    "running": (255, 196, 70),
    "succeeded": (110, 220, 120),
    "failed": (255, 100, 90),
}
_BAND = (28, 30, 36)
_INK = (235, 235, 235)
_DIM = (170, 174, 184)


class RecordingError(Exception):
    """The recording cannot be written as asked: an unknown format or no video writer."""


class EventLike(Protocol):
    """What the recorder reads of an executor event (``actions.events.Event``)."""

    @property
    def topic(self) -> str: ...

    @property
    def message(self) -> dict[str, Any]: ...


# --- formats and writers ------------------------------------------------------------------------


@lru_cache(maxsize=1)
def find_ffmpeg() -> str | None:
    """The ffmpeg executable to write videos with: imageio-ffmpeg's bundled one, else one on PATH."""
    try:
        module = importlib.import_module("imageio_ffmpeg")
        exe = module.get_ffmpeg_exe()
        if exe:
            return str(exe)
    except (ImportError, RuntimeError, OSError):
        pass
    return shutil.which("ffmpeg")


@lru_cache(maxsize=4)
def _encoders(ffmpeg: str) -> frozenset[str]:
    try:
        listed = subprocess.run(
            [ffmpeg, "-hide_banner", "-encoders"], capture_output=True, text=True, timeout=30, check=False
        ).stdout
    except OSError:
        return frozenset()
    return frozenset(line.split()[1] for line in listed.splitlines() if len(line.split()) > 1)


_CODECS: dict[str, tuple[str, ...]] = {
    # Each format's encoders, best first, with their ffmpeg arguments; yuv420p is what players take.
    ".mp4": (
        "-c:v libx264 -preset veryfast -crf 23 -pix_fmt yuv420p -movflags +faststart",
        "-c:v mpeg4 -q:v 4 -pix_fmt yuv420p",
    ),
    ".webm": (
        "-c:v libvpx-vp9 -b:v 0 -crf 34 -deadline realtime -cpu-used 8 -pix_fmt yuv420p",
        "-c:v libvpx -b:v 1M -deadline realtime -cpu-used 8 -pix_fmt yuv420p",
    ),
}


def _codec(ffmpeg: str, suffix: str) -> list[str] | None:
    available = _encoders(ffmpeg)
    return next((args.split() for args in _CODECS[suffix] if args.split()[1] in available), None)


def check_target(target: Path) -> None:
    """Refuse, before anything runs, a file the recording cannot be written to."""
    suffix = target.suffix.lower()
    if suffix not in FORMATS:
        raise RecordingError(f"{target.name!r} must end in .gif, .mp4 or .webm")
    if suffix == ".gif":
        return
    ffmpeg = find_ffmpeg()
    if ffmpeg is None:
        raise RecordingError(f"writing {suffix} needs ffmpeg, which was not found: {VIDEO_INSTALL}; or record a .gif")
    if _codec(ffmpeg, suffix) is None:
        wanted = " or ".join(args.split()[1] for args in _CODECS[suffix])
        raise RecordingError(f"{ffmpeg} has no {wanted} encoder for {suffix}: {VIDEO_INSTALL}; or record a .gif")


def path_map_name(target: Path) -> Path:
    """Where the path map of a recording goes: ``run.gif`` -> ``run-path.png``."""
    return target.with_name(f"{target.stem}-path.png")


# --- captions -----------------------------------------------------------------------------------


def _local(iri: str) -> str:
    return iri.rsplit("#", 1)[-1].rsplit("/", 1)[-1].split(":")[-1]


@dataclass(frozen=True)
class Caption:
    """What the run is doing: the plan step (index, component, status) or the task's verdict."""

    task: str = ""
    step: int | None = None
    component: str = ""
    status: str = "starting"
    detail: str = ""

    def text(self) -> str:
        """One line, as written on the frame (without the time)."""
        line = f"step {self.step} {self.component}" if self.step is not None else self.task
        line = f"{line}: {self.status}" if line else self.status
        return f"{line} ({self.detail})" if self.detail else line


@lru_cache(maxsize=8)
def _font(size: int) -> ImageFont.FreeTypeFont | ImageFont.ImageFont:
    try:
        return ImageFont.load_default(size=size)
    except TypeError:  # Pillow < 10.1: only the small bitmap font, with no size
        return ImageFont.load_default()


def _fit(draw: ImageDraw.ImageDraw, text: str, font: Any, width: float) -> str:
    """``text`` cut with an ellipsis to fit ``width`` pixels: its longest start that fits with the ellipsis,
    found by halving (cutting a character at a time measured a failure's long reason hundreds of times
    for each frame: 5 s of a failed run's recording)."""
    if draw.textlength(text, font=font) <= width:
        return text
    fits, too_long = 0, len(text)  # text[:too_long] + "..." is too wide; text[:fits] + "..." fits (or is "...")
    while too_long - fits > 1:
        middle = (fits + too_long) // 2
        if draw.textlength(text[:middle] + "...", font=font) <= width:
            fits = middle
        else:
            too_long = middle
    return text[:fits] + "..."


def _band(caption: Caption, seconds: float, width: int) -> Image.Image:
    band = Image.new("RGB", (width, CAPTION_HEIGHT), _BAND)
    draw = ImageDraw.Draw(band)
    big, small = _font(17), _font(13)
    status = caption.status
    colour = next((c for key, c in _STATUS_COLOURS.items() if key in status), _INK)
    status_width = draw.textlength(status, font=big)
    draw.text((width - 10 - status_width, 5), status, fill=colour, font=big)
    head = f"step {caption.step}  {caption.component}" if caption.step is not None else caption.task
    draw.text((10, 5), _fit(draw, head, big, width - 30 - status_width), fill=_INK, font=big)
    clock = f"t = {seconds:.1f} s simulated"
    clock_width = draw.textlength(clock, font=small)
    draw.text((width - 10 - clock_width, 27), clock, fill=_DIM, font=small)
    second = caption.task if caption.step is not None else ""
    if caption.detail:
        second = f"{second}: {caption.detail}" if second else caption.detail
    draw.text((10, 27), _fit(draw, second, small, width - 30 - clock_width), fill=_DIM, font=small)
    return band


# --- the recorder -------------------------------------------------------------------------------


@dataclass(frozen=True)
class Box:
    """A floor rectangle (m)."""

    xmin: float
    ymin: float
    xmax: float
    ymax: float

    def union(self, other: Box) -> Box:
        return Box(
            min(self.xmin, other.xmin),
            min(self.ymin, other.ymin),
            max(self.xmax, other.xmax),
            max(self.ymax, other.ymax),
        )

    @classmethod
    def around(cls, points: Sequence[tuple[float, float]], pad: float) -> Box:
        xs, ys = [x for x, _ in points], [y for _, y in points]
        return cls(min(xs) - pad, min(ys) - pad, max(xs) + pad, max(ys) + pad)


@dataclass(frozen=True)
class Recording:
    """What ``Recorder.save`` wrote."""

    video: Path
    path_map: Path
    frames: int
    seconds: float
    """Simulated seconds from the first frame to the last."""


@dataclass
class _Floor:
    """The static outline of the home, read from the world when recording starts (the world is
    usually closed by the time the map is drawn)."""

    walls: list[Box] = field(default_factory=list)
    furniture: list[tuple[str, Box]] = field(default_factory=list)
    colours: dict[str, tuple[float, float, float]] = field(default_factory=dict)
    labelled: frozenset[str] = frozenset()  # the furniture and the dual-arm robot: named on the map


class Recorder:
    """Frames and positions of one world while a task runs in it.

    ``start()`` before the run, ``on_event`` as (or from) the runner's event callback, ``stop()``
    after it, then ``save(path)`` (the world may be closed by then). ``times`` and ``captions`` hold
    each frame's simulated time and caption text; ``track`` each movable body's sampled positions.
    """

    def __init__(
        self,
        world: HomeWorld,
        title: str = "",
        interval: float = FRAME_INTERVAL,
        size: tuple[int, int] = (WIDTH, HEIGHT),
    ) -> None:
        if interval <= 0:
            raise ValueError("the frame interval must be positive")
        if size[1] <= CAPTION_HEIGHT + 16 or size[0] < 160:
            raise ValueError(f"a frame of {size[0]}x{size[1]} leaves no room for the view")
        self.world = world
        self.size = size
        self.caption = Caption(task=_local(title) if title else "")
        self.times: list[float] = []
        self.captions: list[str] = []
        self.frames: list[Image.Image] = []
        self.track: dict[str, list[tuple[float, float, float]]] = {}
        """Body name -> (simulated s, x, y), every PATH_INTERVAL from ``start`` to ``stop``."""
        self.verdict = ""
        self._frame_steps = max(1, round(interval / world.time_step))
        self._sample_steps = max(1, min(self._frame_steps, round(PATH_INTERVAL / world.time_step)))
        self._unsubscribe: list[Callable[[], None]] = []
        self._floor = _Floor()
        self._base = ""
        self._people: list[str] = []
        self._movable: list[str] = []
        self._fixed: list[str] = []
        self._starts: dict[str, tuple[float, float]] = {}
        self._box: Box | None = None
        self._camera: tuple[float, float, float] | None = None  # target x, target y, distance
        self._view: NDArray[np.uint8] | None = None
        self._view_step = -1

    # -- life cycle --------------------------------------------------------------------------------

    @property
    def recording(self) -> bool:
        return bool(self._unsubscribe)

    def start(self) -> None:
        """Hook into the world's stepping and take the first frame."""
        if self.recording:
            return
        world = self.world
        self._base = self._driven() if world.mobile else ""  # "": no base it drives, or none chosen yet
        self._people = list(world.people)  # none, one or several
        self._movable = [name for name in world.snapshot() if name not in self._people]
        robots = {arm.robot.rsplit("#", 1)[-1] for arm in world.arm_specs.values()}
        self._fixed = [*world.furniture, *sorted(robots)]  # where the arms work: framed from the start
        self._floor = self._read_floor()
        self._starts = {name: self._xy(name) for name in self._movable}
        self._unsubscribe = [
            world.on_steps(self._sample_steps, self._sample),
            world.on_steps(self._frame_steps, self.capture),
        ]
        self._sample()
        self.capture()

    def stop(self) -> None:
        """Take a last frame unless the last one already shows this moment, and unhook."""
        if not self.recording:
            return
        shown = bool(self.times) and self.world.steps == self._view_step and self.captions[-1] == self.caption.text()
        if not shown and not self.world.closed:  # a closed world has nothing left to render
            self._sample()
            self.capture()
        for unsubscribe in self._unsubscribe:
            unsubscribe()
        self._unsubscribe = []

    def __enter__(self) -> Recorder:
        self.start()
        return self

    def __exit__(self, *exc: object) -> None:
        self.stop()

    def _driven(self) -> str:
        """The body name of the base the world drives (in a home of several, the one a run's plan works)."""
        return self.world.name_of(self.world.base.body) or "base"

    def _xy(self, name: str) -> tuple[float, float]:
        x, y, _ = self.world.pose(name).position
        return float(x), float(y)

    def _sample(self) -> None:
        now = self.world.time
        if not self._base and self.world.mobile is not None:
            self._base = self._driven()  # a home of several bases: the one a plan chose since the start
        for name in (*self._movable, *self._people):
            x, y = self._xy(name)
            points = self.track.setdefault(name, [])
            if not points or points[-1][0] != now:
                points.append((now, x, y))

    def on_event(self, event: EventLike) -> None:
        """Follow the executor: a step starting changes the caption; a step ending, or the run, adds a frame."""
        message = event.message
        task = _local(str(message.get("task", ""))) or self.caption.task
        if event.topic == "/cbrs/task_progress" and "step" in message:
            kind = str(message.get("event", ""))
            component = _local(str(message.get("component", "")))
            detail = ""
            if kind == "step_started":
                status = "running"
            elif kind == "step_succeeded":
                status = "succeeded"
            else:
                status = "failed"
                failover = message.get("failover")
                detail = f"failing over to {_local(str(failover))}" if failover else str(message.get("reason", ""))
            self.caption = Caption(task, int(message["step"]), component, status, detail)
            if kind != "step_started":
                self.capture()
        elif event.topic == "/cbrs/task_progress" and message.get("event") == "replanning":
            self.caption = Caption(
                task, 0, f"re-planning (plan {message.get('plan')})", "failed", str(message.get("reason", ""))
            )
            self.capture()
        elif event.topic == "/cbrs/task" and "status" in message:
            self.verdict = str(message["status"])
            reason = str(message.get("reason", ""))
            self.caption = Caption(task, None, "", f"task {self.verdict}", reason)
            self.capture()

    # -- frames ------------------------------------------------------------------------------------

    def capture(self) -> None:
        """Add a frame of the world as it is now, with the current caption."""
        world = self.world
        width, height = self.size
        if self._view is None or self._view_step != world.steps:
            self._view = self._render(width, height - CAPTION_HEIGHT)
            self._view_step = world.steps
        frame = Image.new("RGB", self.size, _BAND)
        frame.paste(_band(self.caption, world.time, width), (0, 0))
        frame.paste(Image.fromarray(self._view), (0, CAPTION_HEIGHT))
        self.frames.append(frame)
        self.times.append(world.time)
        self.captions.append(self.caption.text())

    def _wanted_box(self) -> Box:
        world = self.world
        points: list[tuple[float, float]] = []
        for name in self._fixed:
            if name in world.bodies:
                low, high = p.getAABB(world.body(name), physicsClientId=world.client)
                points += [(low[0], low[1]), (high[0], high[1])]
        for name in self._movable:
            here = self._xy(name)
            start = self._starts[name]
            if math.hypot(here[0] - start[0], here[1] - start[1]) > MOVED:
                points += [start, here]
        if self._base:  # in a home with no base, nobody is driven to
            base = self._xy(self._base)
            start = self._starts.get(self._base, base)
            driven = math.hypot(base[0] - start[0], base[1] - start[1]) > MOVED
            for person in (self._xy(name) for name in self._people):
                if driven and math.hypot(person[0] - base[0], person[1] - base[1]) < PERSON_NEAR:
                    points.append(person)
            if not points:
                points = [base]
        if not points:  # no base, no robot and nothing moved: the middle of the home
            home = world.extent
            points = [((home.xmin + home.xmax) / 2, (home.ymin + home.ymax) / 2)]
        wanted = Box.around(points, PAD)
        self._box = wanted if self._box is None else self._box.union(wanted)
        return self._box

    def _render(self, width: int, height: int) -> NDArray[np.uint8]:
        box = self._wanted_box()
        tan_v = math.tan(math.radians(FOV / 2))
        tan_h = tan_v * width / height
        pitch = math.radians(-PITCH)
        across = (box.xmax - box.xmin) / 2 / tan_h
        # The box's depth is seen foreshortened; 1.2 m of arms and person stand up from the floor.
        deep = ((box.ymax - box.ymin) * math.sin(pitch) + 1.2 * math.cos(pitch)) / 2 / tan_v
        wanted = ((box.xmin + box.xmax) / 2, (box.ymin + box.ymax) / 2, 1.15 * max(across, deep, 2.0))
        if self._camera is None:
            self._camera = wanted
        else:
            self._camera = (
                self._camera[0] + EASE * (wanted[0] - self._camera[0]),
                self._camera[1] + EASE * (wanted[1] - self._camera[1]),
                self._camera[2] + EASE * (wanted[2] - self._camera[2]),
            )
        x, y, distance = self._camera
        client = self.world.client
        view = p.computeViewMatrixFromYawPitchRoll((x, y, 0.4), distance, 0.0, PITCH, 0.0, 2, physicsClientId=client)
        projection = p.computeProjectionMatrixFOV(FOV, width / height, 0.1, 60.0, physicsClientId=client)
        rgba, _ = render(client, width, height, view, projection)
        image = np.reshape(np.asarray(rgba, dtype=np.uint8), (height, width, 4))[:, :, :3]
        return np.ascontiguousarray(image)

    def _read_floor(self) -> _Floor:
        world = self.world
        floor = _Floor(labelled=frozenset(self._fixed))
        tracked = {*self._movable, *self._people}
        for name, body in world.bodies.items():
            data = p.getVisualShapeData(body, physicsClientId=world.client)
            rgba = max(data, key=lambda shape: sum(shape[7][:3]) - 2 * min(shape[7][:3]))[7] if data else (0.5,) * 4
            floor.colours[name] = (float(rgba[0]), float(rgba[1]), float(rgba[2]))
            if name in tracked or name == "Floor":
                continue
            low, high = p.getAABB(body, physicsClientId=world.client)
            outline = Box(low[0], low[1], high[0], high[1])
            if name.startswith("Wall"):
                floor.walls.append(outline)
            elif p.getDynamicsInfo(body, -1, physicsClientId=world.client)[0] == 0.0:
                floor.furniture.append((name, outline))
        return floor

    # -- writing -----------------------------------------------------------------------------------

    def durations(self) -> list[float]:
        """Seconds each frame is shown: simulated time between frames over PLAYBACK_SPEED, at least
        CAPTION_HOLD when the caption changed and LAST_HOLD for the last frame."""
        shown: list[float] = []
        for i, now in enumerate(self.times):
            if i + 1 == len(self.times):
                shown.append(LAST_HOLD)
                continue
            seconds = max(0.05, (self.times[i + 1] - now) / PLAYBACK_SPEED)
            if i == 0 or self.captions[i] != self.captions[i - 1]:
                seconds = max(seconds, CAPTION_HOLD)
            shown.append(seconds)
        return shown

    def save(self, target: Path) -> Recording:
        """Write the frames to ``target`` (.gif, .mp4 or .webm) and the path map beside it."""
        check_target(target)
        if not self.frames:
            raise RecordingError("nothing was recorded")
        target.parent.mkdir(parents=True, exist_ok=True)
        durations = self.durations()
        if target.suffix.lower() == ".gif":
            _write_gif(self.frames, durations, target)
        else:
            _write_video(self.frames, durations, target)
        title = f"{self.caption.task or 'run'}: {self.verdict or 'not finished'}"
        title += f", {self.times[-1] - self.times[0]:.1f} s simulated"
        path_map = path_map_name(target)
        draw_path_map(self.track, self._floor, path_map, title, self._base, self._people)
        return Recording(target, path_map, len(self.frames), self.times[-1] - self.times[0])


def _write_gif(frames: Sequence[Image.Image], durations: Sequence[float], target: Path) -> None:
    ms = [max(20, round(seconds * 100) * 10) for seconds in durations]  # GIF counts hundredths
    frames[0].save(target, save_all=True, append_images=list(frames[1:]), duration=ms, loop=0)


def _write_video(frames: Sequence[Image.Image], durations: Sequence[float], target: Path) -> None:
    ffmpeg = find_ffmpeg()
    suffix = target.suffix.lower()
    codec = _codec(ffmpeg, suffix) if ffmpeg is not None else None
    if ffmpeg is None or codec is None:
        raise RecordingError(f"cannot write {suffix}: {VIDEO_INSTALL}")
    width, height = frames[0].size
    command = [
        ffmpeg,
        "-y",
        "-hide_banner",
        "-loglevel",
        "error",
        "-f",
        "rawvideo",
        "-pix_fmt",
        "rgb24",
        "-s",
        f"{width}x{height}",
        "-framerate",
        str(VIDEO_FPS),
        "-i",
        "-",
        "-an",
        *codec,
        str(target),
    ]
    process = subprocess.Popen(command, stdin=subprocess.PIPE, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    assert process.stdin is not None
    shown = 0.0
    written = 0
    try:
        for frame, seconds in zip(frames, durations, strict=True):
            shown += seconds
            # A constant frame rate: repeat each frame until the video's clock catches up with it.
            repeats = max(1, round(shown * VIDEO_FPS) - written)
            data = frame.convert("RGB").tobytes()
            for _ in range(repeats):
                process.stdin.write(data)
            written += repeats
        process.stdin.close()
    except BrokenPipeError:
        pass
    errors = process.stderr.read().decode(errors="replace") if process.stderr is not None else ""
    if process.wait() != 0:
        raise RecordingError(f"ffmpeg could not write {target}: {errors.strip()[-500:]}")


# --- the path map -------------------------------------------------------------------------------


def draw_path_map(
    track: Mapping[str, Sequence[tuple[float, float, float]]],
    floor: _Floor,
    target: Path,
    title: str,
    base: str,
    people: Collection[str],
) -> None:
    """A top-down map: walls and furniture, the base's path coloured by time, and an arrow from each
    object's start to its end position; moves of a few centimetres get a magnified inset."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg  # slow to import; only when saving
    from matplotlib.figure import Figure

    width, height = PATH_MAP_SIZE
    figure = Figure(figsize=(width / 100, height / 100), dpi=100, layout="constrained")
    FigureCanvasAgg(figure)
    axes = figure.add_subplot()
    bounds = [(b.xmin, b.ymin) for b in floor.walls] + [(b.xmax, b.ymax) for b in floor.walls]
    bounds += [(x, y) for points in track.values() for _, x, y in points]
    home = Box.around(bounds or [(0.0, 0.0)], 0.3)
    lines = _draw_layer(axes, track, floor, base, people, labels=True)
    axes.set_xlim(home.xmin, home.xmax)
    axes.set_ylim(home.ymin, home.ymax)
    axes.set_aspect("equal")
    axes.set_xlabel("x (m)")
    axes.set_ylabel("y (m)")
    axes.set_title(title, fontsize=11)
    if lines is not None:
        figure.colorbar(lines, ax=axes, shrink=0.6, pad=0.01, label=f"{base} path: simulated s")
    moves = [
        (x, y)
        for name, points in track.items()
        if name != base and name not in people and points
        for _, x, y in (points[0], points[-1])
    ]
    if moves:
        near = Box.around(moves, 0.35)
        if max(near.xmax - near.xmin, near.ymax - near.ymin) < 0.25 * (home.xmax - home.xmin):
            # Objects move centimetres on a 10 m plan: magnify where they are, in the corner farthest from them.
            right = (near.xmin + near.xmax) / 2 < (home.xmin + home.xmax) / 2
            top = (near.ymin + near.ymax) / 2 < (home.ymin + home.ymax) / 2
            inset = axes.inset_axes((0.58 if right else 0.02, 0.58 if top else 0.02, 0.4, 0.4))
            _draw_layer(inset, track, floor, base, people, labels=False)
            inset.set_xlim(near.xmin, near.xmax)
            inset.set_ylim(near.ymin, near.ymax)
            inset.set_aspect("equal")
            inset.set_xticks([])
            inset.set_yticks([])
            inset.set_title("magnified", fontsize=7, color="0.35")
            inset.set_facecolor("white")
            axes.indicate_inset_zoom(inset, edgecolor="0.4")
    axes.plot([], [], marker="o", markerfacecolor="none", markeredgecolor="0.3", ls="", label="start (hollow)")
    axes.plot([], [], marker="o", color="0.3", ls="", label="end (filled)")
    axes.legend(loc="upper center", bbox_to_anchor=(0.5, -0.08), ncol=7, fontsize=8, frameon=False)
    figure.savefig(target, dpi=100)


def _draw_layer(
    axes: Any,
    track: Mapping[str, Sequence[tuple[float, float, float]]],
    floor: _Floor,
    base: str,
    people: Collection[str],
    labels: bool,
) -> Any:
    """Draw the floor and the tracks on ``axes``; returns the base's path (for a colour bar) or None."""
    from matplotlib.collections import LineCollection
    from matplotlib.patches import Rectangle

    for box in floor.walls:
        axes.add_patch(Rectangle((box.xmin, box.ymin), box.xmax - box.xmin, box.ymax - box.ymin, color="0.25"))
    for name, box in floor.furniture:
        axes.add_patch(
            Rectangle(
                (box.xmin, box.ymin), box.xmax - box.xmin, box.ymax - box.ymin, facecolor="0.88", edgecolor="0.55"
            )
        )
        if labels and name in floor.labelled:
            axes.annotate(
                name, ((box.xmin + box.xmax) / 2, box.ymax), ha="center", va="bottom", fontsize=7, color="0.4"
            )
    path = track.get(base, [])
    drawn = None
    if _travelled(path) > MOVED:
        xy = np.array([(x, y) for _, x, y in path])
        times = np.array([t for t, _, _ in path])
        drawn = LineCollection(list(np.stack([xy[:-1], xy[1:]], axis=1)), cmap="viridis", linewidths=2.5, zorder=3)
        drawn.set_array(times[:-1])
        axes.add_collection(drawn)
    if path:
        (_, x0, y0), (_, x1, y1) = path[0], path[-1]
        axes.plot(x0, y0, marker="o", markersize=9, markerfacecolor="white", color="black", linestyle="")
        axes.plot(x1, y1, marker="s", markersize=8, color="black", linestyle="", label=base if labels else None)
        if labels:
            axes.annotate(base, (x1, y1), xytext=(7, -12), textcoords="offset points", fontsize=8)
    for name, points in track.items():
        if name == base or not points:
            continue
        colour = floor.colours.get(name, (0.3, 0.3, 0.3))
        (_, x0, y0), (_, x1, y1) = points[0], points[-1]
        label = name if labels else None
        if name in people:
            axes.plot(x1, y1, marker="o", markersize=12, color=colour, markeredgecolor="black", ls="", label=label)
            continue
        axes.plot(x0, y0, marker="o", markersize=7, markerfacecolor="none", markeredgecolor=colour, linestyle="")
        axes.plot(x1, y1, marker="o", markersize=7, color=colour, linestyle="", label=label)
        if _travelled(points) > 0.01:
            # Faintly the way it went (a carried object rides under the base's path), boldly from where
            # it started to where it ended.
            xs, ys = [x for _, x, _ in points], [y for _, _, y in points]
            axes.plot(xs, ys, color=colour, lw=1.0, ls=":", alpha=0.7, zorder=1)
            arrow = {"arrowstyle": "-|>", "color": colour, "lw": 1.6, "mutation_scale": 14, "shrinkA": 4, "shrinkB": 4}
            axes.annotate("", (x1, y1), (x0, y0), arrowprops=arrow, zorder=4)
    return drawn


def _travelled(path: Sequence[tuple[float, float, float]]) -> float:
    return sum(math.dist(a[1:], b[1:]) for a, b in itertools.pairwise(path))
