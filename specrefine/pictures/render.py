"""Top-down pictures of a maze task: the image a VLM sees, and the pictures in the notebooks.

Colours follow the paper's figures: walls black, the start region cyan, the goal green,
subgoals / waypoints orange, successful trajectories green and failed ones red; hazard cells
``~`` (avoided like walls, but no walls) purple and hatched.  Axes are in
metres with a light grid at every cell so that coordinates can be read off the picture.

Figures are plain :class:`matplotlib.figure.Figure` objects (no pyplot state, nothing to
close); :func:`to_png` / :func:`save_png` rasterise them at exactly the requested size.

>>> from specrefine.core.mazes import load_maze
>>> from specrefine.core.spec import maze_task
>>> maze = load_maze("u_maze")
>>> png = to_png(render_task(maze, maze_task(maze), size_px=512))
"""

from __future__ import annotations

import io
from pathlib import Path

import matplotlib
import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.patches import Circle, FancyArrowPatch, Patch, Rectangle
from matplotlib.ticker import MultipleLocator

from ..core.regions import Box, Disc, Region


class PngFigure(Figure):
    """A Figure that shows itself as a PNG in Jupyter (``display(fig)``, or as a cell's last value).

    IPython renders a plain matplotlib Figure as a picture only when the inline backend has
    registered its formatter (``%matplotlib inline``); otherwise a live JupyterLab shows the text
    ``<Figure size 640x535 with 1 Axes>``, which is what the search slider of notebook 05 did.
    """

    def _repr_png_(self):
        return to_png(self)


def subplots(nrows: int = 1, ncols: int = 1, *, figsize, **kwargs):
    """``(fig, axes)`` like ``pyplot.subplots``, on a :class:`PngFigure`: no pyplot state, nothing to close."""
    fig = PngFigure(figsize=figsize)
    return fig, fig.subplots(nrows, ncols, **kwargs)

WALL = "black"
HAZARD = "#8e24aa"  # purple: hazard cells '~'
START = "#00c8e6"  # cyan
GOAL = "#22b14c"  # green
SUBGOAL = "#ff8c00"  # orange
CANDIDATE = "#ff8c00"
PROPOSED = "#5f6368"  # grey outline: a waypoint set as proposed, under the subset chosen in it
SUCCESS = "#119933"
FAILURE = "#dd2222"
EDGE = "#333333"
PATH = "#1f4fff"
DPI = 100

__all__ = [
    "render_task", "render_graph_diagram", "render_roadmap", "to_png", "save_png", "new_figure", "subplots",
    "PngFigure", "draw_walls", "draw_hazards", "draw_region", "draw_maze_regions", "draw_graph", "draw_trajectories",
    "draw_waypoints", "draw_points",
]


# --- figures -----------------------------------------------------------------------------------
def _font(size_px: int) -> float:
    return float(np.clip(size_px / 64, 7.0, 16.0))


def new_figure(bounds, size_px: int = 768, title: str | None = None, legend_row: bool = True):
    """An empty figure whose longer side is ``size_px`` pixels, with map axes over ``bounds``.

    Returns ``(fig, ax)``; the axes are equal-aspect, in metres, with a light grid.
    """
    x0, y0, x1, y1 = bounds
    fs = _font(size_px)
    # margins in pixels: left for y tick labels, bottom for x tick labels, top for title + legend
    left, right, bottom = 4.2 * fs, 1.2 * fs, 3.4 * fs
    title_lines = title.count("\n") + 1 if title else 0
    top = 0.8 * fs + 1.4 * fs * title_lines + (2.0 * fs if legend_row else 0.0)
    aspect = (y1 - y0) / (x1 - x0)
    if aspect <= 1.0:
        w = size_px
        h = int(round(min(size_px, max((w - left - right) * aspect + top + bottom, 0.35 * size_px))))
    else:
        h = size_px
        w = int(round(min(size_px, max((h - top - bottom) / aspect + left + right, 0.35 * size_px))))
    fig = PngFigure(figsize=(w / DPI, h / DPI), dpi=DPI)
    FigureCanvasAgg(fig)
    ax = fig.add_axes((left / w, bottom / h, 1 - (left + right) / w, 1 - (top + bottom) / h))
    ax.set_xlim(x0, x1)
    ax.set_ylim(y0, y1)
    ax.set_aspect("equal", adjustable="box", anchor="C")
    ax.tick_params(labelsize=0.85 * fs, length=2, pad=1.5)
    ax.set_xlabel("x (m)", fontsize=0.85 * fs, labelpad=1)
    ax.set_ylabel("y (m)", fontsize=0.85 * fs, labelpad=1)
    if title:
        fig.suptitle(title, fontsize=fs, y=1 - 0.35 * fs / h, va="top")
    fig._specrefine_font = fs  # used by the draw_* helpers for consistent sizes
    return fig, ax


