"""Top-down pictures: every maze renders to a PNG of the requested size, with and without trajectories."""

import io

import numpy as np
import pytest
from matplotlib.image import imread

from specrefine.core.graph import TaskGraph
from specrefine.core.mazes import benchmark_mazes, load_maze
from specrefine.core.regions import Box, Disc
from specrefine.core.spec import maze_task
from specrefine.pictures.render import render_graph_diagram, render_task, save_png, to_png


def decode(png: bytes) -> np.ndarray:
    assert png[:8] == b"\x89PNG\r\n\x1a\n"
    return imread(io.BytesIO(png), format="png")


@pytest.mark.parametrize("name", sorted(benchmark_mazes()))
def test_every_maze_renders_at_requested_size(name):
    maze = load_maze(name)
    img = decode(to_png(render_task(maze, maze_task(maze), title=name, size_px=512)))
    assert max(img.shape[:2]) == 512 and min(img.shape[:2]) >= 0.3 * 512
    rgb = img[..., :3]
    assert (rgb.max(axis=-1) < 0.05).mean() > 0.05  # walls are black
    cyan = (rgb[..., 0] < 0.5) & (rgb[..., 1] > 0.7) & (rgb[..., 2] > 0.75)
    assert cyan.sum() > 20  # the start region is visible
    assert rgb.std() > 0.1  # not a blank picture


def test_trajectory_picture(tmp_path):
    maze = load_maze("split_doorway").for_agent("ant")
    rng = np.random.default_rng(0)
    trajs = maze.start.centre() + np.cumsum(rng.normal(0, 0.3, (12, 50, 2)), axis=1)
    success = np.arange(12) % 2 == 0
    fig = render_task(maze, maze_task(maze), trajectories=trajs, success=success, lengths=np.full(12, 40),
                      waypoints=[Box(-2, 12, 2, 16), Disc(8, -10, 1.5), (4.0, 8.0)], path=["S", "G"],
                      title="split doorway (ant)", size_px=1024, edge_labels={("S", "G"): "p=0.50"})
    out = tmp_path / "sub" / "traj.png"
    save_png(fig, out)
    img = decode(out.read_bytes())
    assert max(img.shape[:2]) == 1024
    rgb = img[..., :3]
    red = (rgb[..., 0] > 0.7) & (rgb[..., 1] < 0.35) & (rgb[..., 2] < 0.35)
    green = (rgb[..., 1] > 0.45) & (rgb[..., 0] < 0.3) & (rgb[..., 2] < 0.4)
    assert red.sum() > 50 and green.sum() > 50


def test_graph_diagram():
    tg = TaskGraph("S")
    for name, x in (("S", 0), ("a", 2), ("b", 2), ("G", 4)):
        tg.add_vertex(name, Box(x, 0, x + 1, 1))
    for u, v in (("S", "a"), ("S", "b"), ("a", "G"), ("b", "G"), ("S", "G")):
        tg.add_edge(u, v, Box(10, 10, 11, 11))
    tg.finals = {"G"}
    img = decode(to_png(render_graph_diagram(tg, {("S", "a"): 0.9, ("a", "G"): 0.5}, path=["S", "a", "G"],
                                             title="choices", size_px=400)))
    assert img.shape[1] == 400 and img[..., :3].std() > 0.05


def test_the_roadmap_picture_shows_replies_probes_and_the_legs_its_searches_built_on():
    from specrefine.pictures.render import PATH, PROPOSED, SUBGOAL, SUCCESS, render_roadmap
    from specrefine.refine.roadmap import Roadmap

    maze = load_maze("u_maze")
    graph = maze_task(maze)
    roadmap = Roadmap(reach=3.0)
    roadmap.add([Disc(1.0, 1.0, 0.3), Disc(2.0, 1.0, 0.3)])  # two reply waypoints, the second one a probe
    roadmap.probes = {1: Roadmap._key(np.array([1.0, 1.0]), np.array([1.0, 1.0]))}
    roadmap.trees = {(0.0, 0.0, 0.0, 0.0): {0: (None, -1), 1: (None, 0)}}  # origin -> 1 -> 2
    fig = render_roadmap(maze, roadmap, graph, ["S", "G"], title="roadmap", size_px=400)
    lines = fig.axes[0].get_lines()
    colours = [line.get_color() for line in lines]
    dots = {c: line.get_xydata().tolist() for c, line in zip(colours, lines) if line.get_marker() == "."}
    assert dots == {PROPOSED: [[1.0, 1.0]], SUBGOAL: [[2.0, 1.0]]}
    legs = [line.get_xydata().tolist() for line in lines if line.get_color() == SUCCESS]
    assert legs == [[[1.0, 1.0], [0.0, 0.0]], [[2.0, 1.0], [1.0, 1.0]]]
    assert colours.count(PATH) == 1
    img = decode(to_png(fig))
    assert max(img.shape[:2]) == 400


def test_the_search_slider_redraws_its_picture_from_the_step_log():
    """notebook 05's slider: the last step shown first, another step's picture (PNG bytes of an Image widget, no Output
    widget for nbclient to hang on) when the slider moves."""
    from ipywidgets import Image, IntSlider

    from specrefine.runs.explore import search_slider, step_png

    maze = load_maze("u_maze").for_agent("point")
    graph = maze_task(maze)
    steps = [{"step": 0, "event": "expand", "vertex": "S", "cost": 0.0, "open": ["G"], "closed": ["S"]},
             {"step": 1, "event": "done", "path": ["S", "G"], "predicted_success": 0.5, "open": [],
              "closed": ["S", "G"]}]
    box = search_slider(maze, steps, graph, size_px=200)
    slider, image = box.children
    assert isinstance(slider, IntSlider) and isinstance(image, Image)
    assert (slider.min, slider.max, slider.value) == (0, 1, 1)
    last = bytes(image.value)  # the widget holds a memoryview
    assert last == step_png(maze, steps, graph, 1, 200) and last.startswith(b"\x89PNG")
    assert imread(io.BytesIO(last)).shape[:2] == (200, 200)
    slider.value = 0
    assert bytes(image.value) == step_png(maze, steps, graph, 0, 200) != last
