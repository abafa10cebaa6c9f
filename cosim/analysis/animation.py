"""A run's animation, a GIF (Pillow) or an MP4 (ffmpeg), about 25 s at 10 frames per second."""
from __future__ import annotations

import math
import shutil
import subprocess
from pathlib import Path

import numpy as np
from matplotlib.patches import Polygon

from autopilot_fmu.guidance import route as followed_route

from ..core.files import whole_file
from ..core.recording import Recording
from .figures import RUDDER_LABEL, new_figure
from .reports import title
from .track import hull_outline, legend_if_any, outlines, track_panel, waypoint_name

FPS = 10
VIDEO_SECONDS = 25.0
NEEDS = ("ship.x", "ship.y", "ship.psi", "ship.delta")


def require_track(columns: list[str]) -> None:
    if missing := [c for c in NEEDS if c not in columns]:
        raise ValueError(f"--animate needs the ship's track; this system records no "
                         f"{', '.join(missing)}")


def frame_times(t: np.ndarray) -> np.ndarray:
    """Indices of the rows shown, one per frame."""
    frames = max(2, min(len(t), round(VIDEO_SECONDS * FPS)))
    return np.unique(np.round(np.linspace(0, len(t) - 1, frames)).astype(int))


def leg_text(wp_index: int, points: np.ndarray) -> str:
    """'leg WP1 -> WP2 (30, 0) m' toward point ``wp_index``; past the last, held course."""
    if wp_index >= len(points):
        return f"past {waypoint_name(len(points) - 1)}, the last: holding its course"
    north, east = points[wp_index]
    return (f"leg {waypoint_name(wp_index - 1)} -> {waypoint_name(wp_index)} "
            f"({north:g}, {east:g}) m")


def animate(run: Recording, path: Path, label: str, fmt: str) -> Path:
    """Write the animation at ``path`` with ``fmt``'s suffix ('gif', 'mp4'), whole or not at all."""
    t, (x, y, psi, delta) = run.t, (run[c] for c in NEEDS)
    fig = new_figure(figsize=(10, 5.6), dpi=90, layout="constrained")
    grid = fig.add_gridspec(2, 2, width_ratios=(1.0, 1.1))
    track, heading, rudder = map(fig.add_subplot, (grid[:, 0], grid[0, 1], grid[1, 1]))
    track_panel(track, run, ship=False)
    track.plot(y, x, color="0.8", linewidth=0.8, zorder=1)            # the whole track, faint
    wake, = track.plot([], [], color="k", linewidth=1.2, zorder=3)
    shown = outlines(run)
    hull = track.add_patch(Polygon(hull_outline(x[0], y[0], psi[0], shown.scale), closed=True,
                                   color="tab:red", zorder=5))
    track.plot([], [], "s", color="tab:red", label=f"ship outline {shown.size}")
    legs = run.meta.get("parameters", {}).get("guidance")
    points = np.array(followed_route(legs)) if legs else None
    leg = run["guidance.wp_index"].astype(int) if legs else None
    active, = track.plot([], [], color="tab:green", linewidth=3, alpha=0.6, zorder=2,
                         label="active leg" if points is not None else None)
    legend_if_any(track)
    heading.plot(t, np.degrees(psi), color="k", linewidth=0.8, label="psi")
    if "guidance.psi_d" in run.columns:
        heading.plot(t, np.degrees(run["guidance.psi_d"]), "--", color="tab:red",
                     linewidth=0.8, label="psi_d")
    heading.set(ylabel="heading (deg)")
    legend_if_any(heading)
    rudder.plot(t, np.degrees(delta), color="k", linewidth=0.8)
    rudder.set(xlabel="time (s)", ylabel=RUDDER_LABEL)
    cursors = [a.axvline(t[0], color="tab:red", linewidth=1) for a in (heading, rudder)]
    for a in (heading, rudder):
        a.grid(alpha=0.3)
    fig.suptitle(title(label, run.meta), fontsize=7)

    def draw(k: int) -> str:
        wake.set_data(y[:k + 1], x[:k + 1])
        hull.set_xy(hull_outline(x[k], y[k], psi[k], shown.scale))
        for cursor in cursors:
            cursor.set_xdata([t[k], t[k]])
        text = (f"t = {t[k]:.0f} s   heading {math.degrees(psi[k]):.1f} deg   "
                f"rudder {math.degrees(delta[k]):+.1f} deg")
        if leg is None:
            return text + "\n"
        to = min(leg[k], len(points) - 1)
        active.set_data(points[to - 1:to + 1, 1], points[to - 1:to + 1, 0])
        return f"{text}\n{leg_text(int(leg[k]), points)}"

    readout = track.set_title(draw(0), loc="left", fontsize=8, family="monospace")
    dynamic = [wake, hull, active, readout, *cursors]
    for artist in dynamic:
        artist.set_animated(True)           # left out of the background, drawn once
    fig.canvas.draw()
    background = fig.canvas.copy_from_bbox(fig.bbox)
    target = path.with_suffix(f".{fmt}")
    frames = []
    for k in frame_times(t):
        readout.set_text(draw(k))
        fig.canvas.restore_region(background)
        for artist in dynamic:
            artist.axes.draw_artist(artist)
        frames.append(np.asarray(fig.canvas.buffer_rgba())[:, :, :3].copy())
    with whole_file(target) as tmp:
        if fmt == "gif":
            from PIL import Image
            images = [Image.fromarray(f).quantize(colors=64, method=Image.Quantize.FASTOCTREE)
                      for f in frames]
            images[0].save(tmp, save_all=True, append_images=images[1:],
                           duration=round(1000 / FPS), loop=0)
            return target
        height, width, _ = frames[0].shape
        encode = subprocess.run(
            [shutil.which("ffmpeg"), "-loglevel", "error", "-y", "-f", "rawvideo", "-pix_fmt",
             "rgb24", "-s", f"{width}x{height}", "-r", str(FPS), "-i", "-", "-vf",
             "pad=ceil(iw/2)*2:ceil(ih/2)*2", "-pix_fmt", "yuv420p", "-f", "mp4", tmp],
            input=b"".join(frame.tobytes() for frame in frames), capture_output=True)
        if encode.returncode != 0:
            raise RuntimeError(f"ffmpeg could not encode the animation: "
                               f"{encode.stderr.decode(errors='replace').strip()}")
    return target