def _fs(ax) -> float:
    return getattr(ax.figure, "_specrefine_font", 10.0)


def _grid(ax, step: float) -> None:
    """Light grid every ``step`` metres, drawn above the walls so coordinates stay readable."""
    x0, x1 = ax.get_xlim()
    y0, y1 = ax.get_ylim()
    span = max(x1 - x0, y1 - y0)
    tick = step * max(1, int(np.ceil(span / step / 24)))  # at most ~24 labelled ticks per axis
    ax.xaxis.set_major_locator(MultipleLocator(tick))
    ax.yaxis.set_major_locator(MultipleLocator(tick))
    if tick != step:
        ax.xaxis.set_minor_locator(MultipleLocator(step))
        ax.yaxis.set_minor_locator(MultipleLocator(step))
    ax.grid(True, which="both", color="#9aa0a6", alpha=0.45, lw=0.5, zorder=1.5)
    ax.set_axisbelow(False)


# --- drawing helpers ---------------------------------------------------------------------------
def draw_region(ax, region: Region, color, *, alpha=0.45, edge=False, hatch=None, zorder=1.0, lw=1.0, ls="-"):
    """Fill (and optionally outline) every part of a region."""
    for part in region.parts():
        kw = dict(facecolor=color if alpha > 0 else "none", alpha=None, zorder=zorder, hatch=hatch,
                  edgecolor=color if (edge or hatch) else "none", lw=lw if edge else 0.0, linestyle=ls)
        if isinstance(part, Box):
            patch = Rectangle((part.xmin, part.ymin), part.xmax - part.xmin, part.ymax - part.ymin, **kw)
        elif isinstance(part, Disc):
            patch = Circle((part.cx, part.cy), part.r, **kw)
        else:  # pragma: no cover - unknown region type
            continue
        if alpha > 0:
            patch.set_facecolor(matplotlib.colors.to_rgba(color, alpha))
        if edge:
            patch.set_edgecolor(matplotlib.colors.to_rgba(color, 1.0))
        ax.add_patch(patch)


def draw_walls(ax, maze) -> None:
    """Wall cells in black (the frame around the grid lies outside the axes)."""
    draw_region(ax, maze.walls, WALL, alpha=1.0, zorder=1.0)


def draw_hazards(ax, maze) -> None:
    """Hazard cells ``~`` in hatched purple (avoided by every subtask, but no walls: the body can cross them)."""
    if getattr(maze, "hazards", None) is not None:
        draw_region(ax, maze.hazards, HAZARD, alpha=0.55, hatch="xx", zorder=1.05)


def _label(ax, xy, text, color="black", size=None, zorder=6):
    ax.text(xy[0], xy[1], text, ha="center", va="center", fontsize=size or 0.9 * _fs(ax), color=color,
            fontweight="bold", zorder=zorder,
            bbox=dict(boxstyle="round,pad=0.15", fc="white", ec=color, lw=0.6, alpha=0.85))


def draw_maze_regions(ax, maze, *, alpha=0.45, labels=True) -> None:
    """The maze's own start (cyan), goal (green) and lettered subgoals (orange)."""
    draw_region(ax, maze.start, START, alpha=alpha, zorder=1.1)
    draw_region(ax, maze.goal, GOAL, alpha=alpha, zorder=1.1)
    for letter, region in maze.subgoals.items():
        draw_region(ax, region, SUBGOAL, alpha=alpha, zorder=1.1)
        if labels:
            _label(ax, region.centre(), letter, SUBGOAL)
    if labels:
        _label(ax, maze.start.centre(), "S", "#007a8c")
        _label(ax, maze.goal.centre(), "G", "#116622")


