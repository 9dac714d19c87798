"""An animation of the speed field: the wave as people would rather watch it than read it.

The frames are the speeds of every bead that the tracker kept at evenly spaced samples of the
run (``field_samples``, no dump needed): :func:`movie_samples` picks them, :func:`speed_movie`
draws each as the packing's beads coloured by |v|/V0 on a logarithmic scale (a solitary
front decays by orders of magnitude as it spreads) and writes an animated GIF atomically.
Frictional spheres also turn: the same drawing of their rims' speed |ω_z| r / V0 shows the
spin on the same scale as the motion (:data:`SPIN_LABEL`).
"""

from __future__ import annotations

import numpy as np

from hexdem.common.io import atomic_path

#: Frames of a movie, and how long each is shown [ms].
MOVIE_FRAMES = 60
FRAME_MS = 100
#: Colours of the GIF's palette, shared by every frame.
PALETTE_COLOURS = 192
#: The colour scale spans this many decades below V0.
DECADES = 3.0
#: Colour-bar labels of the speed movie and of the spin movie.
SPEED_LABEL = "speed |v| / V₀"
SPIN_LABEL = "spin: rim speed |ω_z| r / V₀"


def movie_samples(n_samples: int, frames: int = MOVIE_FRAMES) -> tuple[int, ...]:
    """Indices of ``frames`` samples evenly spread over a run of ``n_samples`` (the first and last included)."""
    return tuple(int(k) for k in np.unique(np.linspace(0, n_samples - 1, min(frames, n_samples)).round()))


def speed_movie(results, model, times, speeds, v0: float, path, title: str = "", label: str = SPEED_LABEL) -> None:
    """Write ``path`` (GIF): one frame per row of ``speeds`` (F, N), the beads coloured by
    speed/``v0`` (``label`` on the colour bar), the frame's time from ``times`` (F,) in the
    run's units, walls and the struck beads drawn."""
    from matplotlib.colors import LogNorm  # (drawing only: a run picks its frames without matplotlib)

    from hexdem.analysis.plotting import UNIT_LABELS, draw_lattice, subplots

    units = UNIT_LABELS[results.units]
    fig, ax = subplots(figsize=(6.4, 5.4))
    fig.subplots_adjust(left=0.1, right=0.97, bottom=0.09, top=0.92)
    floor = 10.0**-DECADES
    circles = draw_lattice(
        ax,
        results,
        model,
        np.full(len(model.packing), floor),
        label,
        cmap="inferno",
        norm=LogNorm(floor, 1.0),
        marker_colour="c",
    )
    clock = ax.text(0.5, 1.01, "", transform=ax.transAxes, ha="center", va="bottom", fontsize=12)

    def show(frame: int) -> None:
        circles.set_array(np.clip(np.nan_to_num(np.asarray(speeds[frame]) / v0, nan=floor), floor, None))
        clock.set_text(f"{title}   t = {times[frame] * units['time_scale']:.3g} {units['time']}")

    write_gif(fig, (circles, clock), len(times), show, path)


def write_gif(fig, artists, count: int, show, path) -> None:
    """Write ``path`` (GIF) of ``count`` frames of ``fig``: ``show(frame)`` updates ``artists``
    for each, which alone are redrawn on a background of everything else, rendered once."""
    from PIL import Image

    for artist in artists:
        artist.set_animated(True)
    fig.canvas.draw()
    background = fig.canvas.copy_from_bbox(fig.bbox)
    frames, palette = [], None
    for frame in range(count):
        fig.canvas.restore_region(background)
        show(frame)
        for artist in artists:
            artist.axes.draw_artist(artist)
        image = Image.fromarray(np.asarray(fig.canvas.buffer_rgba())[..., :3])
        # one palette for the movie, from the first frame (its colour bar holds the whole scale)
        palette = palette or image.quantize(colors=PALETTE_COLOURS)
        frames.append(image.quantize(palette=palette, dither=Image.Dither.NONE))
    with atomic_path(path) as tmp:
        frames[0].save(tmp, format="GIF", save_all=True, append_images=frames[1:], duration=FRAME_MS, loop=0)