def _vertex_point(graph, v) -> np.ndarray:
    pt = graph.goal_point(v)
    return np.asarray(pt, dtype=float) if pt is not None else np.asarray(graph.region(v).centre(), dtype=float)


def _vertex_colour(graph, v) -> str:
    if v == graph.initial:
        return START
    if v in graph.finals:
        return GOAL
    return SUBGOAL


def draw_graph(ax, graph, *, path=None, edge_labels=None, regions=True, alpha=0.5) -> None:
    """The task graph on the map: vertex regions, vertices at their representative points, edge arrows.

    ``path`` (a list of vertex names) is highlighted in blue; ``edge_labels`` maps ``(u, v)`` to text
    (e.g. a success probability) written at the middle of the arrow. Shortcut edges (over a split's waypoints,
    ``ours-shortcut``) are dashed.
    """
    fs = _fs(ax)
    if regions:
        for v in graph.vertices():
            region = graph.region(v)  # outline single shapes only (a union's inner seams would show)
            draw_region(ax, region, _vertex_colour(graph, v), alpha=alpha, zorder=1.2, edge=len(region.parts()) == 1,
                        lw=0.8)
    on_path = set(zip(path, path[1:], strict=False)) if path else set()
    pts = {v: _vertex_point(graph, v) for v in graph.vertices()}
    for u, v in graph.edges():
        hot = (u, v) in on_path
        arrow = FancyArrowPatch(pts[u], pts[v], arrowstyle="-|>", mutation_scale=1.4 * fs,
                                color=PATH if hot else EDGE, lw=2.4 if hot else 1.2, alpha=0.95 if hot else 0.8,
                                shrinkA=0.7 * fs, shrinkB=0.7 * fs, connectionstyle="arc3,rad=0.08", zorder=5,
                                linestyle="--" if graph.is_shortcut(u, v) else "-")
        ax.add_patch(arrow)
        if edge_labels and (u, v) in edge_labels:
            mid = (pts[u] + pts[v]) / 2
            ax.text(mid[0], mid[1], str(edge_labels[(u, v)]), fontsize=0.8 * fs, ha="center", va="center",
                    zorder=6, color=PATH if hot else EDGE,
                    bbox=dict(boxstyle="round,pad=0.12", fc="white", ec="none", alpha=0.8))
    for v in graph.vertices():
        p = pts[v]
        colour = _vertex_colour(graph, v)
        ax.plot([p[0]], [p[1]], "o", ms=0.45 * fs, mfc=colour, mec="black", mew=0.8, zorder=6)
        label = graph.label(v) or v
        dark = {START: "#007a8c", GOAL: "#116622", SUBGOAL: "#b35f00"}[colour]
        ax.annotate(label, p, xytext=(0.55 * fs, 0.55 * fs), textcoords="offset points", fontsize=0.85 * fs,
                    color=dark, fontweight="bold", zorder=7,
                    bbox=dict(boxstyle="round,pad=0.12", fc="white", ec=dark, lw=0.5, alpha=0.85))


def draw_trajectories(ax, trajectories, success=None, lengths=None, *, alpha=None, lw=None, max_n=256) -> None:
    """Trajectories (n, T, 2) as thin lines: green for success, red for failure (grey if unknown)."""
    trajectories = np.asarray(trajectories, dtype=float)
    if trajectories.ndim == 2:
        trajectories = trajectories[None]
    n = min(len(trajectories), max_n)
    alpha = alpha if alpha is not None else float(np.clip(6.0 / np.sqrt(max(n, 1)), 0.25, 0.8))
    lw = lw if lw is not None else max(0.6, _fs(ax) / 12)
    for i in range(n):
        T = int(lengths[i]) if lengths is not None else trajectories.shape[1]
        xy = trajectories[i, : max(T, 1)]
        colour = "#777777" if success is None else (SUCCESS if success[i] else FAILURE)
        ax.plot(xy[:, 0], xy[:, 1], color=colour, lw=lw, alpha=alpha, zorder=3, solid_capstyle="round")
        ax.plot(xy[-1:, 0], xy[-1:, 1], marker="o" if success is None or success[i] else "x", ms=2.5 * lw,
                color=colour, alpha=min(1.0, alpha + 0.2), zorder=3.1, mew=lw)


def draw_waypoints(ax, waypoints, *, color=CANDIDATE, prefix="x", start_index=1, radius=None) -> None:
    """Candidate waypoints (Regions or (x, y) points) in orange, outlined and numbered x1, x2, ..."""
    for i, w in enumerate(waypoints, start=start_index):
        if isinstance(w, Region):
            draw_region(ax, w, color, alpha=0.35, edge=True, lw=1.4, ls="--", zorder=2.0)
            centre = w.centre()
        else:
            centre = np.asarray(w, dtype=float)
            r = radius if radius is not None else 0.15 * (ax.get_xlim()[1] - ax.get_xlim()[0]) / 20
            ax.add_patch(Circle(centre, r, facecolor=color, edgecolor="black", lw=0.6, zorder=4))
        fs = _fs(ax)
        ax.annotate(f"{prefix}{i}", centre, xytext=(0.7 * fs, 0.7 * fs), textcoords="offset points",
                    fontsize=0.85 * fs, color="#b35f00", fontweight="bold", zorder=7,
                    bbox=dict(boxstyle="round,pad=0.12", fc="white", ec="#b35f00", lw=0.5, alpha=0.85))


def draw_points(ax, points, color="black", marker=".", size=None, label=None) -> None:
    """Scatter (x, y) points, e.g. start states or goal points."""
    points = np.asarray(points, dtype=float).reshape(-1, 2)
    ax.plot(points[:, 0], points[:, 1], marker, color=color, ms=size or _fs(ax) / 3, zorder=4, label=label, lw=0)


def _legend(fig, ax, items) -> None:
    handles = []
    for name, colour, kind in items:
        if kind == "patch":
            handles.append(Patch(facecolor=colour, edgecolor="black" if colour == WALL else colour, label=name,
                                 hatch="xx" if colour == HAZARD else None))
        else:
            handles.append(Line2D([0], [0], color=colour, lw=2, label=name, ls="--" if kind == "dashed" else "-"))
    fs = _fs(ax)
    box = ax.get_position()
    fig.legend(handles=handles, loc="lower center", bbox_to_anchor=(0.5, box.y1 + 0.1 * fs / fig.bbox.height),
               ncol=len(handles), fontsize=0.8 * fs, frameon=False, handlelength=1.4, columnspacing=1.0,
               handletextpad=0.4, borderaxespad=0.0)


def _maze_figure(maze, size_px: int, title, legend_row: bool = True):
    """A figure of ``maze``'s floor: white, a light grid at every cell, walls and hazards; (fig, ax)."""
    fig, ax = new_figure(maze.bounds(), size_px, title, legend_row=legend_row)
    ax.set_facecolor("white")
    _grid(ax, maze.cell_size)
    draw_walls(ax, maze)
    draw_hazards(ax, maze)
    return fig, ax


# --- the task picture ----------------------------------------------------------------------------
def render_task(maze, graph=None, *, trajectories=None, success=None, lengths=None, waypoints=None, path=None,
                title=None, size_px=768, edge_labels=None, points=None, legend=True, proposed=None):
    """Top-down picture of a maze task (the image handed to the VLM).

    maze: a :class:`~specrefine.core.mazes.Maze` (metres follow its ``cell_size``).
    graph: optional :class:`~specrefine.core.graph.TaskGraph` drawn on the map (vertex regions, arrows);
      without it the maze's own S / G / lettered subgoals are drawn.
    trajectories, success, lengths: rollouts (n, T, 2), success flags (n,), valid lengths (n,).
    waypoints: candidate waypoints (Regions or points) drawn orange, dashed and numbered x1, x2, ...
    proposed: regions drawn as grey outlines only, under ``waypoints`` (the sets as proposed, before Algorithm 2
      chose subsets of them: the paper's Figure 3 in one frame).
    path: a list of graph vertices to highlight; edge_labels: {(u, v): text}; points: extra (x, y) dots.
    size_px: the longer side of the picture in pixels (the other follows the maze's aspect ratio).
    """
    fig, ax = _maze_figure(maze, size_px, title, legend_row=legend)
    if graph is None:
        draw_maze_regions(ax, maze)
    else:
        draw_maze_regions(ax, maze, alpha=0.18, labels=False)
        draw_graph(ax, graph, path=path, edge_labels=edge_labels)
    for region in proposed or ():
        draw_region(ax, region, PROPOSED, alpha=0.0, edge=True, lw=1.6, ls="-", zorder=1.9)
    if waypoints:
        draw_waypoints(ax, waypoints)
    if trajectories is not None and len(trajectories):
        draw_trajectories(ax, trajectories, success, lengths)
    if points is not None:
        draw_points(ax, points)
    if legend:
        items = [("wall", WALL, "patch"), ("start", START, "patch"), ("goal", GOAL, "patch")]
        if getattr(maze, "hazards", None) is not None:
            items.insert(1, ("hazard", HAZARD, "patch"))
        if (graph is not None and len(graph.vertices()) > 2) or maze.subgoals or waypoints:
            items.append(("subgoal / waypoint", SUBGOAL, "patch"))
        if proposed:
            items.append(("as proposed", PROPOSED, "line"))
        if graph is not None and any(graph.is_shortcut(u, v) for u, v in graph.edges()):
            items.append(("shortcut edge", EDGE, "dashed"))
        if trajectories is not None and len(trajectories):
            if success is None:
                items.append(("trajectory", "#777777", "line"))
            else:
                k = int(np.sum(success))
                items += [(f"success ({k})", SUCCESS, "line"), (f"failure ({len(success) - k})", FAILURE, "line")]
        _legend(fig, ax, items)
    return fig


# --- the correction's roadmap ------------------------------------------------------------------
def render_roadmap(maze, roadmap, graph=None, path=None, *, title=None, size_px=768):
    """The correction's roadmap (``refine/roadmap.py``; methods ``ours-corrector-roadmap`` and after): every
    waypoint the proposer's replies named, pooled (grey); the search's own probes (orange); the legs its searches
    built on from each origin they started at (green; remembered trees only, ``ours-corrector-memory`` and after);
    and the found path through the refined ``graph`` (blue). Where its searches went and where they stopped: a
    picture of why a dead leg stayed dead."""
    fig, ax = _maze_figure(maze, size_px, title)
    draw_maze_regions(ax, maze, alpha=0.18, labels=False)
    centres = np.asarray([p.centre() for p in roadmap.points], dtype=float).reshape(-1, 2)
    probe = np.zeros(len(centres), dtype=bool)
    probe[[i for i in roadmap.probes if i < len(centres)]] = True
    fs = _fs(ax)
    for points, colour in ((centres[~probe], PROPOSED), (centres[probe], SUBGOAL)):
        ax.plot(points[:, 0], points[:, 1], ".", color=colour, ms=fs / 3, lw=0, zorder=3)
    for key, tree in roadmap.trees.items():
        origin = np.asarray(key[:2], dtype=float)
        for v, (_, u) in tree.items():
            a, b = centres[v], origin if u is None or u < 0 else centres[u]
            ax.plot([a[0], b[0]], [a[1], b[1]], "-", color=SUCCESS, lw=1.0, alpha=0.8, zorder=3.5)
    items = [("wall", WALL, "patch"), ("reply waypoint", PROPOSED, "line"), ("probe", SUBGOAL, "line"),
             ("leg a search built on", SUCCESS, "line")]
    if graph is not None and path:
        line = np.asarray([graph.region(v).centre() for v in path], dtype=float)
        ax.plot(line[:, 0], line[:, 1], "-", color=PATH, lw=2.0, zorder=4)
        items.append(("found path", PATH, "line"))
    _legend(fig, ax, items)
    return fig


# --- the abstract DAG view ---------------------------------------------------------------------
def render_graph_diagram(graph, probs=None, *, path=None, title=None, size_px=512):
    """The task graph as an abstract DAG, left to right by topological depth.

    probs: optional {(u, v): success probability} written on the edges; path: vertices to highlight.
    Vertex colours as on the map: initial cyan, finals green, the rest orange.
    """
    order = {v: i for i, v in enumerate(graph.vertices())}
    layers = [sorted(layer, key=order.get) for layer in graph.topological_layers()]
    depth = {v: i for i, layer in enumerate(layers) for v in layer}
    pos = {v: np.array([float(i), (len(layer) - 1) / 2.0 - j]) for i, layer in enumerate(layers)
           for j, v in enumerate(layer)}
    n_cols, n_rows = len(layers), max(len(layer) for layer in layers)
    fs = _font(size_px) * 1.1
    top = 2.2 * fs if title else 0.5 * fs
    w = size_px
    h = int(round(float(np.clip((w * n_rows) / n_cols + top, 0.3 * size_px, size_px))))
    if h == size_px and (w * n_rows) / n_cols + top > size_px:  # tall graph: shrink the width instead
        w = int(round(max((size_px - top) * n_cols / n_rows, 0.3 * size_px)))
    fig = PngFigure(figsize=(w / DPI, h / DPI), dpi=DPI)
    FigureCanvasAgg(fig)
    ax = fig.add_axes((0.0, 0.0, 1.0, 1.0 - top / h))
    ax.set_xlim(-0.5, n_cols - 0.5)
    ax.set_ylim(-n_rows / 2, n_rows / 2)
    ax.set_aspect("equal", adjustable="box")
    ax.axis("off")
    if title:
        fig.suptitle(title, fontsize=fs, y=1 - 0.4 * fs / h, va="top")
    on_path = set(zip(path, path[1:], strict=False)) if path else set()
    node_r = 0.22
    px_per_unit = min(w / n_cols, (h - top) / n_rows)
    shrink = node_r * px_per_unit * 72 / DPI + 1.0  # points
    for u, v in graph.edges():
        hot = (u, v) in on_path
        rad = 0.0 if depth[v] - depth[u] == 1 else -0.3
        ax.add_patch(FancyArrowPatch(pos[u], pos[v], arrowstyle="-|>", mutation_scale=1.5 * fs,
                                     color=PATH if hot else EDGE, lw=2.4 if hot else 1.2, shrinkA=shrink,
                                     shrinkB=shrink, connectionstyle=f"arc3,rad={rad}", zorder=2,
                                     linestyle="--" if graph.is_shortcut(u, v) else "-"))
        if probs is not None and probs.get((u, v)) is not None:
            mid = (pos[u] + pos[v]) / 2 + np.array([0.0, 0.1 if rad == 0 else 0.1 + 0.3 * (depth[v] - depth[u]) / 2])
            ax.text(mid[0], mid[1], f"{float(probs[(u, v)]):.2f}", ha="center", va="bottom", fontsize=0.9 * fs,
                    color=PATH if hot else EDGE, zorder=4,
                    bbox=dict(boxstyle="round,pad=0.15", fc="white", ec="none", alpha=0.9))
    for v in graph.vertices():
        ax.add_patch(Circle(pos[v], node_r, facecolor=_vertex_colour(graph, v), edgecolor="black",
                            lw=2.0 if v in (path or ()) else 0.8, zorder=3))
        ax.text(pos[v][0], pos[v][1], graph.label(v) or v, ha="center", va="center", fontsize=fs,
                fontweight="bold", zorder=4)
    return fig


# --- output ------------------------------------------------------------------------------------
def to_png(fig) -> bytes:
    """Rasterise a figure to PNG bytes at its own pixel size."""
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=fig.dpi, facecolor="white")
    return buf.getvalue()


def save_png(fig, path) -> None:
    from ..core.runfolder import write_atomic

    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    write_atomic(path, to_png(fig))


def render_maze_pictures(out_dir=None, size_px=512) -> list[Path]:
    """Write data/mazes/pictures/NAME.png for every shipped maze (point scale); returns the paths."""
    from ..core.mazes import MAZE_DIR, benchmark_mazes, load_maze

    out_dir = Path(out_dir) if out_dir is not None else MAZE_DIR / "pictures"
    written = []
    for name, file in benchmark_mazes().items():
        maze = load_maze(file)
        from ..core.spec import maze_task

        fig = render_task(maze, maze_task(maze), title=f"{name} (point scale, cell {maze.cell_size:g} m)",
                          size_px=size_px)
        save_png(fig, out_dir / f"{name}.png")
        written.append(out_dir / f"{name}.png")
    return written


if __name__ == "__main__":  # python -m specrefine.pictures.render  -> regenerate data/mazes/pictures/
    for p in render_maze_pictures():
        print(p)
